"""Command-line flags from parameter dataclasses: every field declared with
:func:`pipeline.scenario.parameters.param` and a flag becomes one option, with its
default, unit, bounds and help; parsed values go back through the dataclass, which
checks them."""
import argparse
import dataclasses
import typing
from pathlib import Path

from pipeline.files import InputError, display_path


def _help(f):
    meta = f.metadata
    unit = f" ({meta['unit']})" if meta.get("unit") else ""
    unset = meta.get("optional")
    unset = f"; unset: {unset}" if isinstance(unset, str) else ""
    return f"{meta['help']}{unit}{_default(f.default)}{unset}{_bounds(meta)}".replace("%", "%%")


def _number(value):
    """An int as it is (a seed of 20091000 stays that), a float by ``:g``."""
    return str(value) if isinstance(value, int) else f"{value:g}"


def _default(value):
    """'; default ...' of a declared default, or '' (None, (), a switch: what unset means
    is the field's ``optional``)."""
    if value is None or value == () or isinstance(value, bool):
        return ""
    if isinstance(value, tuple):
        return "; default " + " ".join(_number(v) if isinstance(v, float) else str(v)
                                       for v in value)
    if isinstance(value, (int, float)):
        return f"; default {_number(value)}"
    if isinstance(value, Path):
        return f"; default {display_path(value)}"
    return f"; default {value}"


def _bounds(meta):
    """'; low-high' of declared bounds ('above low', 'below high' when open), or ''."""
    low, high = meta.get("low"), meta.get("high")
    if low is None and high is None:
        return ""
    if high is None:
        return f"; {'above' if meta.get('low_open') else 'at least'} {_number(low)}"
    if low is None:
        return f"; {'below' if meta.get('high_open') else 'at most'} {_number(high)}"
    ends = [f"{w} {_number(v)}" for w, v, is_open in (("above", low, meta.get("low_open")),
                                                ("below", high, meta.get("high_open")))
            if is_open]
    return f"; {_number(low)}-{_number(high)}" + (f" ({' and '.join(ends)})" if ends else "")


def add_arguments(parser, cls, names=None):
    """Add the flagged fields of parameter dataclass ``cls`` to an argparse parser (their
    defaults None: the dataclass decides).  Field types: int, float, str, Path; bool is a
    switch, tuple a flag that may be given several times (``tuple[float, ...]``: each
    value of that type), or once with several values when declared :func:`several`, or
    once with values apart by commas when its metadata says ``commas``."""
    for f in dataclasses.fields(cls):
        meta = f.metadata
        if not meta.get("flag") or (names is not None and f.name not in names):
            continue
        kwargs = {"dest": f.name, "default": None, "help": _help(f)}
        if meta.get("metavar"):
            kwargs["metavar"] = meta["metavar"]
        kind = {"int": int, "float": float, "str": str, "bool": bool, "tuple": tuple,
                "Path": Path}.get(f.type, f.type) if isinstance(f.type, str) else f.type
        if meta.get("choices"):
            kwargs["choices"] = meta["choices"]
        elif kind is bool:
            kwargs["action"] = "store_const"
            kwargs["const"] = True
        elif meta.get("several"):
            kwargs.update(nargs="+", type=typing.get_args(kind)[0], action=_Once)
        elif meta.get("commas"):
            kwargs.update(type=str, action=_Once)        # split by from_args
        elif kind is tuple or typing.get_origin(kind) is tuple:
            kwargs.update(_tuple_kwargs(typing.get_args(kind)))
        else:
            kwargs["type"] = kind
        if "action" not in kwargs and "nargs" not in kwargs:
            kwargs["action"] = _Once
        parser.add_argument(meta["flag"], **kwargs)


def several(declared):
    """A ``tuple[float, ...]`` field declared by ``param`` as one flag followed by its
    values (``--mu-s 0.3 0.2``), given once, rather than a flag given once per value."""
    return dataclasses.field(default=declared.default,
                             metadata={**declared.metadata, "several": True})


class _Once(argparse.Action):
    """Store a flag's one value; the flag given again is noted (``_repeated``), and
    :func:`from_args` refuses it: a later value would silently replace the first."""

    def __call__(self, parser, namespace, values, option_string=None):
        if getattr(namespace, self.dest, None) is not None:
            repeated = getattr(namespace, "_repeated", [])
            setattr(namespace, "_repeated", repeated + [
                f"{option_string} given more than once ({_shown(getattr(namespace, self.dest))} "
                f"and {_shown(values)}); give it once"])
        setattr(namespace, self.dest, values)


def _comma_list(text, f):
    """The values of field ``f`` (``tuple[kind, ...]``) from ``A,B,...``; InputError
    naming its flag."""
    kind, flag = typing.get_args(f.type)[0], f.metadata["flag"]
    try:
        values = tuple(kind(v.strip()) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError(f"{flag}: not a comma-separated list of {kind.__name__} values: "
                         f"{text!r}") from None
    if not values:
        raise InputError(f"{flag}: give at least one value, got {text!r}")
    return values


def _shown(values):
    """A flag's parsed value as typed: a list's values apart by spaces, a tuple's by commas."""
    if isinstance(values, (list, tuple)):
        return (" " if isinstance(values, list) else ",").join(map(str, values))
    return values


def _tuple_kwargs(args):
    """argparse keywords of a tuple field: ``tuple[float, ...]`` a repeatable flag,
    ``tuple[float, float]`` one flag of two values, ``tuple[tuple[float, float], ...]`` a
    repeatable flag of two values."""
    if not args:
        return {"action": "append"}
    if args[-1] is not Ellipsis:
        return {"nargs": len(args), "type": args[0]}
    inner = args[0]
    if typing.get_origin(inner) is tuple:
        return {"action": "append", "nargs": len(typing.get_args(inner)),
                "type": typing.get_args(inner)[0]}
    return {"action": "append", "type": inner}


def _tuples(value):
    """Lists of parsed arguments as tuples (nested too)."""
    return tuple(_tuples(v) for v in value) if isinstance(value, list) else value


def from_args(cls, args, **fixed):
    """An instance of ``cls`` from parsed arguments (fields left None keep defaults);
    InputError when a one-value flag was given twice."""
    repeated = getattr(args, "_repeated", None)
    if repeated:
        raise InputError(repeated[0])
    fields = {f.name: f for f in dataclasses.fields(cls)}
    values = {name: getattr(args, name) for name in fields
              if getattr(args, name, None) is not None}
    values = {k: _comma_list(v, fields[k]) if fields[k].metadata.get("commas") else _tuples(v)
              for k, v in values.items()}
    return cls(**{**values, **fixed})


def add_column_file_argument(parser, note=""):
    """``--column-file NAME_OR_FILE`` of a single run; ``note``: what the command does
    with it (campaigns declare theirs as fields: :mod:`pipeline.campaign.options`)."""
    from pipeline.campaign.column_file import column_file_help  # lazy: the stage runs only with the command (light start-up and --help)
    parser.add_argument("--column-file", dest="column_file", default=None,
                        metavar="NAME_OR_FILE",
                        help=column_file_help() + (f"; {note}" if note else ""))
