"""The types of ``fragility.json`` to and from the dicts its JSON holds: the keys a type
names become its fields, the others stay in its ``extra``, and the keys' order is kept
(``order``), so that a file read and written again is the same file."""
from dataclasses import MISSING, dataclass, field, fields

KEPT = ("extra", "order", "path")     # fields that are not keys of the file


@dataclass(frozen=True)
class Keyed:
    """What every type of the file keeps besides its named keys: the others (``extra``)
    and the keys' order as read (``order``); keyword-only, after the type's own fields."""
    extra: dict = field(default_factory=dict, kw_only=True)
    order: tuple = field(default=(), compare=False, kw_only=True)


def build(cls, data, convert=None, **more):
    """``cls`` of a dict: its named keys (through ``convert``; a key ``cls`` requires and
    the dict lacks as None, for ``cls`` to refuse by name), the rest in ``extra``, the
    keys' order kept."""
    convert = convert or {}
    names = {f.name for f in fields(cls)} - set(KEPT)
    known = {k: convert.get(k, same)(v) for k, v in data.items() if k in names}
    known.update({f.name: None for f in fields(cls) if f.name in names and f.name not in known
                  and f.default is MISSING and f.default_factory is MISSING})
    extra = {k: v for k, v in data.items() if k not in names}
    return cls(**known, extra=extra, order=tuple(data), **more)


def join(obj, convert=None):
    """The dict of a :func:`build` object: the keys as read, in their order, then keys
    set since (not None)."""
    convert = convert or {}
    values = {f.name: getattr(obj, f.name) for f in fields(obj) if f.name not in KEPT}
    values.update(obj.extra)
    keys = [k for k in obj.order if k in values]
    keys += [k for k, v in values.items() if k not in obj.order and v is not None
             and v != () and v != {}]
    return {k: convert.get(k, same)(values[k]) for k in keys}


def same(value):
    return value
