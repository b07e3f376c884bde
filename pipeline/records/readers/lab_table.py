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
acceleration components in the order of ``axes``; at most MAX_SAMPLES rows and
MAX_DURATION_S seconds (checked before the table is parsed into arrays), accelerations up
to MAX_ACCELERATION_G; a UTF-8 byte-order mark before the first line is passed over.  Units or axes
stated twice (two ``# units:`` lines that name units, two ``# axes:`` lines of axes; a
``# units:`` line describing the columns in words is a comment), or a title, station or
event given twice, are refused (which one is meant?); so is a table whose header lacks
its first line ``# lab-table:``.  A component the table does not have
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
KEYS = ("lab-table", "units", "axes", "station", "event")   # the header lines read
MAX_SAMPLES = 2_000_000       # rows of a table (10 min at 3.3 kHz; the SP1 tests: 800 Hz)
MIN_SAMPLES = 100             # rows a table needs at the least
MAX_DURATION_S = 3600.0       # seconds a table may span (a shake-table test lasts minutes)
# the largest table acceleration read (in g): no shake table nor recorded earthquake comes
# near (the strongest records peak at about 4 g); a table in cm/s^2 declared in g is 981 x
MAX_ACCELERATION_G = 20.0
BOM = b"\xef\xbb\xbf"             # a UTF-8 byte-order mark (spreadsheet exports write one)


def detect(path, head):
    """A table that starts with ``# lab-table``, or with ``#`` lines holding a lab
    table's header (``# units:``, ``# axes:``): :func:`read` then names what is missing."""
    text = head.removeprefix(BOM).lstrip().lower()
    if text.startswith(b"# lab-table"):
        return True
    lines = text.decode("utf-8", errors="replace").splitlines()
    leading = []
    for line in lines:
        if not line.startswith("#"):
            break
        leading.append(line)
    return any((match := HEADER.match(line)) and match.group(1) in ("units", "axes")
               for line in leading)


def _samples(text, name, axes, axes_text, scale):
    """The table's numbers (time, accelerations in the file's units) and its time step (s),
    checked: columns, samples, finite values, the acceleration bound (``scale``: the units
    in m/s^2), a uniform time column and the duration."""
    try:
        data = np.loadtxt(io.StringIO(text.replace(",", " ")), comments="#", ndmin=2)
    except ValueError as exc:
        raise InputError(f"{name}: not a table of numbers ({str(exc).splitlines()[0][:100]})") \
            from None
    if data.shape[1] != 1 + len(axes):
        raise InputError(f"{name}: {data.shape[1]} columns, expected time and "
                         f"{len(axes)} acceleration column(s) for axes {axes_text}")
    if len(data) < MIN_SAMPLES:
        raise InputError(f"{name}: {len(data)} samples, at least {MIN_SAMPLES} needed")
    if not np.all(np.isfinite(data)):
        raise InputError(f"{name}: NaN or infinite values in the table")
    peak = float(np.abs(data[:, 1:]).max()) * scale / STANDARD_GRAVITY
    if peak > MAX_ACCELERATION_G:
        raise InputError(f"{name}: table acceleration up to {peak:.4g} g, beyond the "
                         f"{MAX_ACCELERATION_G:g} g a lab table may reach (no shake table or "
                         "recorded earthquake comes near): check '# units:'")
    steps = np.diff(data[:, 0])
    dt = float(np.median(steps))
    if dt <= 0 or np.abs(steps - dt).max() > SAMPLING_TOLERANCE * dt:
        raise InputError(f"{name}: time column is not uniformly increasing (steps "
                         f"{steps.min():.6g}-{steps.max():.6g} s)")
    if data[-1, 0] - data[0, 0] > MAX_DURATION_S:
        raise InputError(f"{name}: the table spans {data[-1, 0] - data[0, 0]:.6g} s (a time "
                         f"step of {dt:.6g} s), more than the {MAX_DURATION_S:g} s a lab table "
                         "may last: is the time column in seconds?")
    return data, dt


def read(path, key=None):
    name = path.name
    text = read_bytes(path).removeprefix(BOM).decode("utf-8", errors="replace")
    lines, rows = {}, 0
    for line in text.splitlines():
        if not line.startswith("#"):
            if line.strip() and not line.lstrip().startswith("#"):
                rows += 1
            continue
        match = HEADER.match(line)
        if match and not rows and match.group(1).lower() in KEYS:
            lines.setdefault(match.group(1).lower(), []).append(match.group(2))
    first = text.lstrip().splitlines()[0] if text.strip() else ""
    if not first.lower().startswith("# lab-table"):
        raise InputError(f"{name}: lab table without its first line '# lab-table: TITLE' "
                         f"(found {first[:40]!r})")
    header = {field: _statement(field, values, name) for field, values in lines.items()}
    for required in ("units", "axes"):
        if required not in header:
            raise InputError(f"{name}: lab table without a '# {required}:' header line")
    if rows > MAX_SAMPLES:
        raise InputError(f"{name}: {rows} rows, more than the {MAX_SAMPLES} a lab table may "
                         "have")
    units = header["units"].split()[0] if header["units"] else ""
    if units not in UNITS:
        raise InputError(f"{name}: units {units!r}: expected one of {', '.join(UNITS)}")
    axes = [a for a in re.split(r"[,\s]+", header["axes"]) if a]
    orientations = [_orientation(a, name) for a in axes]
    if rows < MIN_SAMPLES:
        raise InputError(f"{name}: {rows} samples, at least {MIN_SAMPLES} needed")
    data, dt = _samples(text, name, axes, header["axes"], UNITS[units])
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


def _statement(field, values, name):
    """The value of a header line given on one or more lines: the units or axes among
    ``# units:`` / ``# axes:`` lines (a line that states none is a comment; none at all:
    the first, which the checks then refuse), the one title, station or event.
    InputError when two lines state it."""
    stated = values
    if field == "units":
        stated = [v for v in values if v.split() and v.split()[0] in UNITS]
    elif field == "axes":
        stated = [v for v in values if _are_axes(v)]
    if len(stated) > 1:
        raise InputError(f"{name}: '# {field}:' given twice ({stated[0]!r} and "
                         f"{stated[1]!r}): which one is meant?")
    return stated[0] if stated else values[0]


def _are_axes(text):
    """True if ``text`` is a list of axes (azimuths in [0, 360) or "up")."""
    tokens = [a for a in re.split(r"[,\s]+", text) if a]
    try:
        return bool(tokens) and all(t.lower() == "up" or 0.0 <= float(t) < 360.0
                                    for t in tokens)
    except ValueError:
        return False


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
