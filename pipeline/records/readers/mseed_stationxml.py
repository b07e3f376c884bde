"""MiniSEED in counts with its StationXML and event file beside it.

Layout (as in ``records/ridgecrest2019_mseed/``)::

    CI.CCC..HNE.mseed  CI.CCC..HNN.mseed  CI.CCC..HNZ.mseed   one channel per file
    CI.CCC.xml(.gz)                                           StationXML of CI.CCC
    event.json                                                the earthquake

``path`` is one MiniSEED file holding all channels of a station or a glob
pattern of its single-channel files (``CI.CCC..HN?.mseed``).  The StationXML
is ``<NET>.<STA>.xml`` (gzip allowed) in the same directory, network and
station taken from the MiniSEED header.  Each channel is found in it by id and
time; the counts are divided by the instrument sensitivity
(``remove_sensitivity``), which must have acceleration input units; azimuth
and dip come from the channel, coordinates from the station.

The event file is ``event.json`` (flat ComCat-like ``{"id", "time", "lat",
"lon", "depth", "magnitude"}`` or a GeoJSON feature) or QuakeML
(``event.xml``/``*.quakeml``); without one the info has no event keys.
"""
import glob
import io
import json
import warnings
from pathlib import Path

import obspy
from obspy import Stream, UTCDateTime

from pipeline.files import InputError
from pipeline.records.readers._text import one_line, read_bytes, strip_gz

FORMAT = "mseed-stationxml"
PRIORITY = 60  # before the generic obspy reader (100), which knows no sensitivity

_ACCELERATION_UNITS = {"M/S**2": 1.0, "M/S2": 1.0, "M/S/S": 1.0, "M/S^2": 1.0, "M/SEC**2": 1.0,
                       "CM/S**2": 0.01, "CM/S2": 0.01, "CM/S/S": 0.01, "CM/S^2": 0.01}


def detect(path, head):
    ids = _miniseed_ids(head)
    if ids is None:
        return False
    return _stationxml_path(Path(path), *ids) is not None


def read(path, key=None):
    """(stream in m/s^2, info); ``key`` is not used."""
    path = Path(path)
    files = _files(path)
    stream = Stream()
    origin_file = {}
    for file in files:
        raw = read_bytes(file)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                part = obspy.read(io.BytesIO(raw), format="MSEED")
            except Exception as exc:  # obspy raises many types for broken input
                raise InputError(f"{file.name}: not a readable MiniSEED file "
                                 f"({type(exc).__name__})") from None
        problems = [w for w in caught if "MSEED" in type(w.message).__name__.upper()
                    or "mseed" in str(w.message).lower()]
        if problems:  # obspy reads what it can of a truncated or corrupt file and warns
            raise InputError(f"{file.name}: truncated or corrupt MiniSEED "
                             f"({one_line(problems[0].message)[:100]})")
        # a file cut between records reads without a warning: its records must fill it
        in_records = sum(tr.stats.mseed.number_of_records * tr.stats.mseed.record_length
                         for tr in part if "mseed" in tr.stats)
        if in_records != len(raw):
            raise InputError(f"{file.name}: truncated or corrupt MiniSEED ({in_records} of "
                             f"{len(raw)} bytes in complete records)")
        for trace in part:
            origin_file.setdefault(trace.id, []).append(file.name)
        stream += part
    if not stream:
        raise InputError(f"{path.name}: no MiniSEED data")
    stations = {(tr.stats.network, tr.stats.station, tr.stats.location, tr.stats.channel[:2])
                for tr in stream}
    if len(stations) > 1:
        raise InputError(f"{path.name}: holds {len(stations)} stations or instruments "
                         f"({', '.join(sorted('.'.join(s) for s in stations))}); give one record")
    for trace_id, names in origin_file.items():
        if len(names) > 1:
            where = (f"in files {', '.join(sorted(set(names)))}" if len(set(names)) > 1
                     else f"{len(names)} segments in {names[0]}")
            kind = "duplicated channel" if len(set(names)) > 1 else "gaps or overlaps"
            raise InputError(f"{path.name}: {kind}: {trace_id} {where}")

    network, station = stream[0].stats.network, stream[0].stats.station
    xml_path = _stationxml_path(path, network, station)
    if xml_path is None:
        raise InputError(f"{path.name}: no StationXML {network}.{station}.xml beside it")
    inventory = _read_inventory(xml_path)

    for trace in stream:
        _calibrate(trace, inventory, xml_path.name)
    hint = "" if len(files) > 1 else f" (for one file per channel give a glob such as " \
        f"{network}.{station}..{stream[0].stats.channel[:2]}?.mseed)"
    _check_components(stream, path.name, hint)

    site = inventory.select(network=network, station=station)[0][0]
    info = {"station": f"{network}.{station}", "station_lat": float(site.latitude),
            "station_lon": float(site.longitude), "horizontals_compass": True}
    info.update(_event_info(path.parent, stream))
    return stream, info


# ---------------------------------------------------------------- files
def _files(path):
    if any(char in str(path) for char in "*?["):
        files = [Path(p) for p in sorted(glob.glob(str(path)))]
        if not files:
            raise InputError(f"no MiniSEED files match {path}")
        return files
    if not path.is_file():
        raise InputError(f"MiniSEED file not found: {path}")
    return [path]


def _miniseed_ids(head):
    """(network, station) from a MiniSEED 2 fixed header, or from a MiniSEED 3 source id;
    None if ``head`` is not MiniSEED."""
    if len(head) >= 48 and head[6:7] in (b"D", b"R", b"Q", b"M") and head[7:8] in (b" ", b"\0") \
            and all(c in b"0123456789 \0" for c in head[:6]):
        text = head[8:20].decode("latin-1")
        station, network = text[0:5].strip(), text[10:12].strip()
        if station.isalnum() and (network.isalnum() or network == ""):
            return network, station
        return None
    if head[:2] == b"MS" and head[2:3] == b"\x03" and len(head) >= 40:
        sid_len = head[33]
        sid = head[40:40 + sid_len].decode("latin-1")  # FDSN:NET_STA_LOC_B_S_SS
        parts = sid.removeprefix("FDSN:").split("_")
        if len(parts) >= 2:
            return parts[0], parts[1]
    return None


def _stationxml_path(path, network, station):
    for name in (f"{network}.{station}.xml", f"{network}.{station}.xml.gz"):
        candidate = path.parent / name
        if candidate.is_file():
            return candidate
    return None


def _read_inventory(xml_path):
    try:
        return obspy.read_inventory(io.BytesIO(read_bytes(xml_path)), format="STATIONXML")
    except InputError:
        raise
    except Exception as exc:
        raise InputError(f"{xml_path.name}: not a readable StationXML file "
                         f"({type(exc).__name__}: {one_line(exc)[:80]})") from None


# ---------------------------------------------------------------- calibration, orientation
def _calibrate(trace, inventory, xml_name):
    st = trace.stats
    selected = inventory.select(network=st.network, station=st.station, location=st.location,
                                channel=st.channel, time=st.starttime)
    channels = [cha for net in selected for sta in net for cha in sta]
    if not channels:
        raise InputError(f"{strip_gz(xml_name)}: no channel {trace.id} at {st.starttime.date} "
                         "(StationXML lacks the channel)")
    if len(channels) > 1:
        raise InputError(f"{strip_gz(xml_name)}: {len(channels)} epochs of {trace.id} cover "
                         f"{st.starttime}")
    channel = channels[0]
    sensitivity = channel.response.instrument_sensitivity if channel.response else None
    if sensitivity is None or not sensitivity.value:
        raise InputError(f"{strip_gz(xml_name)}: channel {trace.id} has no response "
                         "(instrument sensitivity)")
    units = (sensitivity.input_units or "").upper().replace(" ", "")
    if units not in _ACCELERATION_UNITS:
        raise InputError(f"{strip_gz(xml_name)}: channel {trace.id} measures "
                         f"{sensitivity.input_units or 'unknown units'}, not acceleration")
    if channel.azimuth is None or channel.dip is None:
        raise InputError(f"{strip_gz(xml_name)}: channel {trace.id} has no azimuth or dip")
    trace.data = trace.data.astype("float64")
    trace.remove_sensitivity(inventory=selected)
    trace.data *= _ACCELERATION_UNITS[units]
    dip = float(channel.dip)
    if abs(dip) not in (0.0, 90.0):
        raise InputError(f"{strip_gz(xml_name)}: channel {trace.id} dips {dip:g} deg: neither "
                         "horizontal nor vertical")
    st.azimuth = float(channel.azimuth) % 360.0 if dip == 0.0 else 0.0
    st.dip = dip


def _check_components(stream, name, hint=""):
    seen = {}
    for tr in stream:
        key = ("V",) if tr.stats.dip != 0.0 else ("H", round(tr.stats.azimuth % 180.0, 3))
        if key in seen:
            raise InputError(f"{name}: duplicated component: {seen[key]} and {tr.id} share "
                             "one axis")
        seen[key] = tr.id
    horizontals = sum(tr.stats.dip == 0.0 for tr in stream)
    if horizontals != 2 or len(stream) != 3:
        chans = ", ".join(tr.stats.channel for tr in stream)
        raise InputError(f"{name}: has channels {chans}; a record needs two horizontals and one "
                         f"vertical (missing component){hint}")


# ---------------------------------------------------------------- event
def _event_info(directory, stream):
    for name in ("event.json", "event.json.gz"):
        if (directory / name).is_file():
            info = _event_json(directory / name)
            break
    else:
        quakeml = [p for p in sorted(directory.iterdir())
                   if p.name.lower() in ("event.xml", "event.xml.gz")
                   or strip_gz(p.name.lower()).endswith(".quakeml")]
        if not quakeml:
            return {}
        info = _event_quakeml(quakeml[0])
    origin = UTCDateTime(info["origin_time"])
    start = min(tr.stats.starttime for tr in stream)
    end = max(tr.stats.endtime for tr in stream)
    if not start - 3600.0 <= origin <= end:
        raise InputError(f"event file: origin time {origin} is not within the record "
                         f"({start} - {end}); wrong event?")
    return info


def _event_json(path):
    try:
        data = json.loads(read_bytes(path).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path.name}: not valid JSON ({one_line(exc)})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path.name}: not a JSON object")
    if data.get("type") == "Feature":  # ComCat GeoJSON
        props = data.get("properties") or {}
        coords = (data.get("geometry") or {}).get("coordinates")
        if not coords or len(coords) < 2:
            raise InputError(f"{path.name}: GeoJSON feature without coordinates")
        time = props.get("time")
        data = {"id": data.get("id"), "lon": coords[0], "lat": coords[1],
                "depth": coords[2] if len(coords) > 2 else None, "magnitude": props.get("mag"),
                "time": UTCDateTime(time / 1000.0) if isinstance(time, (int, float)) else time,
                "title": props.get("title")}
    info = {}
    fields = {"event_lat": ("lat", "latitude"), "event_lon": ("lon", "longitude"),
              "event_depth_km": ("depth", "depth_km"), "magnitude": ("magnitude", "mag")}
    for out, names in fields.items():
        value = next((data[n] for n in names if data.get(n) is not None), None)
        if value is None:
            if out in ("event_lat", "event_lon"):
                raise InputError(f"{path.name}: no {names[0]}")
            continue
        try:
            info[out] = float(value)
        except (TypeError, ValueError):
            raise InputError(f"{path.name}: {names[0]} {value!r} is not a number") from None
    if not (-90 <= info["event_lat"] <= 90 and -180 <= info["event_lon"] <= 360):
        raise InputError(f"{path.name}: impossible epicentre {info['event_lat']}, "
                         f"{info['event_lon']}")
    if data.get("time") is None:
        raise InputError(f"{path.name}: no origin time")
    try:
        info["origin_time"] = UTCDateTime(str(data["time"])).isoformat()
    except Exception:
        raise InputError(f"{path.name}: unreadable origin time {data['time']!r}") from None
    event = data.get("title") or data.get("name") or data.get("id")
    if event:
        info["event"] = str(event)
    return info


def _event_quakeml(path):
    try:
        catalog = obspy.read_events(io.BytesIO(read_bytes(path)))
    except Exception as exc:
        raise InputError(f"{path.name}: not a readable QuakeML file ({type(exc).__name__})") \
            from None
    if len(catalog) != 1:
        raise InputError(f"{path.name}: holds {len(catalog)} events; give one")
    event = catalog[0]
    origin = event.preferred_origin() or (event.origins[0] if event.origins else None)
    if origin is None or origin.latitude is None or origin.longitude is None:
        raise InputError(f"{path.name}: event without an origin")
    info = {"event_lat": float(origin.latitude), "event_lon": float(origin.longitude),
            "origin_time": origin.time.isoformat(),
            "event": str(event.resource_id).split("/")[-1]}
    if origin.depth is not None:
        info["event_depth_km"] = origin.depth / 1000.0
    magnitude = event.preferred_magnitude() or (event.magnitudes[0] if event.magnitudes else None)
    if magnitude is not None:
        info["magnitude"] = float(magnitude.mag)
    return info
