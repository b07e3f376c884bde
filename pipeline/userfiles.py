"""What the loaders of user-written files (column descriptions, observations) share:
bounds checked before and right after parsing, and short one-line renderings of
whatever a file holds, for the one-line errors."""
import math
import os
import reprlib
import stat

from pipeline.files import InputError
import json
from pathlib import Path

MAX_FILE_BYTES = 1_000_000   # a column description or an observations file is a few kB
DATA_FILE_BYTES = 64_000_000  # a hazard curve, a campaign's fragility.json or runs table
MAX_NESTING = 16             # they nest 4-5 deep
MAX_INT_DIGITS = 100         # longer integers are refused while parsing


class Unreadable(ValueError):
    """A file that cannot be parsed; the message says where and why (one line).
    ``kind``: "size" (over the size limit), "type" (not a regular file), "utf8"
    (``offset``, ``byte``: the first bad byte, 0-based) or None."""

    def __init__(self, message, kind=None, offset=None, byte=None):
        super().__init__(message)
        self.kind, self.offset, self.byte = kind, offset, byte


def read_bytes(path, limit=None):
    """The bytes of a user's file: a regular file (a named pipe, device or socket refused
    before it is opened, and again on the opened descriptor), at most ``limit`` bytes
    (None: no limit).  Unreadable ("size", "type"); OSError as open raises it
    (IsADirectoryError for a directory).  Every loader of a file reads it here."""
    _regular(os.stat(path).st_mode, path)               # nothing opened that is not a file
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)     # and what replaced it since, too
    try:
        _regular(os.fstat(fd).st_mode, path)
        os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as f:
            fd = None
            content = f.read() if limit is None else f.read(limit + 1)
    finally:
        if fd is not None:
            os.close(fd)
    if limit is not None and len(content) > limit:
        raise Unreadable(f"larger than {_size_text(limit)}", "size")
    return content


def read_text(path, limit=MAX_FILE_BYTES):
    """The text of a user's file (:func:`read_bytes`, at most ``limit`` bytes), strict
    UTF-8 (a BOM allowed).  Unreadable ("size", "type" or "utf8"); OSError as open
    raises it (IsADirectoryError for a directory)."""
    content = read_bytes(path, limit)
    bom = 3 if content.startswith(b"\xef\xbb\xbf") else 0     # a UTF-8 BOM is allowed
    try:
        return content[bom:].decode("utf-8")
    except UnicodeDecodeError as exc:
        at = bom + exc.start
        raise Unreadable(f"byte {at + 1} is 0x{content[at]:02x}, not UTF-8", "utf8", at,
                         content[at]) from None


def check_regular(path, what):
    """InputError "``what`` path is not a regular file" when ``path`` exists as a named
    pipe, device or socket (checked by its status, nothing opened)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise InputError(f"{what} {path} is not a regular file (a named pipe, device or "
                         "socket)")


def _regular(mode, path):
    if stat.S_ISDIR(mode):
        raise IsADirectoryError(21, "Is a directory", str(path))
    if not stat.S_ISREG(mode):
        raise Unreadable(f"{path} is not a regular file (a named pipe, device or socket)",
                         "type")


def _size_text(limit):
    return f"{limit / 1_000_000:g} MB"


def read_user_text(path, what, limit=MAX_FILE_BYTES):
    """The text of a user's file (:func:`read_text`, at most ``limit`` bytes); InputError
    (one line) "``what`` not found: path", "``what`` path is a directory", "``what``
    path is not a regular file" or "``what`` path: why"."""
    return _user(read_text, path, what, limit)


def read_user_bytes(path, what, limit=None):
    """The bytes of a user's file (:func:`read_bytes`, at most ``limit`` bytes); the
    one-line InputErrors of :func:`read_user_text`."""
    return _user(read_bytes, path, what, limit)


def _user(reader, path, what, limit):
    try:
        return reader(path, limit)
    except FileNotFoundError:
        raise InputError(f"{what} not found: {path}") from None
    except IsADirectoryError:
        raise InputError(f"{what} {path} is a directory") from None
    except Unreadable as exc:
        raise InputError(f"{what} {exc}" if exc.kind == "type" else f"{what} {path}: {exc}") \
            from None
    except OSError as exc:
        raise InputError(f"{what} {path}: {exc.strerror or exc}") from None


def read_json(path, what, limit=MAX_FILE_BYTES):
    """The parsed JSON of a user's file (read by :func:`read_text`, at most ``limit``
    bytes); InputError (one line) "``what`` not found: path", "``what`` path is a
    directory" or "name: not readable JSON (why)", a nesting too deep for the parser
    included."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{what} not found: {path}")
    if path.is_dir():
        raise InputError(f"{what} {path} is a directory")
    try:
        return json.loads(read_text(path, limit))
    except RecursionError:
        raise InputError(f"{path.name}: not readable JSON (nested too deep)") from None
    except (OSError, ValueError) as exc:      # Unreadable is a ValueError
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


def number(value, what, low=None, high=None, unit="", low_open=False, high_open=False):
    """``value`` read from a file as a float: InputError (one line naming ``what``) unless
    it is a finite JSON/YAML number (not a bool) within [low, high] (``low_open``: above
    low; ``high_open``: below high), ``unit`` for the message.  Compared exactly, also for
    integers beyond a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            (isinstance(value, float) and not math.isfinite(value)):
        raise InputError(f"{what} must be a finite number, got {show(value)}")
    if (low is not None and (value <= low if low_open else value < low)) or \
            (high is not None and (value >= high if high_open else value > high)):
        bounds = f"{'(' if low_open else '['}{'-inf' if low is None else f'{low:g}'}, " \
                 f"{'inf' if high is None else f'{high:g}'}{')' if high_open else ']'}"
        raise InputError(f"{what} {_beside(value, low, high)} outside the allowed range "
                         f"{bounds} {unit}".rstrip())
    try:
        return float(value)
    except OverflowError:                        # an integer beyond any float, no bound
        raise InputError(f"{what} {show(value)} is beyond a float's range") from None


def _beside(value: float, *bounds: float | None) -> str:
    """``value`` as :func:`number_text` gives it, or in all its digits where that reads
    as a bound it is not (10000.001 beside 10000)."""
    text = number_text(value)
    for bound in bounds:
        if bound is not None and text == f"{bound:g}" and value != bound:
            return repr(float(value))
    return text


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
