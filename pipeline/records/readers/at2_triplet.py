"""PEER NGA-West2 triplets ``RSN<n>_1.AT2``, ``_2``, ``_3`` (H1, H2, vertical; gzip allowed)
with the NGA-West2 flatfile row of record sequence number ``n``.

Each AT2 file is::

    PEER NGA STRONG MOTION DATABASE RECORD
    Gazli USSR, 5/17/1976, Karakyr, 0          <- event, date, station, component
    ACCELERATION TIME SERIES IN UNITS OF G
    NPTS=   2048, DT=   .0066 SEC,
    .1717907E-01   .1723899E-01 ...          <- NPTS samples in g

The component is an azimuth in degrees, ``UP``/``V`` (vertical, positive up)
or ``DWN`` (positive down).  ``NA`` takes the azimuth from the flatfile (the
one of its H1/H2 azimuths the other horizontal does not use).  ``L``/``T``
(longitudinal/transverse of undocumented azimuth) are read as 0/90 deg with
``horizontals_compass`` False.

The flatfile rows are ``flatfile_rows.csv`` beside the files, else the shipped
``records/ngawest2/flatfile_rows.csv`` (written by
``records/tools/extract_nearsource.py``), looked up by the RSN of the file
name.  ``key`` may name the RSN (``"RSN126"`` or ``"126"``; it must agree with
the file name) or a flatfile CSV to use instead.  The row must name the
station of the AT2 header.  It gives station and hypocentre coordinates, Mw,
mechanism and the usable band: ``lowest_usable_hz`` is the flatfile's lowest
usable frequency (NGA-West2: 1.25 x the larger high-pass corner of the
horizontals), ``highest_usable_hz`` the smaller low-pass corner of the
horizontals where the flatfile gives the corners.

Only files named ``RSN<n>_<1|2|3>.AT2[.gz]`` are detected, so other AT2 files
stay with the generic AT2 reader.
"""
import csv
import io
import re
from pathlib import Path

import numpy as np
from obspy import Stream, Trace

from pipeline.files import InputError
from pipeline.records.readers._text import (
    STANDARD_GRAVITY, VERTICAL_DOWN, VERTICAL_UP, head_text, number, one_line, open_text)

FORMAT = "at2-triplet"
PRIORITY = 40  # before the generic AT2 reader (50)

SHIPPED_FLATFILE = (Path(__file__).resolve().parents[3] / "records" / "ngawest2"
                    / "flatfile_rows.csv")
_NAME = re.compile(r"^RSN(\d+)_([123])\.AT2(\.gz)?$", re.I)
_NPTS_DT = re.compile(r"NPTS\s*=\s*([^,]*?)\s*,\s*DT\s*=\s*(.*?)\s*SEC", re.I)


def detect(path, head):
    return bool(_NAME.match(Path(path).name)) and head_text(head, 40).upper().startswith("PEER")


def read(path, key=None):
    path = Path(path)
    match = _NAME.match(path.name)
    if not match:
        raise InputError(f"{path.name}: not named RSN<n>_<1|2|3>.AT2")
    rsn = int(match.group(1))
    flatfile = None
    if key is not None:
        key_text = str(key).strip()
        if key_text.lower().endswith(".csv"):
            flatfile = Path(key_text)
            if not flatfile.is_file():
                raise InputError(f"flatfile not found: {flatfile}")
        else:
            key_rsn = re.fullmatch(r"(?:RSN)?\s*(\d+)", key_text, re.I)
            if not key_rsn or int(key_rsn.group(1)) != rsn:
                raise InputError(f"{path.name}: key {key_text!r} does not name RSN{rsn}")
    row = _flatfile_row(rsn, path, flatfile)

    files = {k: _sibling(path, rsn, k) for k in (1, 2, 3)}
    no_vertical = row is not None and _missing(row.get("file_name_v"))
    for k, file in files.items():
        if file is None and not (k == 3 and no_vertical):
            raise InputError(f"{path.name}: RSN{rsn}_{k}.AT2 missing beside it "
                             "(missing component: a triplet needs _1, _2 and _3)")
    comps = [_read_component(files[k], k) for k in (1, 2, 3) if files[k] is not None]

    first = comps[0]
    for comp in comps[1:]:
        if comp["prefix"] != first["prefix"]:
            raise InputError(f"{comp['name']}: header '{comp['prefix']}' is not the recording "
                             f"of {first['name']} ('{first['prefix']}')")
        if comp["dt"] != first["dt"]:
            raise InputError(f"{comp['name']}: DT {comp['dt']:g} s differs from {first['name']} "
                             f"({first['dt']:g} s)")
    parts = [p.strip() for p in first["prefix"].split(",")]
    header_event, header_station = parts[0], parts[-1] if len(parts) >= 3 else ""
    if row is not None and _normalise(row.get("station", "")) != _normalise(header_station):
        raise InputError(f"{first['name']}: header station {header_station!r} is not the "
                         f"flatfile station {row.get('station')!r} of RSN{rsn}")

    notes = []
    compass = _orient(comps, row, rsn, notes)
    _check_duplicates(comps)

    stream = Stream()
    for comp in comps:
        trace = Trace(comp["values"] * STANDARD_GRAVITY)
        trace.stats.delta = comp["dt"]
        trace.stats.station = f"RSN{rsn}"
        trace.stats.channel = comp["channel"]
        trace.stats.azimuth, trace.stats.dip = comp["azimuth"], comp["dip"]
        stream.append(trace)

    info = {"station": header_station or f"RSN{rsn}", "event": header_event,
            "horizontals_compass": compass}
    if row is not None:
        info.update(_row_info(row))
    else:
        notes.append(f"no NGA-West2 flatfile row for RSN{rsn}: no coordinates or usable band")
    if notes:
        info["notes"] = "; ".join(notes)
    return stream, info


# ---------------------------------------------------------------- files
def _sibling(path, rsn, k):
    for name in (f"RSN{rsn}_{k}.AT2", f"RSN{rsn}_{k}.AT2.gz"):
        for candidate in (path.parent / name, path.parent / name.lower(),
                          path.parent / name.replace(".AT2", ".at2")):
            if candidate.is_file():
                return candidate
    return None


def _read_component(path, index):
    name = path.name
    lines = open_text(path).splitlines()
    if len(lines) < 4 or not lines[0].upper().startswith("PEER"):
        raise InputError(f"{name}: not a PEER AT2 file (line 1 should start with PEER)")
    if "," not in lines[1]:
        raise InputError(f"{name}: AT2 line 2 should read 'event, date, station, component'")
    prefix, component = (s.strip() for s in lines[1].rsplit(",", 1))
    if "UNITS OF G" not in lines[2].upper():
        raise InputError(f"{name}: AT2 units not g ({one_line(lines[2])[:60]!r})")
    match = _NPTS_DT.search(lines[3])
    if not match:
        raise InputError(f"{name}: AT2 line 4 lacks 'NPTS= n, DT= dt SEC' "
                         f"({one_line(lines[3])[:60]!r})")
    try:
        npts = int(match.group(1))
    except ValueError:
        raise InputError(f"{name}: AT2 NPTS {match.group(1)!r} is not an integer") from None
    if npts <= 0:
        raise InputError(f"{name}: AT2 NPTS {npts} is not positive")
    dt = number(match.group(2), "AT2 DT", name)
    if dt <= 0:
        raise InputError(f"{name}: AT2 DT {dt:g} s is not a positive time step")
    tokens = " ".join(lines[4:]).split()
    try:
        values = np.array(tokens, dtype=float)
    except ValueError:
        bad = next(t for t in tokens if not _is_float(t))
        raise InputError(f"{name}: non-numeric AT2 sample {bad[:20]!r}") from None
    if values.size != npts:
        raise InputError(f"{name}: AT2 has {values.size} samples, header NPTS={npts}")
    if not np.all(np.isfinite(values)):
        raise InputError(f"{name}: AT2 has non-finite samples")
    return {"name": name, "index": index, "prefix": prefix, "component": component,
            "npts": npts, "dt": dt, "values": values}


def _is_float(token):
    try:
        float(token)
        return True
    except ValueError:
        return False


# ---------------------------------------------------------------- orientation
def _orient(comps, row, rsn, notes):
    """Set azimuth/dip/channel of each component; returns horizontals_compass."""
    compass = True
    pending_na = []
    for comp in comps:
        token = comp["component"].upper().replace("-", "").replace(" ", "")
        comp["channel"] = comp["component"]
        if re.fullmatch(r"\d{1,3}(\.\d+)?", token):
            comp["azimuth"], comp["dip"] = float(token) % 360.0, 0.0
        elif token in {"UP", "V", "VER", "VERT", "Z"}:
            comp["azimuth"], comp["dip"] = 0.0, VERTICAL_UP
            if token != "UP":
                notes.append(f"vertical '{comp['component']}' taken as positive up")
        elif token in {"DWN", "DOWN", "DN"}:
            comp["azimuth"], comp["dip"] = 0.0, VERTICAL_DOWN
        elif token in {"L", "T"}:
            comp["azimuth"], comp["dip"] = (0.0 if token == "L" else 90.0), 0.0
            compass = False
        elif token in {"N", "NS"}:
            comp["azimuth"], comp["dip"] = 0.0, 0.0
        elif token in {"E", "EW"}:
            comp["azimuth"], comp["dip"] = 90.0, 0.0
        elif token in {"NA", ""}:
            pending_na.append(comp)
        else:
            raise InputError(f"{comp['name']}: component {comp['component']!r} has no known "
                             "azimuth")
    if not compass:
        notes.append("horizontal components L/T (longitudinal/transverse) of unknown azimuth: "
                     "read as 0/90 deg, directions are not compass directions")
    flat = _flatfile_azimuths(row)
    for comp in pending_na:
        others = {c["azimuth"] for c in comps if "azimuth" in c and c["dip"] == 0.0}
        candidates = [a for a in flat if a not in others]
        if len(candidates) != 1:
            raise InputError(f"{comp['name']}: component 'NA' and the flatfile gives no "
                             f"azimuth for it (RSN{rsn})")
        comp["azimuth"], comp["dip"] = candidates[0], 0.0
        comp["channel"] = f"{candidates[0]:03.0f}"
        notes.append(f"{comp['name']}: component 'NA' in the header, azimuth "
                     f"{candidates[0]:g} deg from the flatfile")
    header = {c["azimuth"] for c in comps if c["dip"] == 0.0}
    if compass and len(flat) == 2 and not pending_na and header != set(flat):
        notes.append(f"header azimuths {sorted(header)} differ from the flatfile's "
                     f"{sorted(flat)}; header used")
    return compass


def _flatfile_azimuths(row):
    if row is None:
        return []
    out = []
    for col in ("h1_azimuth_deg", "h2_azimuth_deg"):
        value = row.get(col, "")
        if value not in ("", None):
            out.append(float(value) % 360.0)
    return out


def _check_duplicates(comps):
    horizontals = [c for c in comps if c["dip"] == 0.0]
    verticals = [c for c in comps if c["dip"] != 0.0]
    for i, a in enumerate(comps):
        for b in comps[i + 1:]:
            if a["values"].size == b["values"].size and np.array_equal(a["values"], b["values"]):
                raise InputError(f"{b['name']}: same samples as {a['name']} (duplicated "
                                 "component; the file of one component is missing)")
    if len(horizontals) != 2 or len(verticals) > 1:
        raise InputError(f"{comps[0]['name']}: components "
                         f"{', '.join(c['component'] for c in comps)}: need two horizontals "
                         "and one vertical")
    a, b = horizontals
    if abs((a["azimuth"] - b["azimuth"] + 90.0) % 180.0 - 90.0) < 1e-6:
        raise InputError(f"{b['name']}: duplicated component: azimuth {b['azimuth']:g} is the "
                         f"axis of {a['name']}")


# ---------------------------------------------------------------- flatfile
def _flatfile_row(rsn, path, flatfile):
    candidates = [flatfile] if flatfile else [path.parent / "flatfile_rows.csv", SHIPPED_FLATFILE]
    for candidate in candidates:
        if candidate is None or not candidate.is_file():
            continue
        rows = _load_flatfile(candidate)
        if rsn in rows:
            return rows[rsn]
    return None


_CACHE = {}


def _load_flatfile(path):
    stat = path.stat()
    cache_key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    if cache_key not in _CACHE:
        text = open_text(path)
        rows = {}
        for row in csv.DictReader(io.StringIO(text)):
            try:
                rows[int(row["rsn"])] = row
            except (KeyError, TypeError, ValueError):
                raise InputError(f"{path.name}: flatfile rows need an integer 'rsn' column") \
                    from None
        _CACHE.clear()
        _CACHE[cache_key] = rows
    return _CACHE[cache_key]


def _row_info(row):
    def value(col):
        text = (row.get(col) or "").strip()
        if text in ("", "-999", "-999.0"):
            return None
        try:
            return float(text)
        except ValueError:
            return None

    info = {}
    for out, col in (("station_lat", "station_lat"), ("station_lon", "station_lon"),
                     ("event_lat", "hypo_lat"), ("event_lon", "hypo_lon"),
                     ("event_depth_km", "hypo_depth_km"), ("magnitude", "magnitude"),
                     ("lowest_usable_hz", "lowest_usable_hz")):
        v = value(col)
        if v is not None:
            info[out] = v
    lowpass = [v for v in (value("lp_h1_hz"), value("lp_h2_hz")) if v]
    if lowpass:
        info["highest_usable_hz"] = min(lowpass)
    if row.get("event"):
        info["event"] = row["event"]
    if row.get("mechanism"):
        info["mechanism"] = row["mechanism"]
    if value("pga_g") is not None and value("pgv_cm_s") is not None:
        info["peer"] = {"measure": "RotD50", "source": "NGA-West2 flatfile",
                        "rsn": int(value("rsn")) if value("rsn") else None,
                        "pga_ms2": value("pga_g") * STANDARD_GRAVITY,
                        "pgv_ms": value("pgv_cm_s") / 100.0, "pulse_like": None}
    return info


def _missing(value):
    return value is None or str(value).strip() in ("", "-999", "nan")


def _normalise(name):
    return re.sub(r"[^a-z0-9]", "", str(name).lower())
