"""Laboratory table motions: a text table of time and 1-3 acceleration components.

The file (plain or gzip-compressed) starts with ``#`` header lines; three are required::

    # lab-table: granite shake-table test 123 (any title)
    # units: g                 (or m/s^2)
    # axes: 90                 (one per acceleration column: azimuth of its positive
    #                           direction in degrees clockwise from North, or "up")
    # station: UNR shake table (optional; also "event")
    0.000  0.00123
    0.005  0.00131
    ...

Columns are separated by blanks or commas: time (s, uniformly sampled) and the
acceleration components in the order of ``axes``.  A component the table does not have
is zero (a uniaxial table moves along its one axis only); the reader says which it added
in ``info["zero_components"]``.
"""
import io
import math
import re

import numpy as np
from obspy import Stream, Trace

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records.readers import VERTICAL_UP, read_bytes

FORMAT = "lab-table"
PRIORITY = 5
UNITS = {"g": STANDARD_GRAVITY, "m/s^2": 1.0, "m/s2": 1.0, "m/s**2": 1.0}
SAMPLING_TOLERANCE = 1e-3     # relative spread of the time steps allowed
HEADER = re.compile(r"#\s*([A-Za-z_-]+)\s*:\s*(.*?)\s*$")


def detect(path, head):
    return head.lstrip().lower().startswith(b"# lab-table")


def read(path, key=None):
    name = path.name
    text = read_bytes(path).decode("utf-8", errors="replace")
    header = {}
    for line in text.splitlines():
        if not line.startswith("#"):
            if line.strip():
                break
            continue
        match = HEADER.match(line)
        if match:
            header.setdefault(match.group(1).lower(), match.group(2))
    for required in ("units", "axes"):
        if required not in header:
            raise InputError(f"{name}: lab table without a '# {required}:' header line")
    units = header["units"].split()[0] if header["units"] else ""
    if units not in UNITS:
        raise InputError(f"{name}: units {units!r}: expected one of {', '.join(UNITS)}")
    axes = [a for a in re.split(r"[,\s]+", header["axes"]) if a]
    orientations = [_orientation(a, name) for a in axes]
    try:
        data = np.loadtxt(io.StringIO(text.replace(",", " ")), comments="#", ndmin=2)
    except ValueError as exc:
        raise InputError(f"{name}: not a table of numbers ({str(exc).splitlines()[0][:100]})") \
            from None
    if data.shape[1] != 1 + len(axes):
        raise InputError(f"{name}: {data.shape[1]} columns, expected time and "
                         f"{len(axes)} acceleration column(s) for axes {header['axes']}")
    if len(data) < 100:
        raise InputError(f"{name}: {len(data)} samples, at least 100 needed")
    if not np.all(np.isfinite(data)):
        raise InputError(f"{name}: NaN or infinite values in the table")
    steps = np.diff(data[:, 0])
    dt = float(np.median(steps))
    if dt <= 0 or np.abs(steps - dt).max() > SAMPLING_TOLERANCE * dt:
        raise InputError(f"{name}: time column is not uniformly increasing (steps "
                         f"{steps.min():.6g}-{steps.max():.6g} s)")
    horizontal = [o for o in orientations if o[1] == 0.0]
    vertical = [o for o in orientations if o[1] != 0.0]
    if len(horizontal) > 2 or len(vertical) > 1 or not horizontal:
        raise InputError(f"{name}: axes {header['axes']}: need 1-2 horizontal and at most "
                         "one vertical axis")
    if len(horizontal) == 2 and abs(math.sin(math.radians(horizontal[0][0]
                                                          - horizontal[1][0]))) < 0.5:
        raise InputError(f"{name}: horizontal axes {horizontal[0][0]:g} and "
                         f"{horizontal[1][0]:g} deg are not independent")
    stream = Stream()
    for k, (azimuth, dip) in enumerate(orientations):
        stream.append(_trace(data[:, k + 1] * UNITS[units], dt, azimuth, dip, f"HN{k + 1}"))
    zero = []
    if len(horizontal) == 1:
        azimuth = (horizontal[0][0] + 90.0) % 360.0
        stream.append(_trace(np.zeros(len(data)), dt, azimuth, 0.0, "HNX"))
        zero.append(f"horizontal {azimuth:g} deg")
    if not vertical:
        stream.append(_trace(np.zeros(len(data)), dt, 0.0, VERTICAL_UP, "HNZ"))
        zero.append("vertical")
    info = {"zero_components": zero}
    for key_ in ("station", "event"):
        if header.get(key_):
            info[key_] = header[key_]
    return stream, info


def _orientation(text, name):
    """(azimuth deg, SEED dip) of one axis: an azimuth, or "up"."""
    if text.lower() == "up":
        return 0.0, VERTICAL_UP
    try:
        azimuth = float(text)
    except ValueError:
        raise InputError(f"{name}: axis {text!r}: expected an azimuth in degrees or 'up'") \
            from None
    if not (math.isfinite(azimuth) and 0.0 <= azimuth < 360.0):
        raise InputError(f"{name}: axis azimuth {text} outside [0, 360)")
    return azimuth, 0.0


def _trace(values, dt, azimuth, dip, channel):
    trace = Trace(np.asarray(values, float))
    trace.stats.delta = dt
    trace.stats.channel = channel
    trace.stats.azimuth, trace.stats.dip = azimuth, dip
    return trace
