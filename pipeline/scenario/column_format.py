"""The column description file (JSON, YAML optional): limits, keys and the parsing of a
description into :class:`~pipeline.scenario.solids.ColumnBlock` objects; the shipped examples.
Schema: docs/columns-and-model.md; the column it describes:
:class:`pipeline.scenario.geometry.ColumnGeometry`."""
import json
import math
from pathlib import Path

from pipeline.files import InputError
from pipeline.scenario.solids import SHAPES, TILT_MODES, Box, ColumnBlock, Frustum
from pipeline.userfiles import MAX_INT_DIGITS, MAX_NESTING
from pipeline.userfiles import Unreadable as _Unreadable
from pipeline.userfiles import json_int as _json_int
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import number as _number
from pipeline.userfiles import number_text as _g
from pipeline.userfiles import show as _show

EXAMPLES_DIR = Path(__file__).with_name("columns")
# plausibility limits of a column file ("absurd values" are rejected with one line)
MIN_SIZE_M = 0.02            # a block must hold its rims of contact spheres (4 radii)
MAX_BLOCK_HEIGHT_M = 30.0
MAX_WIDTH_M = 10.0
MAX_COLUMN_HEIGHT_M = 40.0
MAX_BLOCKS = 60
DENSITY_RANGE = (100.0, 25000.0)
MAX_TILT_DEG = 30.0
MAX_OFFSET_M = 2.0
TOP_KEYS = {"name", "density", "blocks", "source", "notes"}
BLOCK_KEYS = {"frustum": {"height", "bottom_diameter", "top_diameter"},
              "box": {"height", "width", "depth"}}
OPTIONAL_BLOCK_KEYS = {"shape", "density", "name", "offset_m", "tilt_deg", "tilt_azimuth_deg",
                       "tilt_mode", "joined", "notes"}


def _one_line(text, most=200):
    """``text`` as one line of at most ``most`` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= most else text[:most - 3] + "..."


def _check_keys(mapping, where):
    for key in mapping:
        if not isinstance(key, str):
            raise InputError(f"{where}: keys must be strings, got {_show(key)}")


def _parse_json(text):
    try:
        return json.loads(text, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise _Unreadable(f"line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
    except RecursionError:
        raise _Unreadable(f"nested more than {MAX_NESTING} levels deep") from None
    except ValueError as exc:
        raise _Unreadable(_one_line(exc)) from None


_YAML_LOADER = None


def _yaml_loader():
    """PyYAML's SafeLoader (standard tags only) that refuses long integers and reports a
    standard tag's bad value (``!!bool maybe``, a 13th month) at its line and column."""
    global _YAML_LOADER
    if _YAML_LOADER is None:
        import yaml  # lazy: PyYAML, optional (YAML column files only)
        from yaml.constructor import ConstructorError  # lazy: PyYAML, optional (YAML column files only)

        class Loader(yaml.SafeLoader):
            def construct_object(self, node, deep=False):
                try:
                    return super().construct_object(node, deep)
                except (yaml.YAMLError, RecursionError):
                    raise
                except Exception as exc:         # the standard tags' own constructors
                    value = f"{node.value!r:.40} " if isinstance(node, yaml.ScalarNode) else ""
                    raise ConstructorError(None, None, f"cannot read {value}as "
                                           f"{node.tag.rpartition(':')[2]} ({exc})",
                                           node.start_mark) from None

            def construct_yaml_int(self, node):
                digits = len(str(node.value).lstrip("+-"))
                if digits > MAX_INT_DIGITS:
                    raise ConstructorError(None, None, f"an integer of {digits} digits (at "
                                           f"most {MAX_INT_DIGITS})", node.start_mark)
                return super().construct_yaml_int(node)

        Loader.add_constructor("tag:yaml.org,2002:int", Loader.construct_yaml_int)
        _YAML_LOADER = Loader
    return _YAML_LOADER


def _parse_yaml(text):
    import yaml  # lazy: PyYAML, optional (YAML column files only)
    try:
        return yaml.load(text, Loader=_yaml_loader())
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        at = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = ", ".join(p for p in (exc.context, exc.problem) if p)
        raise _Unreadable(_one_line(at + (problem or "not YAML"))) from None
    except yaml.YAMLError as exc:                # e.g. a control character
        raise _Unreadable(_one_line(exc)) from None
    except RecursionError:
        raise _Unreadable(f"nested more than {MAX_NESTING} levels deep") from None


def _parse_block(raw, where, index):
    if not isinstance(raw, dict):
        raise InputError(f"{where}: expected an object with shape and sizes")
    _check_keys(raw, where)
    shape = raw.get("shape")
    if shape is None:
        raise InputError(f"{where}: missing key 'shape' (one of {', '.join(SHAPES)})")
    if shape not in SHAPES:
        raise InputError(f"{where}: unknown shape {_show(shape)} (known: {', '.join(SHAPES)})")
    missing = sorted(BLOCK_KEYS[shape] - set(raw))
    if missing:
        raise InputError(f"{where}: missing key(s) {', '.join(missing)} for a {shape}")
    unknown = set(raw) - BLOCK_KEYS[shape] - OPTIONAL_BLOCK_KEYS
    if unknown:
        raise InputError(f"{where}: unknown key(s) {_keys(unknown)} for a {shape}")
    sizes = {}
    for key in sorted(BLOCK_KEYS[shape]):
        value = raw[key]
        if isinstance(value, (int, float)) and not isinstance(value, bool) and \
                (isinstance(value, int) or math.isfinite(value)) and value <= 0:
            raise InputError(f"{where}: {key} must be positive, got {_g(value)}")
        high = MAX_BLOCK_HEIGHT_M if key == "height" else MAX_WIDTH_M
        sizes[key] = _number(value, f"{where}: {key}", MIN_SIZE_M, high, "m")
    solid = Frustum(**sizes) if shape == "frustum" else Box(**sizes)
    density = None if raw.get("density") is None else _number(
        raw["density"], f"{where}: density", *DENSITY_RANGE, "kg/m^3")
    offset = raw.get("offset_m", [0.0, 0.0])
    if not (isinstance(offset, (list, tuple)) and len(offset) == 2):
        raise InputError(f"{where}: offset_m must be [east, north] in metres")
    offset = tuple(_number(v, f"{where}: offset_m", -MAX_OFFSET_M, MAX_OFFSET_M, "m")
                   for v in offset)
    tilt = _number(raw.get("tilt_deg", 0.0), f"{where}: tilt_deg", 0.0, MAX_TILT_DEG, "deg")
    azimuth = _number(raw.get("tilt_azimuth_deg", 0.0), f"{where}: tilt_azimuth_deg", 0.0,
                      360.0, "deg") % 360.0
    mode = raw.get("tilt_mode", "wedge")
    if mode not in TILT_MODES:
        raise InputError(f"{where}: tilt_mode must be one of {', '.join(TILT_MODES)}, "
                         f"got {_show(mode)}")
    joined = raw.get("joined", False)
    if not isinstance(joined, bool):
        raise InputError(f"{where}: joined must be true or false")
    if joined and index == 0:
        raise InputError(f"{where}: the bottom block cannot be joined to a block below")
    if joined and tilt:
        raise InputError(f"{where}: a joined block shares the tilt of the stone it is "
                         "carved with; give tilt_deg on that stone's first block")
    name = raw.get("name")
    if name is not None and not isinstance(name, str):
        raise InputError(f"{where}: name must be a string")
    return ColumnBlock(solid, density, name, offset, tilt, azimuth, mode, joined)


def example_names():
    """Names of the shipped column descriptions."""
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.json"))


def shipped_or_file(name_or_path, directory):
    """(path, found, shown) of a description named by the user: the shipped
    ``directory/<name>.json`` for a bare name it holds, else the path as given; ``found``:
    it is a file (False for a name no file system takes: too long, a NUL byte);
    ``shown``: the name as a message may print it."""
    text = str(name_or_path)
    path = Path(text)
    shipped = directory / f"{text}.json"
    try:
        if path.suffix == "" and "/" not in text and shipped.is_file():
            path = shipped
        found = path.is_file()
    except (OSError, ValueError):
        found = False
    return path, found, text if text.isprintable() and len(text) <= 300 else _show(text)
