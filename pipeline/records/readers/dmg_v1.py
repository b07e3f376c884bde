"""CSMIP/DMG Volume 1 text (uncorrected acceleration; gzip allowed)."""
import re

from obspy import Stream, Trace, UTCDateTime

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records.readers import VERTICAL_DOWN, VERTICAL_UP, read_bytes
from pipeline.records.readers._text import counted_samples

FORMAT = "dmg-v1"
PRIORITY = 30


def detect(path, head):
    first = head[:200].decode("latin-1").upper().split("\n", 1)[0]
    return "UNCORRECTED ACCELEROGRAM" in first


def read(path, key=None):
    return read_dmg_v1(read_bytes(path).decode("latin-1"), path.name)


def read_dmg_v1(text, name="V1 file"):
    """CSMIP/DMG Volume 1 text: per channel 13 text, 7 integer and 7 real header
    lines, a line ``N Accelerogram points at R pts/sec in units of g ... (8f9.6)``,
    the samples in fixed-width fields and an end-of-channel line."""
    lines = text.splitlines()
    starts = [i for i, line in enumerate(lines) if "UNCORRECTED ACCELEROGRAM" in line.upper()]
    stream, info = Stream(), {}
    for start in starts:
        stream.append(_dmg_channel(lines, start, name, info))
    if not stream:
        raise InputError(f"{name}: no DMG V1 channel found")
    return stream, info


def _dmg_channel(lines, start, name, info):
    header = lines[start:start + 13]
    data_line = next((i for i in range(start + 13, min(start + 40, len(lines)))
                      if "ACCELEROGRAM POINTS" in lines[i].upper()), None)
    if len(header) < 13 or data_line is None:
        raise InputError(f"{name}: truncated DMG V1 channel header at line {start + 1}")
    fmt = re.search(r"(\d+)\s+ACCELEROGRAM POINTS AT\s+([\d.]+)\s+PTS/SEC IN UNITS OF\s+(\S+?)\.?\s"
                    r".*\((\d+)F(\d+)\.\d+\)", lines[data_line].upper())
    if not fmt:
        raise InputError(f"{name}: unreadable DMG V1 data line {data_line + 1}")
    npts, rate, unit = int(fmt.group(1)), float(fmt.group(2)), fmt.group(3)
    per_line, width = int(fmt.group(4)), int(fmt.group(5))
    scale = {"G": STANDARD_GRAVITY, "CM/SEC/SEC": 0.01, "CM/S/S": 0.01}.get(unit)
    if scale is None:
        raise InputError(f"{name}: DMG V1 unit {unit!r} not supported")
    n_lines = -(-npts // per_line)
    body = lines[data_line + 1:data_line + 1 + n_lines]
    values = counted_samples([line[k:k + width] for line in body
                              for k in range(0, per_line * width, width)
                              if line[k:k + width].strip()], npts, name,
                             f"non-numeric DMG V1 samples after line {data_line + 1}",
                             "DMG V1 channel")

    trace = Trace(values * scale)
    trace.stats.sampling_rate = rate
    start_time = re.search(r"START TIME:\s*(\d+)/(\d+)/(\d+),\s*(\d+):\s*(\d+):\s*([\d.]+)",
                           header[3].upper())
    if start_time:
        month, day, year, hour, minute = (int(v) for v in start_time.groups()[:5])
        try:
            trace.stats.starttime = UTCDateTime(2000 + year if year < 70 else 1900 + year,
                                                month, day, hour, minute) + \
                float(start_time.group(6))
        except ValueError:
            raise InputError(f"{name}: impossible start time in the DMG V1 header: "
                             f"{header[3].strip()[:60]!r}") from None
    station = re.search(r"STATION ID\.\s+(\S+)", header[4].upper())
    chan = re.search(r"CHAN\s+(\d+):\s*(\d+\s*DEG|UP|DOWN)", header[6].upper())
    if not chan:
        raise InputError(f"{name}: DMG V1 channel orientation unreadable: {header[6].strip()!r}")
    trace.stats.station = station.group(1) if station else ""
    trace.stats.channel = f"HN{chan.group(1)}"
    orient = chan.group(2)
    if orient == "UP":
        trace.stats.azimuth, trace.stats.dip = 0.0, VERTICAL_UP
    elif orient == "DOWN":
        trace.stats.azimuth, trace.stats.dip = 0.0, VERTICAL_DOWN
    else:
        trace.stats.azimuth, trace.stats.dip = float(orient.split()[0]) % 360.0, 0.0
    info.setdefault("station", trace.stats.station)
    info.update(_dmg_coordinates(header[4], lines[start + 20:start + 27]))
    return trace


def _dmg_coordinates(station_line, real_lines):
    """Station latitude/longitude: the 5-decimal values of the real header (fields
    29-30) when they agree with the 3-decimal ones of the text header."""
    match = re.search(r"([\d.]+)([NS]),\s*([\d.]+)([EW])", station_line.upper())
    if not match:
        return {}
    lat = float(match.group(1)) * (1 if match.group(2) == "N" else -1)
    lon = float(match.group(3)) * (1 if match.group(4) == "E" else -1)
    fields = [line[k:k + 10] for line in real_lines for k in range(0, 80, 10)]
    try:
        precise = float(fields[28]), float(fields[29])
        if abs(precise[0] - lat) < 1e-3 and abs(precise[1] - lon) < 1e-3:
            lat, lon = precise
    except (IndexError, ValueError):
        pass
    return {"station_lat": lat, "station_lon": lon}
