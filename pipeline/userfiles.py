"""What the loaders of user-written files (column descriptions, observations) share:
bounds checked before and right after parsing, and short one-line renderings of
whatever a file holds, for the one-line errors."""
import math
import reprlib

from pipeline.files import InputError

MAX_FILE_BYTES = 1_000_000   # a column description or an observations file is a few kB
MAX_NESTING = 16             # they nest 4-5 deep
MAX_INT_DIGITS = 100         # longer integers are refused while parsing


class Unreadable(ValueError):
    """A file that cannot be parsed; the message says where and why (one line).
    ``kind``: "size" (over MAX_FILE_BYTES), "utf8" (``offset``, ``byte``: the first
    bad byte, 0-based) or None."""

    def __init__(self, message, kind=None, offset=None, byte=None):
        super().__init__(message)
        self.kind, self.offset, self.byte = kind, offset, byte


def read_text(path):
    """The text of a user's file: at most MAX_FILE_BYTES read, strict UTF-8 (a BOM
    allowed).  Unreadable ("size" or "utf8"); OSError as open raises it."""
    with open(path, "rb") as f:
        content = f.read(MAX_FILE_BYTES + 1)
    if len(content) > MAX_FILE_BYTES:
        raise Unreadable(f"larger than {MAX_FILE_BYTES // 1_000_000} MB", "size")
    bom = 3 if content.startswith(b"\xef\xbb\xbf") else 0     # a UTF-8 BOM is allowed
    try:
        return content[bom:].decode("utf-8")
    except UnicodeDecodeError as exc:
        at = bom + exc.start
        raise Unreadable(f"byte {at + 1} is 0x{content[at]:02x}, not UTF-8", "utf8", at,
                         content[at]) from None


def read_json(path, what):
    """The parsed JSON of a user's file (read by :func:`read_text`); InputError (one line)
    "``what`` not found: path" or "name: not readable JSON (why)"."""
    import json
    from pathlib import Path
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{what} not found: {path}")
    try:
        return json.loads(read_text(path))
    except (OSError, ValueError, RecursionError) as exc:      # Unreadable is a ValueError
        raise InputError(f"{path.name}: not readable JSON ({exc})") from None


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict, _REPR.maxset = 2, 4, 4, 4
_REPR.maxstring, _REPR.maxother, _REPR.maxlong = 60, 60, 40


def show(value, most=80):
    """A short one-line repr of a value read from a file, for messages."""
    try:
        text = _REPR.repr(value)
    except ValueError:                    # an int beyond Python's str conversion limit
        return f"<{type(value).__name__}>"
    return text if len(text) <= most else text[:most - 3] + "..."


def number(value, what, low=None, high=None, unit="", low_open=False):
    """``value`` read from a file as a float: InputError (one line naming ``what``) unless
    it is a finite JSON/YAML number (not a bool) within [low, high] (``low_open``: above
    low), ``unit`` for the message.  Compared exactly, also for integers beyond a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            (isinstance(value, float) and not math.isfinite(value)):
        raise InputError(f"{what} must be a finite number, got {show(value)}")
    if (low is not None and (value <= low if low_open else value < low)) or \
            (high is not None and value > high):
        bounds = f"{'(' if low_open else '['}{'-inf' if low is None else f'{low:g}'}, " \
                 f"{'inf' if high is None else f'{high:g}'}]"
        raise InputError(f"{what} {number_text(value)} outside the allowed range {bounds} {unit}"
                         .rstrip())
    try:
        return float(value)
    except OverflowError:                        # an integer beyond any float, no bound
        raise InputError(f"{what} {show(value)} is beyond a float's range") from None


def number_text(value):
    """A number from a file as ``{:g}`` formats it (a short repr beyond a float's range)."""
    try:
        return f"{float(value):g}"
    except OverflowError:
        return show(value)


def keys_text(keys, most=8):
    """Keys read from a file, for messages: sorted, odd ones quoted, at most ``most``."""
    names = sorted(k if isinstance(k, str) and k.isprintable() and len(k) <= 40 else show(k)
                   for k in keys)
    more = f" and {len(names) - most} more" if len(names) > most else ""
    return ", ".join(names[:most]) + more


def json_int(digits):
    """``parse_int`` of json.loads: Unreadable past MAX_INT_DIGITS digits."""
    n = len(digits.lstrip("-"))
    if n > MAX_INT_DIGITS:
        raise Unreadable(f"an integer of {n} digits (at most {MAX_INT_DIGITS})")
    return int(digits)


def nesting(value, limit=MAX_NESTING):
    """Nesting depth of parsed data (0: a scalar; lists and dicts count), or limit + 1 once
    it exceeds ``limit`` or refers to itself (YAML anchors can build cycles).  Iterative;
    each container is visited once, so shared ones (YAML aliases) cost nothing more."""
    depth, path = {}, set()            # depths of finished containers; ids on the path
    stack = [(value, False)]
    while stack:
        node, finished = stack.pop()
        key = id(node)
        items = node.values() if isinstance(node, dict) else node
        if finished:
            path.discard(key)
            depth[key] = 1 + max((depth.get(id(c), 0) for c in items), default=0)
            if depth[key] > limit:
                return limit + 1
        elif key in path:
            return limit + 1
        elif key not in depth and isinstance(node, (list, dict)):
            path.add(key)
            stack.append((node, True))
            stack.extend((c, False) for c in items if isinstance(c, (list, dict)))
    return depth.get(id(value), 0)
