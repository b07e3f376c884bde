"""Readers for strong-motion record files.

Every reader returns ``(stream, info)``:

- ``stream``: an :class:`obspy.Stream` of acceleration in m/s^2, one trace per
  sensor component, each with ``stats.azimuth`` (degrees clockwise from North
  of the positive sensor axis) and ``stats.dip`` (degrees, SEED convention:
  -90 = positive up, 90 = positive down, 0 = horizontal);
- ``info``: a dict of what the file says about the record (``station``,
  ``event``, ``magnitude``, ``station_lat``/``station_lon``,
  ``event_lat``/``event_lon`` in degrees, ``lowest_usable_hz``,
  ``origin_time``); keys are absent when the file does not tell.

Formats: PEER NGA ``.AT2`` (one component per file; the sibling files of the
same recording are found by their header), CSMIP/DMG Volume 1 text (``.V1``,
``.RAW``; gzip allowed), ASDF/HDF5 (raw counts with StationXML and QuakeML),
the compact FEMA P695 file ``records/fema_p695.npz`` (needs a key, e.g.
``NF11``), and anything :func:`obspy.read` reads (MiniSEED, SAC, ...).
"""
import glob
import gzip
import io
import json
import re
from pathlib import Path

import numpy as np
import obspy
from obspy import Stream, Trace, UTCDateTime

from pipeline.files import InputError

G = 9.80665  # standard gravity, m/s^2
VERTICAL_UP, VERTICAL_DOWN = -90.0, 90.0


def read_record(path, key=None):
    """Read one 3-component (or FEMA 2-component) record file; see module doc.

    ``path`` may also be a glob pattern naming the single-channel files of one
    record (e.g. ``rec.*.sac``), read together by obspy.
    """
    path = Path(path)
    if is_pattern(path):
        if not glob.glob(str(path)):
            raise InputError(f"no record files match {path}")
        return read_obspy(path)
    if not path.is_file():
        raise InputError(f"record file not found: {path}")
    if path.suffix.lower() == ".npz":
        if key is None:
            raise InputError(f"{path.name}: a FEMA P695 file needs a record key such as NF11")
        return read_fema_p695(path, key)
    raw = path.read_bytes()
    if raw[:2] == b"\x1f\x8b":
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError) as exc:
            raise InputError(f"{path.name}: broken gzip file ({exc})") from None
    if raw[:8] == b"\x89HDF\r\n\x1a\n":
        return read_asdf(io.BytesIO(raw), path.name)
    first_line = raw[:200].decode("latin-1").upper().split("\n", 1)[0]
    if "UNCORRECTED ACCELEROGRAM" in first_line:
        return read_dmg_v1(raw.decode("latin-1"), path.name)
    if first_line.startswith("PEER"):
        return read_at2_group(path)
    return read_obspy(path)


def is_pattern(path):
    """True if ``path`` is a glob pattern (contains *, ? or [)."""
    return any(char in str(path) for char in "*?[")


# ---------------------------------------------------------------- obspy formats
def read_obspy(path):
    """MiniSEED, SAC, ... via obspy; orientation from channel codes or SAC cmpaz/cmpinc."""
    try:
        stream = obspy.read(str(path))
    except Exception as exc:  # obspy raises many types for unknown formats
        raise InputError(f"{Path(path).name}: not a readable record file ({type(exc).__name__})") \
            from None
    stations = {(tr.stats.network, tr.stats.station, tr.stats.location, tr.stats.channel[:2])
                for tr in stream}
    if len(stations) > 1:
        raise InputError(f"{Path(path).name}: holds {len(stations)} stations or instruments; "
                         "give one record per file")
    stream.merge(method=0)  # gaps become masked arrays, rejected later
    info = {}
    for tr in stream:
        sac = tr.stats.get("sac")
        azimuth, dip = _orientation_from_code(tr.stats.channel)
        if sac is not None and "cmpaz" in sac and "cmpinc" in sac:
            # SAC: cmpinc is measured from vertical up (0 = up, 90 = horizontal)
            azimuth, dip = float(sac.cmpaz) % 360.0, float(sac.cmpinc) - 90.0
        if azimuth is None:
            raise InputError(f"{Path(path).name}: channel {tr.id} has no azimuth "
                             "(use E/N/Z channel codes or SAC cmpaz/cmpinc)")
        tr.stats.azimuth, tr.stats.dip = azimuth, dip
        if sac is not None:
            info.update(_sac_info(sac))
    first = stream[0].stats if len(stream) else None
    if first is not None:
        info.setdefault("station", ".".join(p for p in (first.network, first.station) if p))
    return stream, info


def _orientation_from_code(channel):
    """(azimuth, dip) from the last letter of a SEED channel code; azimuth None if unknown."""
    code = channel[-1:].upper()
    if code == "Z":
        return 0.0, VERTICAL_UP
    if code == "N":
        return 0.0, 0.0
    if code == "E":
        return 90.0, 0.0
    return None, 0.0


def _sac_info(sac):
    names = {"stla": "station_lat", "stlo": "station_lon", "evla": "event_lat",
             "evlo": "event_lon", "mag": "magnitude"}
    info = {new: float(sac[old]) for old, new in names.items() if old in sac}
    if "kstnm" in sac:
        info["station"] = sac.kstnm.strip()
    if "kevnm" in sac and sac.kevnm.strip():
        info["event"] = sac.kevnm.strip()
    return info


# ---------------------------------------------------------------- PEER AT2
def read_at2_group(path):
    """A PEER ``.AT2`` file plus its sibling components (same header line 2 up to the last comma).

    Header line 2 reads e.g. ``Kocaeli Turkey, 8/17/1999, Izmit, 90``; the last
    field is the component: an azimuth in degrees, UP/DWN (vertical), or N/E.
    """
    path = Path(path)
    prefix, _ = _at2_title(path)
    siblings = sorted(p for p in path.parent.iterdir()
                      if p.is_file() and p.suffix.lower() == ".at2")
    stream = Stream()
    for sibling in siblings:
        try:
            other_prefix, component = _at2_title(sibling)
        except InputError:
            continue
        if other_prefix != prefix:
            continue
        trace = read_at2(sibling)
        trace.stats.azimuth, trace.stats.dip = _at2_orientation(component, sibling)
        stream.append(trace)
    parts = [p.strip() for p in prefix.split(",")]
    info = {"event": parts[0]} if parts and parts[0] else {}
    if len(parts) >= 2:
        info["station"] = parts[-1]
    return stream, info


def _at2_title(path):
    with open(path, encoding="latin-1") as handle:
        first, second = handle.readline(), handle.readline()
    if not first.upper().startswith("PEER") or "," not in second:
        raise InputError(f"{path.name}: not a PEER AT2 file (header)")
    prefix, component = second.strip().rsplit(",", 1)
    return prefix.strip(), component.strip()


def _at2_orientation(component, path):
    token = component.upper().replace("-", "")
    if re.fullmatch(r"\d{1,3}", token):
        return float(token) % 360.0, 0.0
    if token in {"UP", "UPDO", "V", "VER", "Z"}:
        return 0.0, VERTICAL_UP
    if token in {"DWN", "DOWN"}:
        return 0.0, VERTICAL_DOWN
    if token in {"N", "NS"}:
        return 0.0, 0.0
    if token in {"E", "EW"}:
        return 90.0, 0.0
    raise InputError(f"{path.name}: component {component!r} has no known azimuth")


def read_at2(path):
    """One PEER AT2 component as an obspy Trace in m/s^2 (stats.azimuth not set)."""
    path = Path(path)
    lines = path.read_text(encoding="latin-1").splitlines()
    if len(lines) < 5 or not lines[0].upper().startswith("PEER"):
        raise InputError(f"{path.name}: not a PEER AT2 file")
    if "UNITS OF G" not in lines[2].upper():
        raise InputError(f"{path.name}: AT2 units not in g ({lines[2].strip()})")
    match = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([0-9.Ee+-]+)", lines[3].upper())
    if not match:
        raise InputError(f"{path.name}: AT2 line 4 lacks NPTS and DT")
    npts, dt = int(match.group(1)), float(match.group(2))
    try:
        values = np.array(" ".join(lines[4:]).split(), dtype=float)
    except ValueError:
        raise InputError(f"{path.name}: non-numeric AT2 samples") from None
    if values.size != npts or dt <= 0:
        raise InputError(f"{path.name}: AT2 has {values.size} samples, header says {npts}")
    trace = Trace(values * G)
    trace.stats.delta = dt
    trace.stats.channel = lines[1].rsplit(",", 1)[-1].strip()[:8]
    return trace


# ---------------------------------------------------------------- CSMIP / DMG V1
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
    scale = {"G": G, "CM/SEC/SEC": 0.01, "CM/S/S": 0.01}.get(unit)
    if scale is None:
        raise InputError(f"{name}: DMG V1 unit {unit!r} not supported")
    n_lines = -(-npts // per_line)
    body = lines[data_line + 1:data_line + 1 + n_lines]
    try:
        values = np.array([float(line[k:k + width]) for line in body
                           for k in range(0, per_line * width, width) if line[k:k + width].strip()])
    except ValueError:
        raise InputError(f"{name}: non-numeric DMG V1 samples after line {data_line + 1}") from None
    if values.size != npts:
        raise InputError(f"{name}: DMG V1 channel has {values.size} samples, header says {npts}")

    trace = Trace(values * scale)
    trace.stats.sampling_rate = rate
    start_time = re.search(r"START TIME:\s*(\d+)/(\d+)/(\d+),\s*(\d+):\s*(\d+):\s*([\d.]+)",
                           header[3].upper())
    if start_time:
        month, day, year, hour, minute = (int(v) for v in start_time.groups()[:5])
        trace.stats.starttime = UTCDateTime(2000 + year if year < 70 else 1900 + year,
                                            month, day, hour, minute) + float(start_time.group(6))
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


# ---------------------------------------------------------------- ASDF / HDF5
def read_asdf(source, name="ASDF file"):
    """ASDF (HDF5): raw waveforms of one station with StationXML (sensitivity, orientation)
    and QuakeML (epicentre, magnitude).  Uses the ``*_unprocessed``/``raw_recording`` tag."""
    import h5py
    try:
        h5 = h5py.File(source, "r")
    except OSError as exc:
        raise InputError(f"{name}: unreadable HDF5 file ({exc})") from None
    with h5:
        if "Waveforms" not in h5 or len(h5["Waveforms"]) != 1:
            raise InputError(f"{name}: ASDF file must hold exactly one station under Waveforms")
        group = next(iter(h5["Waveforms"].values()))
        if "StationXML" not in group:
            raise InputError(f"{name}: ASDF station has no StationXML")
        inventory = obspy.read_inventory(io.BytesIO(group["StationXML"][()].tobytes()))
        stream = Stream()
        for key, dataset in group.items():
            if key == "StationXML" or not key.endswith(("_unprocessed", "__raw_recording")):
                continue
            network, station, location, channel = key.split("__")[0].split(".")
            trace = Trace(np.asarray(dataset[()], dtype=np.float64))
            trace.stats.update({"network": network, "station": station, "location": location,
                                "channel": channel,
                                "sampling_rate": float(dataset.attrs["sampling_rate"]),
                                "starttime": UTCDateTime(int(dataset.attrs["starttime"]) * 1e-9)})
            stream.append(trace)
        events = (obspy.read_events(io.BytesIO(h5["QuakeML"][()].tobytes()))
                  if "QuakeML" in h5 else [])
    if not stream:
        raise InputError(f"{name}: no raw waveforms (tag unprocessed/raw_recording) found")
    try:
        stream.remove_sensitivity(inventory)
    except Exception as exc:
        raise InputError(f"{name}: no instrument sensitivity for the waveforms ({exc})") from None
    for trace in stream:
        channel = inventory.select(channel=trace.stats.channel)[0][0][0]
        if channel.response.instrument_sensitivity.input_units.upper() not in {"M/S**2", "M/S2"}:
            raise InputError(f"{name}: {trace.id} is not an accelerometer channel")
        azimuth, dip = _orientation_from_code(trace.stats.channel)
        if channel.azimuth is not None and azimuth is not None:
            azimuth = channel.azimuth
        if channel.dip is not None:
            dip = channel.dip
        if azimuth is None:
            raise InputError(f"{name}: channel {trace.id} has no azimuth")
        trace.stats.azimuth, trace.stats.dip = azimuth, dip
    site = inventory[0][0]
    info = {"station": f"{inventory[0].code}.{site.code}", "station_lat": site.latitude,
            "station_lon": site.longitude}
    if events:
        origin = events[0].preferred_origin() or events[0].origins[0]
        info.update(event_lat=origin.latitude, event_lon=origin.longitude,
                    origin_time=str(origin.time))
        if events[0].magnitudes:
            info["magnitude"] = events[0].magnitudes[0].mag
    return stream, info


# ---------------------------------------------------------------- FEMA P695 compact file
def read_fema_p695(path, key):
    """Record ``key`` (``FF01``-``FF22``, ``NF01``-``NF28``) of the compact FEMA P695 file.

    Two horizontal components (g in the file); the set has no verticals.  The
    orientation of each component comes from the catalogue (see records/README.md),
    so ``stats.azimuth`` is None here and the caller sets it.
    """
    with np.load(path, allow_pickle=False) as archive:
        meta = json.loads(str(archive["metadata"]))["records"]
        if key not in meta:
            raise InputError(f"{Path(path).name}: no record {key!r} (known: FF01-FF22, NF01-NF28)")
        entry = meta[key]
        stream = Stream()
        for comp, comp_meta in entry["components"].items():
            trace = Trace(archive[f"{key}_{comp}"].astype(np.float64) * G)
            trace.stats.delta = comp_meta["dt"]
            trace.stats.channel = comp_meta["name"].split("/")[-1]
            trace.stats.azimuth, trace.stats.dip = None, 0.0
            stream.append(trace)
    info = {"event": f"{entry['EarthquakeName']} {entry['EarthquakeYear']}",
            "station": entry["RecordingStationName"], "magnitude": entry["EarthquakeMagnitude"],
            "lowest_usable_hz": entry["LowestUsableFrequency"]}
    return stream, info
