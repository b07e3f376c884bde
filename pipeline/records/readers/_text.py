"""Small helpers shared by the near-source readers (geonet, dmg_v2, at2_triplet,
mseed_stationxml): transparent gzip, fixed-width numbers, one-line errors.

Files may be stored gzip-compressed (``<name>.gz``): gzip is recognised by its
magic bytes 1f 8b, not by the name.
"""
import math
import re

import numpy as np

from pipeline.files import InputError

from pipeline.constants import STANDARD_GRAVITY  # noqa: F401  (used by the readers)
from pipeline.records.readers import VERTICAL_DOWN, VERTICAL_UP, read_bytes  # noqa: F401


def open_text(path):
    """The text of ``path`` (latin-1, so any byte decodes), gunzipped if needed."""
    return read_bytes(path).decode("latin-1")


def head_text(head, n=400):
    """The first ``n`` bytes of an already-gunzipped head as text."""
    return head[:n].decode("latin-1")


def strip_gz(name):
    """File name without a trailing ``.gz``."""
    return name[:-3] if name.lower().endswith(".gz") else name


def one_line(obj):
    """``str(obj)`` squeezed onto one line (for messages quoting exceptions or file text)."""
    return re.sub(r"\s+", " ", str(obj)).strip()


def number(text, what, name):
    """float(text) or a one-line InputError naming ``what`` in file ``name``."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise InputError(f"{name}: {what} {one_line(text)!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{name}: {what} is not finite ({one_line(text)})")
    return value


def fixed_width_values(lines, width, per_line, count, name, what):
    """``count`` numbers in fixed-width fields (``per_line`` fields of ``width`` characters)
    from the start of ``lines``; returns (values, number of lines used).

    Fixed width matters: neighbouring fields may touch (``-11024.7-11000.0``).
    """
    n_lines = -(-count // per_line)
    if len(lines) < n_lines:
        raise InputError(f"{name}: {what}: file ends after {len(lines)} of {n_lines} data lines")
    fields = []
    for line in lines[:n_lines]:
        line = line.rstrip("\r\n")
        fields.extend(line[k:k + width] for k in range(0, len(line), width))
    fields = [f for f in fields if f.strip()]
    if len(fields) != count:
        raise InputError(f"{name}: {what}: {len(fields)} samples in {n_lines} data lines, "
                         f"header says {count}")
    try:
        values = np.array(fields, dtype=float)
    except ValueError:
        bad = next(f for f in fields if not _is_float(f))
        raise InputError(f"{name}: {what}: non-numeric sample {bad.strip()!r}") from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"{name}: {what}: non-finite samples")
    return values, n_lines


def counted_samples(fields, count, name, non_numeric, holder):
    """The texts ``fields`` as floats, exactly ``count`` of them (the header's); else one
    InputError: "{name}: {non_numeric}" or "{name}: {holder} has n samples, header says
    count"."""
    try:
        values = np.array(fields, dtype=float)
    except ValueError:
        raise InputError(f"{name}: {non_numeric}") from None
    if values.size != count:
        raise InputError(f"{name}: {holder} has {values.size} samples, header says {count}")
    return values


def _is_float(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def compass_azimuth(token):
    """Azimuth in degrees of a compass component name such as ``N28W`` (332), ``S62W`` (242),
    ``N10E`` (10), ``S45E`` (135), ``N``, ``E``, ``S``, ``W``; None if not of that form."""
    token = token.strip().upper()
    base = {"N": 0.0, "E": 90.0, "S": 180.0, "W": 270.0}
    if token in base:
        return base[token]
    match = re.fullmatch(r"([NS])\s*(\d{1,2}(?:\.\d+)?)\s*([EW])", token)
    if not match:
        return None
    angle = float(match.group(2))
    if angle > 90:
        return None
    start, end = match.group(1), match.group(3)
    if start == "N":
        azimuth = angle if end == "E" else 360.0 - angle
    else:
        azimuth = 180.0 - angle if end == "E" else 180.0 + angle
    return azimuth % 360.0
