"""GeoNet (GNS Science, New Zealand) strong-motion text: Volume 1 (``.V1A``,
uncorrected) and Volume 2 (``.V2A``, instrument-corrected and band-passed).

One file holds the three components of a station, one channel after another.
Each channel is

- 16 text lines: title (``Corrected accelerogram ... GNS Science`` or
  ``Uncorrected ...``), ``Site <code> dd mm ssS ddd mm ssE``, site name,
  instrument, resolution, accelerogram id, epicentre locality, origin date and
  time (UT), ``Epicentre dd mm ssS ddd mm ssE ... Depth ..km Mw m.mm``, number
  of points, sampling (V1: ``Raw readings in units of 1.00 mm/s/s at intervals
  of 0.005 s``; V2: ``Instrument corrected data at 0.020 sec intervals``),
  filter (V2: ``Band-pass filter transition bands are .10-.25 Hz and
  24.50-25.50 Hz``), ``Component N28W ...`` and the acceleration peak;
- 4 lines of 10 integers and 6 lines of 10 reals (8 characters each): integer
  row 3 holds the component azimuth in field 8, row 4 the number of samples
  (V1: field 1; V2: prepended, appended, acceleration, velocity, displacement
  in fields 2-6) and, with rows 1-2, the buffer start time (year, month / day,
  hour / minute, millisecond in fields 9-10); real row 2 the station
  coordinates in decimal degrees (sign dropped), real row 3 the durations of
  the prepended padding (field 2, seconds) and the sample interval (field 6);
- the samples, 10 per line in 8-character fields: acceleration (mm/s^2), and in
  V2 files then velocity and displacement (skipped here).

A V2 series starts with the prepended padding (5 s in the Kaikoura files): its
first sample is that long before the buffer start, and the peak times the
header prints count from the buffer start.  The traces carry that time base.

Component names are compass bearings of the positive sensor axis (``N28W`` =
332 deg, ``S62W`` = 242 deg) or ``Up``.  Layout as described by GeoNet
("strong motion file formats") and read by gmprocess ``io/geonet``.
"""
import re
from datetime import datetime
from pathlib import Path

import numpy as np
from obspy import Stream, Trace, UTCDateTime

from pipeline.files import InputError
from pipeline.records.readers._text import (
    VERTICAL_DOWN, VERTICAL_UP, compass_azimuth, fixed_width_values, head_text, number,
    one_line, open_text)

FORMAT = "geonet"
# Below dmg-v1 (30): its detector also matches "Uncorrected accelerogram" titles.
PRIORITY = 25

TEXT_ROWS, INT_ROWS, REAL_ROWS = 16, 4, 6
PER_LINE, WIDTH = 10, 8
_TITLE = re.compile(r"\s*(corrected|uncorrected)\s+accelerogram\b.*gns science", re.I)
_DMS = r"(\d+)\s+(\d+)\s+(\d+(?:\.\d+)?)\s*([NSEW])"


def detect(path, head):
    first = head_text(head, 300).split("\n", 1)[0]
    return bool(_TITLE.match(first))


def read(path, key=None):
    """Three components of a GeoNet V1A/V2A file (``key`` is not used)."""
    path = Path(path)
    name = path.name
    lines = open_text(path).splitlines()
    channels, pos = [], 0
    while pos < len(lines):
        if not lines[pos].strip():
            pos += 1
            continue
        channel, pos = _read_channel(lines, pos, name, len(channels) + 1)
        channels.append(channel)
    if not channels:
        raise InputError(f"{name}: no GeoNet channel found")
    levels = {c["level"] for c in channels}
    if len(levels) > 1:
        raise InputError(f"{name}: mixes corrected (V2) and uncorrected (V1) channels")
    stations = {c["station"] for c in channels}
    if len(stations) > 1:
        raise InputError(f"{name}: holds several stations ({', '.join(sorted(stations))})")
    _check_components(channels, name)

    stream = Stream([c["trace"] for c in channels])
    first = channels[0]
    info = {"station": f"NZ.{first['station']}", "horizontals_compass": True}
    info.update(first["coords"])
    info.update(first["event"])
    level = first["level"]
    if level == "V2":
        band = first.get("band")
        if band:
            info["lowest_usable_hz"], info["highest_usable_hz"] = band
        info["notes"] = ("GeoNet Volume 2: instrument-corrected acceleration, band-pass "
                         + (f"transition bands {first['band_text']} Hz" if band else "filtered"))
    else:
        info["notes"] = ("GeoNet Volume 1: uncorrected acceleration, unfiltered, "
                         "no baseline correction")
    return stream, info


def _check_components(channels, name):
    comps = [c["component"] for c in channels]
    horizontals = [c for c in channels if c["trace"].stats.dip == 0.0]
    verticals = [c for c in channels if c["trace"].stats.dip != 0.0]
    seen = {}
    for c in channels:
        st = c["trace"].stats
        k = ("V",) if st.dip != 0.0 else ("H", round(st.azimuth % 180.0, 3))
        if k in seen:
            raise InputError(f"{name}: duplicated component: {seen[k]} and {c['component']} "
                             "share one axis")
        seen[k] = c["component"]
    if len(horizontals) != 2 or len(verticals) != 1:
        raise InputError(f"{name}: has components {', '.join(comps)}; a GeoNet record needs "
                         "two horizontals and one vertical (missing component)")


def _read_channel(lines, start, name, index):
    text = lines[start:start + TEXT_ROWS]
    where = f"channel {index} (line {start + 1})"
    title = _TITLE.match(text[0]) if text else None
    if not title:
        raise InputError(f"{name}: line {start + 1} does not start a GeoNet channel "
                         f"(found {one_line(text[0])[:50]!r})")
    if len(text) < TEXT_ROWS:
        raise InputError(f"{name}: {where}: truncated text header")
    level = "V2" if title.group(1).lower() == "corrected" else "V1"

    site = re.match(r"\s*Site\s+(\S+)\s+" + _DMS + r"\s+" + _DMS, text[1])
    if not site:
        raise InputError(f"{name}: {where}: unreadable site line {one_line(text[1])!r}")
    station = site.group(1)
    lat = _dms(site.groups()[1:5], "NS", name, where)
    lon = _dms(site.groups()[5:9], "EW", name, where)

    comp = re.match(r"\s*Component\s+(\S+)", text[12])
    if not comp:
        raise InputError(f"{name}: {where}: no 'Component' line (line {start + 13})")
    component = comp.group(1)

    ints, reals, npts, dt = _headers(lines, start, text, level, name, where)

    scale = _scale(text, level, name, where)
    azimuth, dip = _orientation(component, name, where)
    if dip == 0.0 and abs((ints[2, 7] - azimuth + 180.0) % 360.0 - 180.0) > 0.5:
        raise InputError(f"{name}: {where}: component {component} ({azimuth:g} deg) disagrees "
                         f"with the integer header azimuth {ints[2, 7]:g}")
    if abs(abs(lat) - reals[1, 0]) > 2e-3 or abs(abs(lon) - reals[1, 1]) > 2e-3:
        raise InputError(f"{name}: {where}: site coordinates {one_line(text[1])[:40]!r} disagree "
                         f"with the real header ({reals[1, 0]:g}, {reals[1, 1]:g})")

    values, end = _samples(lines, start, ints, npts, level, component, name, where)

    trace = Trace(values * scale)
    trace.stats.network, trace.stats.station, trace.stats.location = "NZ", station, ""
    trace.stats.channel = component
    trace.stats.delta = dt
    trace.stats.azimuth, trace.stats.dip = azimuth, dip
    # V2 series are padded: their first sample lies `prepended` seconds before the buffer
    # start (header peak times count from the buffer start)
    prepended = float(reals[2, 1]) if level == "V2" else 0.0
    if not (np.isfinite(prepended) and prepended >= 0):
        raise InputError(f"{name}: {where}: prepended duration {prepended:g} s is not valid")
    trace.stats.starttime = _start_time(ints, name, where) - prepended

    channel = {"level": level, "station": station, "component": component, "trace": trace,
               "coords": {"station_lat": lat, "station_lon": lon},
               "event": _event(text, name, where)}
    band = re.search(r"transition bands are\s*([\d.]+)\s*-\s*([\d.]+)\s*Hz\s*and\s*([\d.]+)"
                     r"\s*-\s*([\d.]+)\s*Hz", text[11], re.I)
    if band:
        lo0, lo1, hi0, hi1 = (number(v, "filter band", name) for v in band.groups())
        channel["band"] = (lo1, hi0)  # pass band between the two transition bands
        channel["band_text"] = f"{lo0:g}-{lo1:g} and {hi0:g}-{hi1:g}"
    return channel, end


def _headers(lines, start, text, level, name, where):
    """The channel's integer and real headers (arrays of their rows), its sample count and
    sample interval (s), checked against the text header."""
    ints_f, _ = fixed_width_values(lines[start + TEXT_ROWS:start + TEXT_ROWS + INT_ROWS], WIDTH,
                                   PER_LINE, INT_ROWS * PER_LINE, name, f"{where} integer header")
    reals_f, _ = fixed_width_values(
        lines[start + TEXT_ROWS + INT_ROWS:start + TEXT_ROWS + INT_ROWS + REAL_ROWS], WIDTH,
        PER_LINE, REAL_ROWS * PER_LINE, name, f"{where} real header")
    ints = ints_f.reshape(INT_ROWS, PER_LINE)
    reals = reals_f.reshape(REAL_ROWS, PER_LINE)

    npts = int(ints[3, 0] if level == "V1" else ints[3, 3])
    stated = re.search(r"Number of points\s+(\d+)", text[9])
    if not stated:
        raise InputError(f"{name}: {where}: no 'Number of points' line")
    if int(stated.group(1)) != npts or npts <= 0:
        raise InputError(f"{name}: {where}: text header says {stated.group(1)} points, "
                         f"integer header {npts}")
    dt = float(reals[2, 5])
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"{name}: {where}: sample interval {dt:g} s is not positive")
    interval = re.search(r"(?:intervals of|at)\s+([\d.]+)\s*s", text[10])
    if interval and abs(number(interval.group(1), "sample interval", name) - dt) > 1e-6:
        raise InputError(f"{name}: {where}: text header interval {interval.group(1)} s, "
                         f"real header {dt:g} s")
    return ints, reals, npts, dt


def _samples(lines, start, ints, npts, level, component, name, where):
    """The channel's acceleration samples (file units) and the line after its last sample
    block (V2: after the velocity and displacement blocks)."""
    data_start = start + TEXT_ROWS + INT_ROWS + REAL_ROWS
    values, used = fixed_width_values(lines[data_start:], WIDTH, PER_LINE, npts, name,
                                      f"{where} {component} acceleration")
    end = data_start + used
    if level == "V2":  # velocity and displacement blocks follow
        for count in (int(ints[3, 4]), int(ints[3, 5])):
            end += -(-count // PER_LINE)
    if end > len(lines) or (end < len(lines) and lines[end].strip()
                            and not _TITLE.match(lines[end])):
        raise InputError(f"{name}: {where} {component}: the sample blocks do not end where the "
                         f"header counts say (line {end + 1}); wrong sample count")
    return values, end


def _dms(groups, hemispheres, name, where):
    deg, minutes, seconds, hemi = groups
    if hemi not in hemispheres:
        raise InputError(f"{name}: {where}: coordinate hemisphere {hemi!r} out of place")
    value = float(deg) + float(minutes) / 60.0 + float(seconds) / 3600.0
    if float(minutes) >= 60 or float(seconds) >= 60 or value > (90 if hemi in "NS" else 180):
        raise InputError(f"{name}: {where}: impossible coordinate {deg} {minutes} {seconds}{hemi}")
    return -value if hemi in "SW" else value


def _scale(text, level, name, where):
    """Factor from the file's sample unit to m/s^2."""
    if level == "V1":
        unit = re.search(r"units of\s+([\d.]+)\s*mm/s/s", text[10])
        if not unit:
            raise InputError(f"{name}: {where}: V1 sample unit unreadable "
                             f"({one_line(text[10])!r})")
        factor = number(unit.group(1), "V1 unit", name)
        if factor <= 0:
            raise InputError(f"{name}: {where}: V1 unit {factor:g} mm/s/s is not positive")
        return factor * 1e-3
    if not re.search(r"Acceleration:.*mm/s/s", text[13]):
        raise InputError(f"{name}: {where}: V2 acceleration not in mm/s/s "
                         f"({one_line(text[13])!r})")
    return 1e-3


def _orientation(component, name, where):
    token = component.upper()
    if token in {"UP", "UPDO"}:
        return 0.0, VERTICAL_UP
    if token in {"DOWN", "DN"}:
        return 0.0, VERTICAL_DOWN
    azimuth = compass_azimuth(token)
    if azimuth is None:
        raise InputError(f"{name}: {where}: component {component!r} is not a compass bearing "
                         "(like N28W) or Up")
    return azimuth, 0.0


def _start_time(ints, name, where):
    try:
        year, month, day, hour = (int(ints[0, 8]), int(ints[0, 9]), int(ints[1, 8]),
                                  int(ints[1, 9]))
        minute, millis = int(ints[3, 8]), float(ints[3, 9])
        if not 0 <= millis < 60000:
            raise ValueError
        return UTCDateTime(year, month, day, hour, minute) + millis / 1000.0
    except (ValueError, TypeError):
        raise InputError(f"{name}: {where}: start time in the integer header is not a date") \
            from None


def _event(text, name, where):
    event = {}
    when = re.match(r"\s*(\d{4})\s+([A-Za-z]+)\s+(\d{1,2})\s+(\d{1,2}):(\d{2}):(\d{2}(?:\.\d*)?)"
                    r"\s*UT", text[7])
    if when:
        try:
            stamp = datetime.strptime(" ".join(when.groups()[:3]), "%Y %B %d")
            origin = UTCDateTime(stamp.year, stamp.month, stamp.day, int(when.group(4)),
                                 int(when.group(5))) + float(when.group(6))
        except ValueError:
            raise InputError(f"{name}: {where}: unreadable origin time "
                             f"{one_line(text[7])!r}") from None
        event["origin_time"] = origin.isoformat()
        locality = text[6].strip()
        event["event"] = f"{origin.strftime('%Y-%m-%d %H:%M:%S')} UT" + (
            f", {locality}" if locality else "")
    epi = re.match(r"\s*Epicentre\s+" + _DMS + r"\s+" + _DMS, text[8])
    if epi:
        event["event_lat"] = _dms(epi.groups()[0:4], "NS", name, where)
        event["event_lon"] = _dms(epi.groups()[4:8], "EW", name, where)
    depth = re.search(r"Depth\s+([\d.]+)\s*km", text[8])
    if depth:
        event["event_depth_km"] = float(depth.group(1))
    mag = re.search(r"\bM[a-zA-Z]?\s+([\d.]+)\s*$", text[8].rstrip())
    if mag:
        event["magnitude"] = float(mag.group(1))
    return event
