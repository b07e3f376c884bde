"""Ground motion: the :class:`Motion` every stage passes around, and its one file format.

A processed motion file (``.npz``) holds ``dt`` (s), ``acc`` (m/s^2), ``vel``
(m/s), ``disp`` (m) as (n, 3) arrays with columns East, North, Up, and ``meta``,
a JSON object (record id, event, station, ``back_azimuth_deg``,
``epicentral_distance_km``, ``has_vertical``, ``processing`` provenance,
``start_in_file_s``, ...).
Records, synthetics and the YADE scene all read and write it through
:meth:`Motion.load` and :meth:`Motion.save`.

Two clocks: a motion's samples are ``dt`` apart from its first sample (the motion's
clock: the YADE scene and its trajectory run on it); a user reads the record's clock,
seconds after the record's first sample.  ``meta["start_in_file_s"]`` is the time on the
record's clock of the motion's first sample (negative where the processing added zeros
before the record; absent: 0, a motion that is its own record), so record time = motion
time + ``start_in_file_s``.
"""
import io
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from pipeline.files import InputError, write_npz
from pipeline.userfiles import read_user_bytes

NPZ_KEYS = ("dt", "acc", "vel", "disp", "meta")
RECORD_CLOCK = "s after the record's first sample"    # the unit of every time a user reads


@dataclass(frozen=True)
class Motion:
    """Three-component ground motion sampled every ``dt`` seconds.

    ``acc`` m/s^2, ``vel`` m/s, ``disp`` m: (n, 3) arrays, columns East, North, Up.
    ``meta``: what is known about the motion (JSON-serialisable dict).
    """
    dt: float
    acc: np.ndarray
    vel: np.ndarray
    disp: np.ndarray
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        name = self.meta.get("record_id", "motion")
        if not (isinstance(self.dt, (int, float, np.floating)) and math.isfinite(self.dt)
                and self.dt > 0):
            raise InputError(f"{name}: time step dt must be a positive number, got {self.dt!r}")
        shapes = {k: np.shape(getattr(self, k)) for k in ("acc", "vel", "disp")}
        first = shapes["acc"]
        if len(first) != 2 or first[1] != 3 or first[0] < 2 or \
                any(s != first for s in shapes.values()):
            raise InputError(f"{name}: acc, vel and disp must be (n, 3) arrays of one shape with "
                             f"n >= 2, got {', '.join(f'{k} {v}' for k, v in shapes.items())}")
        for key in ("acc", "vel", "disp"):
            if not np.all(np.isfinite(getattr(self, key))):
                raise InputError(f"{name}: {key} holds NaN or infinite samples")
        start = self.meta.get("start_in_file_s")
        if start is not None and (isinstance(start, bool) or not isinstance(
                start, (int, float)) or not math.isfinite(start)):
            raise InputError(f"{name}: start_in_file_s must be a finite number (s), "
                             f"got {start!r}")

    @property
    def npts(self):
        """Number of samples."""
        return len(self.acc)

    @property
    def duration(self):
        """Duration (s) from the first to the last sample."""
        return (self.npts - 1) * self.dt

    @property
    def record_id(self):
        return self.meta.get("record_id")

    @property
    def start_in_file_s(self):
        """Time (s) on the record's clock (after the record's first sample) of this
        motion's first sample: record time = motion time + start_in_file_s."""
        value = self.meta.get("start_in_file_s")
        return 0.0 if value is None else float(value)

    @property
    def back_azimuth(self):
        """Back azimuth (deg, station to epicentre) or None when unknown."""
        value = self.meta.get("back_azimuth_deg")
        return None if value is None or not math.isfinite(value) else float(value)

    @property
    def processing_mode(self):
        """How the motion was processed: "default", or "none" (run as given, or made
        processed: a synthetic, an analytic pulse), from ``meta["processing"]``."""
        recorded = self.meta.get("processing") or {}
        return recorded.get("mode", "default" if recorded.get("steps") else "none")

    # ------------------------------------------------------------ file format
    @classmethod
    def load(cls, path):
        """Read a processed motion ``.npz``; InputError names what is wrong."""
        path = Path(path)
        if not path.exists():
            raise InputError(f"processed motion not found: {path}")
        try:
            content = read_user_bytes(path, "processed motion")
            with np.load(io.BytesIO(content), allow_pickle=False) as archive:
                missing = [k for k in NPZ_KEYS if k not in archive.files]
                if missing:
                    raise InputError(f"{path.name}: not a processed motion file "
                                     f"(missing {', '.join(missing)})")
                data = {k: archive[k] for k in NPZ_KEYS}
        except (ValueError, OSError, EOFError) as exc:
            raise InputError(f"{path.name}: unreadable npz ({type(exc).__name__})") from None
        try:
            meta = json.loads(str(data["meta"]))
        except ValueError:
            raise InputError(f"{path.name}: meta is not JSON") from None
        if not isinstance(meta, dict):
            raise InputError(f"{path.name}: meta is not a JSON object")
        try:
            dt = float(data["dt"])
            arrays = [np.asarray(data[k], dtype=float) for k in ("acc", "vel", "disp")]
        except (TypeError, ValueError):
            raise InputError(f"{path.name}: dt, acc, vel, disp must be numeric") from None
        meta.setdefault("record_id", path.stem)
        return cls(dt, *arrays, meta=meta)

    def save(self, path):
        """Write the motion atomically as ``.npz`` (see module docstring)."""
        write_npz(path, dt=np.float64(self.dt), acc=np.asarray(self.acc, float),
                  vel=np.asarray(self.vel, float), disp=np.asarray(self.disp, float),
                  meta=np.array(json.dumps(self.meta, allow_nan=False)))
        return Path(path)

    # ------------------------------------------------------------ transformations
    def window(self, start_s, end_s):
        """Excerpt from ``start_s`` to ``end_s`` (s, the motion's clock); displacement
        re-zeroed at its start; ``start_in_file_s`` moves with the first sample."""
        if not (math.isfinite(start_s) and math.isfinite(end_s) and 0 <= start_s < end_s):
            raise InputError(f"window must satisfy 0 <= start < end (finite), got "
                             f"{start_s}, {end_s}")
        i0, i1 = int(round(start_s / self.dt)), int(round(end_s / self.dt)) + 1
        if i0 >= self.npts - 1:
            raise InputError(f"window starts at {start_s} s, after the record ends "
                             f"({self.duration:.1f} s)")
        meta = dict(self.meta, window_s=[float(start_s), float(min(end_s, self.duration))],
                    start_in_file_s=self.start_in_file_s + i0 * self.dt)
        return replace(self, acc=self.acc[i0:i1], vel=self.vel[i0:i1],
                       disp=self.disp[i0:i1] - self.disp[i0], meta=meta)

    def rotate(self, degrees):
        """Horizontal motion turned clockwise (seen from above) by ``degrees``: a motion
        along azimuth phi becomes one along phi + degrees; the back azimuth turns with it."""
        if not math.isfinite(degrees):
            raise InputError(f"rotation must be a finite angle, got {degrees}")
        meta = dict(self.meta)
        if self.back_azimuth is not None:
            meta["back_azimuth_deg"] = (self.back_azimuth + degrees) % 360.0
        return replace(self, acc=rotate_horizontal(self.acc, degrees),
                       vel=rotate_horizontal(self.vel, degrees),
                       disp=rotate_horizontal(self.disp, degrees), meta=meta)

    def scale(self, factor):
        """Motion scaled by ``factor`` (>= 0)."""
        if not (math.isfinite(factor) and factor >= 0):
            raise InputError(f"scale must be a non-negative number, got {factor}")
        return replace(self, acc=self.acc * factor, vel=self.vel * factor,
                       disp=self.disp * factor)


def rotate_horizontal(vectors, degrees):
    """Turn the horizontal part of (n, 3) East/North/Up vectors clockwise by ``degrees``."""
    b = math.radians(degrees)
    out = np.array(vectors, float)
    e, n = out[:, 0].copy(), out[:, 1].copy()
    out[:, 0] = e * math.cos(b) + n * math.sin(b)
    out[:, 1] = -e * math.sin(b) + n * math.cos(b)
    return out


def azimuth_deg(d_east, d_north):
    """Azimuth clockwise from North in [0, 360) of a horizontal vector (deg)."""
    return float(np.degrees(np.arctan2(d_east, d_north)) % 360.0)
