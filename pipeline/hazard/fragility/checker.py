"""Typed reads of ``fragility.json``'s values (:class:`Checker`), shared by the file's
checks (:mod:`pipeline.hazard.fragility.check`) and its types that check themselves
(:mod:`pipeline.hazard.fragility.fits`, :mod:`pipeline.hazard.fragility.rows`): each
refusal one InputError naming the key path, and, read from a file, the file
(:func:`leaf`)."""
from pipeline.files import InputError
from pipeline.userfiles import number, show

MAX_MEMBERS = 10_000           # parameter sets of a campaign
MAX_RUNS = 10_000_000          # runs of one cell
MAX_TOTAL = 10 ** 15           # runs of a column, model or fit (counts only, no allocation)
MAX_TEXT = 10_000              # characters of a note, description or record id
TOLERANCE = 1e-9               # an estimate "inside" its interval, P = overturned / n


def leaf(cls, data, name, where):
    """``cls`` (a type of the file that checks itself) of ``data`` as read at key path
    ``where`` of the file ``name``: an object, else InputError; a refusal of its values
    named by file and key path."""
    at = f"{name}: {where}" if name else where
    if not isinstance(data, dict):
        raise InputError(f"{at} must be an object, got {kind_of(data)}")
    try:
        return cls.of(data)
    except InputError as exc:
        raise InputError(f"{at}.{exc}") from None


class Checker:
    """Typed reads of one file's values; each failure one line naming the key path."""

    def __init__(self, name):
        self.name = name

    def fail(self, where, what):
        raise InputError(f"{self.name}: {where} {what}" if self.name else f"{where} {what}")

    def obj(self, value, where, most=None):
        if not isinstance(value, dict):
            self.fail(where, f"must be an object, got {kind_of(value)}")
        if most is not None and len(value) > most:
            self.fail(where, f"holds {len(value)} entries (at most {most})")
        return value

    def lst(self, value, where, most):
        if not isinstance(value, list):
            self.fail(where, f"must be a list, got {kind_of(value)}")
        if len(value) > most:
            self.fail(where, f"holds {len(value)} values (at most {most})")
        return value

    def num(self, value, where, low=None, high=None, low_open=False, optional=False):
        if value is None and optional:
            return None
        return number(value, f"{self.name}: {where}" if self.name else where, low, high, "",
                      low_open)

    def integer(self, value, where, low, high, optional=False):
        if value is None and optional:
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(where, f"must be an integer, got {show(value)}")
        if not low <= value <= high:
            self.fail(where, f"must be {low} to {high}, got {show(value)}")
        return value

    def text(self, value, where):
        if value is not None and not (isinstance(value, str) and len(value) <= MAX_TEXT):
            self.fail(where, f"must be a text of at most {MAX_TEXT} characters, got "
                             f"{kind_of(value)}")
        return value

    def pair(self, value, where, low=None, high=None, holds=None, low_open=False):
        """A 95 % interval [lo, hi] (or None) within [low, high] that holds ``holds``."""
        if value is None:
            return None
        if not (isinstance(value, list) and len(value) == 2):
            self.fail(where, f"must be a pair [lo, hi], got {show(value)}")
        lo, hi = (self.num(v, where, low, high, low_open) for v in value)
        if lo > hi:
            self.fail(where, f"is [{lo:g}, {hi:g}]: lo above hi")
        if holds is not None and not lo - _slack(lo, holds) <= holds <= hi + _slack(hi, holds):
            self.fail(where, f"[{lo:g}, {hi:g}] does not hold its estimate {holds:g}")
        return lo, hi


def _slack(a, b):
    return TOLERANCE * max(1.0, abs(a), abs(b))


def kind_of(value):
    """What a JSON value is, for messages."""
    names = {dict: "an object", list: "a list", str: "a text", bool: "true/false",
             type(None): "null", int: "a number", float: "a number"}
    return f"{names.get(type(value), type(value).__name__)} {show(value, 40)}"


def key_text(name):
    """A key of the file as it appears in a key path."""
    return name if name.isidentifier() and len(name) <= 40 else show(name, 40)


def counts(c, entry, where, total, part):
    """Two counts of runs (integers, or absent), ``part`` of ``total``."""
    at = f"{where}." if where else ""
    n = c.integer(entry.get(total), f"{at}{total}", 0, MAX_TOTAL, optional=True)
    c.integer(entry.get(part), f"{at}{part}", 0, MAX_TOTAL if n is None else n, optional=True)
