"""A part of a result file as a type: :class:`Record`, a frozen keyword dataclass written
as a JSON object (its fields in their order, a field left :data:`ABSENT` not written) and
read back from one (:meth:`Record.from_json`: unknown and missing keys named, the parts
that are records themselves read as their types)."""
import types
from dataclasses import MISSING, fields
from enum import Enum

from pipeline.files import InputError


class _Absent:
    """A field the route does not fill (not written to the file)."""

    def __repr__(self):
        return "ABSENT"


ABSENT = _Absent()


def as_json(value):
    """``value`` as JSON-ready data: a record's :meth:`~Record.as_json`, an enum's value,
    lists and dicts element by element, anything else as it is."""
    if hasattr(value, "as_json"):
        return value.as_json()
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, list | tuple):
        return [as_json(v) for v in value]
    if isinstance(value, dict):
        return {k: as_json(v) for k, v in value.items()}
    return value


def each(read):
    """A reader of a JSON list whose items ``read`` reads (a list of the items read)."""
    def read_list(data):
        if not isinstance(data, list):
            raise InputError(f"not a list: {type(data).__name__}")
        return [read(item) for item in data]
    return read_list


def optional(read):
    """A reader of a JSON value that ``read`` reads, or null (None)."""
    def read_or_none(data):
        return None if data is None else read(data)
    return read_or_none


class Record:
    """A frozen ``kw_only`` dataclass of a result file's part: ``NAME`` what it is (in
    errors), ``PARTS`` the readers of the fields that are not plain JSON (field name to a
    function of the JSON value).  A field without a default is required; one of default
    :data:`ABSENT` is written only when given."""
    NAME = ""
    PARTS = {}

    def given(self, name):
        """The field ``name``, or None where it is absent."""
        value = getattr(self, name)
        return None if value is ABSENT else value

    def as_json(self) -> dict:
        """The JSON object: the fields given, in their order."""
        return {f.name: as_json(getattr(self, f.name)) for f in fields(self)
                if getattr(self, f.name) is not ABSENT}

    @classmethod
    def from_json(cls, data):
        """The record of the JSON object ``data`` (InputError naming an unknown or missing
        key, or a value the type refuses)."""
        if not isinstance(data, dict):
            raise InputError(f"{cls.NAME}: not a JSON object")
        names = [f.name for f in fields(cls)]
        unknown = sorted(set(data) - set(names))
        if unknown:
            raise InputError(f"{cls.NAME}: unknown keys {', '.join(unknown)}")
        missing = [f.name for f in fields(cls) if f.default is MISSING and f.name not in data]
        if missing:
            raise InputError(f"{cls.NAME}: no {', '.join(missing)}")
        try:
            return cls(**{k: cls.PARTS[k](v) if k in cls.PARTS else v
                          for k, v in data.items()})
        except (ValueError, TypeError, KeyError) as e:
            raise InputError(f"{cls.NAME}: {e}") from None


def check_probability(record, *names):
    """InputError unless each field ``names`` of ``record`` given and not None is in [0, 1]
    (a NaN left to the writer's one-line error)."""
    for name in names:
        p = record.given(name)
        if p is not None and (p < 0.0 or p > 1.0):
            raise InputError(f"{record.NAME}: {name} {p!r} is not in [0, 1]")


def check_rate(record, *names):
    """InputError unless each rate (1/yr) ``names`` of ``record`` given and not None is >= 0."""
    for name in names:
        rate = record.given(name)
        if rate is not None and rate < 0.0:
            raise InputError(f"{record.NAME}: {name} {rate!r} < 0")


def check_leaves(record, *names):
    """ValueError unless each field ``names`` of ``record`` (every field if none named)
    given is of its declared type: a float a number (an int too, not a bool), an int an
    int (not a bool), ``X | None`` an X or None, any other type an instance of it."""
    for f in fields(record):
        value = getattr(record, f.name)
        if (names and f.name not in names) or value is ABSENT:
            continue
        kinds = f.type.__args__ if isinstance(f.type, types.UnionType) else (f.type,)
        if not any(_of_kind(value, kind) for kind in kinds):
            said = " or ".join("null" if k is type(None) else k.__name__ for k in kinds)
            raise ValueError(f"{f.name} is not {said}: {value!r:.60}")


def _of_kind(value, kind):
    if kind is type(None):
        return value is None
    if kind is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    if kind is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, kind)
