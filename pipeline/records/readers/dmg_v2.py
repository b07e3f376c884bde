"""CSMIP/DMG Volume 2 text (``.V2``): corrected acceleration, velocity and
displacement of every channel of a station, one channel after another.

Each channel starts with a line ``CORRECTED ACCELEROGRAM <id> CHAN n: 90 DEG``
(or ``UP``/``DOWN``) followed by a text header (event name, origin and trigger
times, ``STATION NO. 36456 35.908N, 120.458W``, station name, channel,
``HYPOCENTER(BRK): 36.25N,120.28W, H=9KM ... ML=6.5``, the band-pass ramps
``BANDPASS FILTERED WITH RAMPS AT .050- .100 AND 23.00-25.00 CYC/SEC``, the
number of points and ``PEAK ACCELERATION = -267.957 CM/SEC/SEC``), integer and
real header blocks, then three data blocks each introduced by e.g.
``3251 POINTS OF ACCEL DATA EQUALLY SPACED AT .020 SEC. (UNITS: CM/SEC/SEC)``
(8 values of 10 characters per line) and ends with ``/& ... END OF DATA FOR
CHANNEL n``.  Only the acceleration block is read.
"""
import re
from pathlib import Path

from obspy import Stream, Trace, UTCDateTime

from pipeline.files import InputError
from pipeline.records.readers._text import (
    STANDARD_GRAVITY, VERTICAL_DOWN, VERTICAL_UP, fixed_width_values, head_text, number,
    one_line, open_text)

FORMAT = "dmg-v2"
PRIORITY = 30

WIDTH, PER_LINE = 10, 8
_START = re.compile(r"\s*CORRECTED ACCELEROGRAM\b", re.I)
_CHAN = re.compile(r"CHAN\s+(\d+)\s*:\s*(\d+(?:\.\d+)?\s*DEG|UP|DOWN|DWN)", re.I)
_DATA = re.compile(r"^\s*(\S+)\s+POINTS OF (ACCEL|VELOC|DISPL)\w* DATA EQUALLY SPACED AT\s+(\S+?)"
                   r"\s*SEC\.?\s*\(UNITS:\s*([^)]*)\)", re.I)
_UNITS = {"CM/SEC/SEC": 0.01, "CM/S/S": 0.01, "CM/SEC2": 0.01, "CM/S2": 0.01,
          "G": STANDARD_GRAVITY, "M/SEC/SEC": 1.0, "M/S/S": 1.0}
_UTC_OFFSET_H = {"UTC": 0, "GMT": 0, "UT": 0, "PDT": 7, "PST": 8}


def detect(path, head):
    first = head_text(head, 300).split("\n", 1)[0]
    return bool(_START.match(first)) and "GNS SCIENCE" not in first.upper()


def read(path, key=None):
    """All channels of a DMG V2 file: two horizontals and one vertical (``key`` unused)."""
    path = Path(path)
    name = path.name
    lines = open_text(path).splitlines()
    starts = [i for i, line in enumerate(lines) if _START.match(line)]
    if not starts or starts[0] != next((i for i, text in enumerate(lines) if text.strip()), None):
        raise InputError(f"{name}: does not start with 'CORRECTED ACCELEROGRAM' "
                         "(not a DMG V2 file)")
    stream, info = Stream(), {}
    for n, start in enumerate(starts):
        end = starts[n + 1] if n + 1 < len(starts) else len(lines)
        stream.append(_read_channel(lines[start:end], start, name, info))
    _check_components(stream, name)
    info["horizontals_compass"] = True
    return stream, info


def _check_components(stream, name):
    seen = {}
    for tr in stream:
        key = ("V",) if tr.stats.dip != 0.0 else ("H", round(tr.stats.azimuth % 180.0, 3))
        if key in seen:
            raise InputError(f"{name}: duplicated component: channels {seen[key]} and "
                             f"{tr.stats.channel} share one axis")
        seen[key] = tr.stats.channel
    horizontals = sum(tr.stats.dip == 0.0 for tr in stream)
    if horizontals != 2 or len(stream) != 3:
        comps = ", ".join(tr.stats.channel for tr in stream)
        raise InputError(f"{name}: has channels {comps}; a record needs two horizontals and one "
                         "vertical (missing component)")


def _read_channel(block, offset, name, info):
    """One channel's block as an obspy Trace (m/s^2); its station and event facts merged
    into ``info`` (a second channel must name the same station)."""
    where = f"channel at line {offset + 1}"
    chan = _CHAN.search(block[0])
    if not chan:
        raise InputError(f"{name}: {where}: no 'CHAN n: <orientation>' in {one_line(block[0])!r}")
    number_, orient = chan.group(1), re.sub(r"\s+", " ", chan.group(2).upper())
    where = f"channel {number_} (line {offset + 1})"
    trace, header = _acceleration(block, name, where)
    trace.stats.channel = f"CH{number_}"
    if orient in {"UP"}:
        trace.stats.azimuth, trace.stats.dip = 0.0, VERTICAL_UP
    elif orient in {"DOWN", "DWN"}:
        trace.stats.azimuth, trace.stats.dip = 0.0, VERTICAL_DOWN
    else:
        trace.stats.azimuth, trace.stats.dip = float(orient.split()[0]) % 360.0, 0.0
    repeat = _search(header[1:], r"^\s*CHAN\s+(\d+)\s*:\s*(\S+(?:\s*DEG)?)")
    if repeat and repeat.group(1) != number_:
        raise InputError(f"{name}: {where}: header names channel {repeat.group(1)}")

    code, start_time, channel_info = _header_facts(header, name, where)
    trace.stats.network, trace.stats.station = "CE", code
    if start_time is not None:
        trace.stats.starttime = start_time
    for key, value in channel_info.items():
        if key in info and info[key] != value and key in ("station_lat", "station_lon", "station"):
            raise InputError(f"{name}: {where}: {key} {value} differs from the first channel's "
                             f"{info[key]}")
        info.setdefault(key, value)
    return trace


def _acceleration(block, name, where):
    """The channel's acceleration block as a Trace (m/s^2, its sample interval set) and the
    text header above it."""
    data_rows = [i for i, line in enumerate(block) if _DATA.match(line)]
    accel = next((i for i in data_rows if _DATA.match(block[i]).group(2).upper() == "ACCEL"), None)
    if accel is None:
        raise InputError(f"{name}: {where}: no 'POINTS OF ACCEL DATA' line")
    header = block[:accel]
    npts_text, kind, dt_text, unit = _DATA.match(block[accel]).groups()
    try:
        npts = int(npts_text)
    except ValueError:
        raise InputError(f"{name}: {where}: number of points {npts_text!r} is not an integer") \
            from None
    dt = number(dt_text, "sample interval", name)
    if dt <= 0:
        raise InputError(f"{name}: {where}: sample interval {dt_text} s is not positive")
    scale = _UNITS.get(re.sub(r"\s+", "", unit.upper()))
    if scale is None:
        raise InputError(f"{name}: {where}: acceleration unit {unit.strip()!r} not supported")
    stated = _search(header, r"^\s*(\d+)\s+POINTS OF INSTRUMENT")
    if stated and int(stated.group(1)) != npts:
        raise InputError(f"{name}: {where}: text header says {stated.group(1)} points, data "
                         f"block {npts}")

    # the acceleration block ends at the next data block, the end marker or the block end
    stop = next((i for i in range(accel + 1, len(block))
                 if _DATA.match(block[i]) or block[i].lstrip().startswith("/&")), len(block))
    body = [line for line in block[accel + 1:stop] if line.strip()]
    if -(-npts // PER_LINE) != len(body):
        found = sum(1 for line in body for k in range(0, len(line.rstrip()), WIDTH)
                    if line[k:k + WIDTH].strip())
        raise InputError(f"{name}: {where}: acceleration block has {found} samples, "
                         f"header says {npts}")
    values, _ = fixed_width_values(body, WIDTH, PER_LINE, npts, name, f"{where} acceleration")
    trace = Trace(values * scale)
    trace.stats.delta = dt
    return trace, header


def _header_facts(header, name, where):
    """Station code, trigger time (or None) and the station/event facts of a channel's text
    header (coordinates in degrees, depth km)."""
    station = _search(header, r"STATION\s+NO\.\s*(\S+)\s+([\d.]+)\s*([NS])\s*,\s*"
                              r"([\d.]+)\s*([EW])")
    if not station:
        raise InputError(f"{name}: {where}: no 'STATION NO. <id> <lat>N, <lon>W' line")
    code = station.group(1)
    lat = _coordinate(station.group(2), station.group(3), name, where)
    lon = _coordinate(station.group(4), station.group(5), name, where)
    start_time = _time(header, "TRIGGER TIME", name, where)

    channel_info = {"station_lat": lat, "station_lon": lon}
    line_no = next(i for i, line in enumerate(header) if "STATION NO." in line.upper())
    site = header[line_no + 1].strip() if line_no + 1 < len(header) else ""
    channel_info["station"] = f"CE.{code}" + (f" {site.title()}" if site else "")
    event = header[2].strip() if len(header) > 2 else ""
    if event:
        channel_info["event"] = event.title()
    origin = _time(header, r"ORIGIN(?:\(\w+\))?", name, where)
    if origin is not None:
        channel_info["origin_time"] = origin.isoformat()
    hypo = _search(header, r"HYPOCENTER(?:\(\w+\))?\s*:\s*([\d.]+)\s*([NS])\s*,\s*"
                           r"([\d.]+)\s*([EW])(?:\s*,\s*H\s*=\s*([\d.]+)\s*KM)?")
    if hypo:
        channel_info["event_lat"] = _coordinate(hypo.group(1), hypo.group(2), name, where)
        channel_info["event_lon"] = _coordinate(hypo.group(3), hypo.group(4), name, where)
        if hypo.group(5):
            channel_info["event_depth_km"] = float(hypo.group(5))
    mag = _search(header, r"\b(?:M[LSW]?|MAG)\s*=\s*([\d.]+)")
    if mag:
        channel_info["magnitude"] = float(mag.group(1))
    ramps = _search(header, r"BANDPASS FILTERED WITH RAMPS AT\s*([\d.]+)\s*-\s*([\d.]+)\s+AND\s+"
                            r"([\d.]+)\s*-\s*([\d.]+)")
    if ramps:
        lo0, lo1, hi0, hi1 = (number(v, "filter ramp", name) for v in ramps.groups())
        channel_info["lowest_usable_hz"], channel_info["highest_usable_hz"] = lo1, hi0
        channel_info["notes"] = (f"CSMIP/DMG Volume 2: corrected acceleration, band-pass ramps "
                                 f"{lo0:g}-{lo1:g} and {hi0:g}-{hi1:g} Hz")
    if hypo and "PRELIMINARY" in hypo.string.upper():
        channel_info["notes"] = (channel_info.get("notes", "CSMIP/DMG Volume 2")
                                 + "; hypocentre in the header is a preliminary solution")
    return code, start_time, channel_info


def _search(lines, pattern):
    regex = re.compile(pattern, re.I)
    for line in lines:
        match = regex.search(line)
        if match:
            return match
    return None


def _coordinate(value, hemi, name, where):
    degrees = number(value, "coordinate", name)
    if degrees > (90 if hemi.upper() in "NS" else 180):
        raise InputError(f"{name}: {where}: impossible coordinate {value}{hemi}")
    return -degrees if hemi.upper() in "SW" else degrees


def _time(header, label, name, where):
    match = _search(header, label + r"\s*:\s*(\d{1,2})/(\d{1,2})/(\d{2,4})\s*,\s*"
                                    r"(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d*)?)\s*"
                                    r"(UTC|GMT|UT|PDT|PST)")
    if not match:
        return None
    month, day, year, hour, minute = (int(v) for v in match.groups()[:5])
    if year < 100:
        year += 1900 if year >= 30 else 2000
    try:
        local = UTCDateTime(year, month, day, hour, minute) + float(match.group(6))
    except ValueError:
        raise InputError(f"{name}: {where}: impossible date in {one_line(match.group(0))!r}") \
            from None
    return local + 3600.0 * _UTC_OFFSET_H[match.group(7).upper()]
