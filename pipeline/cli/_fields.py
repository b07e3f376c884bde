"""Command-line flags from parameter dataclasses: every field declared with
:func:`pipeline.scenario.parameters.param` and a flag becomes one option, with its
default, unit, bounds and help; parsed values go back through the dataclass, which
checks them."""
import dataclasses
import typing
from pathlib import Path


def _help(f):
    meta = f.metadata
    unit = f" ({meta['unit']})" if meta.get("unit") else ""
    if f.default is None or f.default == () or isinstance(f.default, bool):
        default = ""
    elif isinstance(f.default, (int, float)):
        default = f"; default {f.default:g}"
    else:
        default = f"; default {f.default}"
    bounds = "" if meta.get("low") is None else f"; {meta['low']:g}-{meta['high']:g}"
    return f"{meta['help']}{unit}{default}{bounds}".replace("%", "%%")


def add_arguments(parser, cls, names=None):
    """Add the flagged fields of parameter dataclass ``cls`` to an argparse parser (their
    defaults None: the dataclass decides).  Field types: int, float, str, Path; bool is a
    switch, tuple a flag that may be given several times (``tuple[float, ...]``: each
    value of that type)."""
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
        elif kind is tuple or typing.get_origin(kind) is tuple:
            kwargs["action"] = "append"
            if typing.get_args(kind):
                kwargs["type"] = typing.get_args(kind)[0]
        else:
            kwargs["type"] = kind
        parser.add_argument(meta["flag"], **kwargs)


def from_args(cls, args, **fixed):
    """An instance of ``cls`` from parsed arguments (fields left None keep defaults)."""
    values = {f.name: getattr(args, f.name) for f in dataclasses.fields(cls)
              if getattr(args, f.name, None) is not None}
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()}
    return cls(**{**values, **fixed})


def add_column_file_argument(parser, note=""):
    """``--column-file NAME_OR_FILE`` of a single run; ``note``: what the command does
    with it (campaigns declare theirs as fields: :mod:`pipeline.campaign.options`)."""
    from pipeline.campaign.column_file import column_file_help  # lazy: the stage runs only with the command (light start-up and --help)
    parser.add_argument("--column-file", dest="column_file", default=None,
                        metavar="NAME_OR_FILE",
                        help=column_file_help() + (f"; {note}" if note else ""))
