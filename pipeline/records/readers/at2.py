"""PEER NGA ``.AT2`` files: one component per file, in g.

Header line 2 reads e.g. ``Kocaeli Turkey, 8/17/1999, Izmit, 90``: the sibling
files of the same recording share it up to the last comma, whose field is the
component (an azimuth in degrees, UP/DWN, or N/E).
"""
import re
from pathlib import Path

import numpy as np
from obspy import Stream, Trace

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records.readers import HEAD_BYTES, VERTICAL_DOWN, VERTICAL_UP, read_bytes
from pipeline.records.readers._text import counted_samples

FORMAT = "at2"
PRIORITY = 50


def detect(path, head):
    return head[:200].decode("latin-1").upper().startswith("PEER")


def read(path, key=None):
    return read_at2_group(Path(path))


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
    first, second = (read_bytes(path)[:HEAD_BYTES].decode("latin-1").splitlines() + ["", ""])[:2]
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
    lines = read_bytes(path).decode("latin-1").splitlines()
    if len(lines) < 5 or not lines[0].upper().startswith("PEER"):
        raise InputError(f"{path.name}: not a PEER AT2 file")
    if "UNITS OF G" not in lines[2].upper():
        raise InputError(f"{path.name}: AT2 units not in g ({lines[2].strip()})")
    match = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([0-9.Ee+-]+)", lines[3].upper())
    if not match:
        raise InputError(f"{path.name}: AT2 line 4 lacks NPTS and DT")
    npts = int(match.group(1))
    try:
        dt = float(match.group(2))
    except ValueError:
        raise InputError(f"{path.name}: AT2 DT {match.group(2)!r} is not a number") from None
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"{path.name}: AT2 DT must be a positive time step, got {dt:g}")
    values = counted_samples(" ".join(lines[4:]).split(), npts, path.name,
                             "non-numeric AT2 samples", "AT2")
    trace = Trace(values * STANDARD_GRAVITY)
    trace.stats.delta = dt
    trace.stats.channel = lines[1].rsplit(",", 1)[-1].strip()[:8]
    return trace
