"""Readers for strong-motion record files: a registry of formats.

Each module of this package is one format and defines ``FORMAT`` (a name),
``PRIORITY`` (lower is tried first), ``detect(path, head) -> bool`` (``head``:
the first 4096 bytes, gunzipped) and ``read(path, key=None) -> (stream, info)``.
A new format is one new module; :func:`read_record` finds it.

``stream``: an :class:`obspy.Stream` of acceleration in m/s^2, one trace per
sensor component, each with ``stats.azimuth`` (degrees clockwise from North of
the positive sensor axis) and ``stats.dip`` (SEED: -90 = positive up, 90 =
positive down, 0 = horizontal).  ``info``: what the file says about the record
(``station``, ``event``, ``magnitude``, ``station_lat``/``station_lon``,
``event_lat``/``event_lon`` in degrees, ``lowest_usable_hz``,
``highest_usable_hz``, ``origin_time``); keys are absent when the file does not
tell.  Bad input raises :class:`~pipeline.files.InputError` with one line.
"""
import functools
import glob
import gzip
import zlib
import importlib
import pkgutil
from pathlib import Path

from pipeline.files import InputError
from pipeline.userfiles import read_user_bytes

VERTICAL_UP, VERTICAL_DOWN = -90.0, 90.0
HEAD_BYTES = 4096


@functools.lru_cache(maxsize=1)
def formats():
    """Format modules of this package, in the order they are tried."""
    modules = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        if all(hasattr(module, a) for a in ("FORMAT", "PRIORITY", "detect", "read")):
            modules.append(module)
    return tuple(sorted(modules, key=lambda m: (m.PRIORITY, m.FORMAT)))


def read_record(path, key=None):
    """Read one record file (or a glob pattern of its single-channel files); see module doc.

    Returns (stream, info) with ``info["format"]`` naming the reader used.
    """
    path = Path(path)
    if is_pattern(path):
        matches = sorted(glob.glob(str(path)))
        if not matches:
            raise InputError(f"no record files match {path}")
        head = read_bytes(matches[0])[:HEAD_BYTES]
    else:
        if not path.exists():
            raise InputError(f"record file not found: {path}")
        head = read_bytes(path)[:HEAD_BYTES]
    for module in formats():
        if module.detect(path, head):
            stream, info = module.read(path, key)
            return stream, dict(info, format=module.FORMAT)
    raise InputError(f"{path.name}: no reader recognises this file")


def read_bytes(path):
    """The file's bytes, gunzipped when it is gzip-compressed."""
    path = Path(path)
    raw = read_user_bytes(path, "record file")
    if raw[:2] == b"\x1f\x8b":
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError, zlib.error) as exc:
            raise InputError(f"{path.name}: broken gzip file ({str(exc).splitlines()[0]})") \
                from None
    return raw


def is_pattern(path):
    """True if ``path`` is a glob pattern (contains *, ? or [)."""
    return any(char in str(path) for char in "*?[")


def orientation_from_code(channel):
    """(azimuth, dip) from the last letter of a SEED channel code; azimuth None if unknown."""
    code = channel[-1:].upper()
    if code == "Z":
        return 0.0, VERTICAL_UP
    if code == "N":
        return 0.0, 0.0
    if code == "E":
        return 90.0, 0.0
    return None, 0.0
