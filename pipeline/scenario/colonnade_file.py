"""The colonnade description file (JSON, YAML optional; docs/colonnades.md): its keys and
limits, the one loader (:func:`load`, a shipped example's name or a file) and the one
writer of its dict (:func:`to_dict`).  The colonnade it describes:
:class:`pipeline.scenario.colonnade.Colonnade`.

    {"name": str, "source": str, "notes": str,
     "stylobate": {"start": [x, y], "end": [x, y], "width": m},
     "columns": [{"name": str, "column": shipped column name, file or description,
                  "x": m, "y": m}, ...],
     "epistyles": [beam, ...], "frieze": [beam, ...] (optional),
     beam = {"name": str, "on": [support names], "length": m, "width": m, "height": m,
             "density": kg/m^3, "shift": m (optional)}}
"""
from pathlib import Path

from pipeline.files import InputError
from pipeline.scenario.colonnade import Beam, Colonnade, Course, PlacedColumn, Stylobate
from pipeline.scenario.column_format import (DENSITY_RANGE, EXAMPLES_DIR, _check_keys,
                                             _one_line, _parse_json, _parse_yaml,
                                             example_names, shipped_or_file)
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.userfiles import MAX_NESTING, read_text
from pipeline.userfiles import Unreadable as _Unreadable
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import nesting as _nesting
from pipeline.userfiles import number as _number
from pipeline.userfiles import show as _show

COLONNADES_DIR = Path(__file__).with_name("colonnades")
MAX_EXTENT_M = 500.0          # coordinates and stylobate sizes
MAX_BEAM_SIZE_M = 30.0
MIN_BEAM_SIZE_M = 0.05
MAX_COLUMNS = 60
MAX_BEAMS = 200
MAX_NAME = 80
TOP_KEYS = {"name", "stylobate", "columns", "epistyles"}
OPTIONAL_TOP_KEYS = {"source", "notes", "frieze"}
STYLOBATE_KEYS = {"start", "end", "width"}
COLUMN_KEYS = {"name", "column", "x", "y"}
BEAM_KEYS = {"name", "on", "length", "width", "height", "density"}
OPTIONAL_BEAM_KEYS = {"shift"}


def shipped_names():
    """Names of the shipped colonnade descriptions."""
    return sorted(p.stem for p in COLONNADES_DIR.glob("*.json"))


def load(name_or_path):
    """The :class:`Colonnade` of a shipped example's name or a file (.json; .yaml/.yml with
    PyYAML); a column given as a file is found beside the colonnade's file.  Any problem
    is one InputError naming the file."""
    path = _found(name_or_path)
    return from_dict(_read(path), where=path.name, base=path.resolve().parent)


def load_if_colonnade(value):
    """The :class:`Colonnade` that ``value`` (what a column file option holds: a name, a
    file or a description dict) describes, or None when it describes no colonnade (a
    column: no ``stylobate``, or no such file or name here)."""
    if isinstance(value, dict):
        return from_dict(value) if "stylobate" in value else None
    try:
        path = _found(value)
    except InputError:
        return None
    try:
        data = _read(path)
    except InputError:
        if path.parent == COLONNADES_DIR:
            raise
        return None          # the column loader says what is wrong with it
    if not (isinstance(data, dict) and "stylobate" in data):
        return None
    return from_dict(data, where=path.name, base=path.resolve().parent)


def _found(name_or_path):
    """The Path of a shipped colonnade's name or of a file; InputError when neither."""
    path, found, shown = shipped_or_file(name_or_path, COLONNADES_DIR)
    if not found:
        raise InputError(f"colonnade {shown}: no such file or shipped colonnade (shipped: "
                         f"{', '.join(shipped_names())})")
    return path


def _read(path):
    """The parsed content of a colonnade file (JSON or YAML); InputError naming it."""
    yaml_file = path.suffix.lower() in (".yaml", ".yml")
    try:
        raw = read_text(path)
        data = _parse_yaml(raw) if yaml_file else _parse_json(raw)
        if _nesting(data, MAX_NESTING) > MAX_NESTING:
            raise _Unreadable(f"nested more than {MAX_NESTING} levels deep")
    except ImportError:
        raise InputError(f"{path}: reading YAML needs PyYAML (pip install pyyaml); or give "
                         "the colonnade as JSON") from None
    except OSError as exc:
        raise InputError(f"{path}: not a readable colonnade description "
                         f"({_one_line(exc.strerror or exc)})") from None
    except _Unreadable as exc:
        raise InputError(f"{path}: not a readable colonnade description ({exc})") from None
    return data


def from_dict(data, where="colonnade description", base=None):
    """Validate a colonnade description dict (a column as a file is looked for in
    ``base``, a directory); InputError with one line naming the problem."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected an object with name, stylobate, columns, "
                         "epistyles")
    _keys_known(data, TOP_KEYS, OPTIONAL_TOP_KEYS, where)
    for key in ("source", "notes"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise InputError(f"{where}: '{key}' must be a string")
    stylobate = _stylobate(data["stylobate"], f"{where}: stylobate")
    columns = _list(data, "columns", MAX_COLUMNS, where)
    placed = tuple(_column(c, f"{where}: columns[{k}]", base) for k, c in enumerate(columns))
    beams = {}
    for course, key in ((Course.EPISTYLE, "epistyles"), (Course.FRIEZE, "frieze")):
        items = _list(data, key, MAX_BEAMS, where) if key in data or key == "epistyles" \
            else []
        beams[course] = tuple(_beam(b, course, f"{where}: {key}[{k}]", where)
                              for k, b in enumerate(items))
    try:
        return Colonnade(_name(data.get("name"), f"{where}: name"), stylobate, placed,
                         beams[Course.EPISTYLE], beams[Course.FRIEZE], data.get("source"),
                         data.get("notes"))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def to_dict(colonnade):
    """The description dict of a :class:`Colonnade` (columns written out in full)."""
    out = {"name": colonnade.name}
    for key in ("source", "notes"):
        if getattr(colonnade, key) is not None:
            out[key] = getattr(colonnade, key)
    s = colonnade.stylobate
    out["stylobate"] = {"start": list(s.start), "end": list(s.end), "width": s.width}
    out["columns"] = [{"name": c.name, "column": c.column.to_dict(), "x": c.x, "y": c.y}
                      for c in colonnade.columns]
    for key, beams in (("epistyles", colonnade.epistyles), ("frieze", colonnade.frieze)):
        if beams or key == "epistyles":
            out[key] = [{"name": b.name, "on": list(b.on), "length": b.length,
                         "width": b.width, "height": b.height, "density": b.density,
                         "shift": b.shift} for b in beams]
    return out


def _keys_known(raw, required, optional, where):
    _check_keys(raw, where)
    unknown = set(raw) - required - optional
    if unknown:
        raise InputError(f"{where}: unknown key(s) {_keys(unknown)} (allowed: "
                         f"{', '.join(sorted(required | optional))})")
    missing = sorted(required - set(raw))
    if missing:
        raise InputError(f"{where}: missing key(s) {', '.join(missing)}")


def _name(value, where):
    if not isinstance(value, str) or not value.strip() or len(value) > MAX_NAME:
        raise InputError(f"{where} must be a non-empty string (at most {MAX_NAME} "
                         "characters)")
    return value.strip()


def _list(data, key, most, where):
    items = data[key]
    if not isinstance(items, list) or not items:
        raise InputError(f"{where}: '{key}' must be a non-empty list")
    if len(items) > most:
        raise InputError(f"{where}: {len(items)} {key}, at most {most}")
    return items


def _point(value, where):
    if not (isinstance(value, list) and len(value) == 2):
        raise InputError(f"{where} must be [x, y] in metres (East, North)")
    return tuple(_number(v, where, -MAX_EXTENT_M, MAX_EXTENT_M, "m") for v in value)


def _stylobate(raw, where):
    if not isinstance(raw, dict):
        raise InputError(f"{where}: expected an object with start, end, width")
    _keys_known(raw, STYLOBATE_KEYS, set(), where)
    start, end = _point(raw["start"], f"{where}: start"), _point(raw["end"], f"{where}: end")
    if start == end:
        raise InputError(f"{where}: start and end are one point; the stylobate needs a length")
    width = _number(raw["width"], f"{where}: width", 0.0, MAX_EXTENT_M, "m", low_open=True)
    return Stylobate(start, end, width)


def _column(raw, where, base):
    if not isinstance(raw, dict):
        raise InputError(f"{where}: expected an object with name, column, x, y")
    _keys_known(raw, COLUMN_KEYS, set(), where)
    name = _name(raw["name"], f"{where}: name")
    where = f"{where} ({name})"
    x = _number(raw["x"], f"{where}: x", -MAX_EXTENT_M, MAX_EXTENT_M, "m")
    y = _number(raw["y"], f"{where}: y", -MAX_EXTENT_M, MAX_EXTENT_M, "m")
    return PlacedColumn(name, _column_geometry(raw["column"], where, base), x, y)


def _column_geometry(ref, where, base):
    """The ColumnGeometry of a shipped column's name, a file (beside ``base``) or an
    inline description; a mesh specimen refused."""
    if isinstance(ref, dict):
        geometry = ColumnGeometry.from_dict(ref, where=f"{where}: column")
    elif isinstance(ref, str) and ref.strip():
        text = ref.strip()
        path = Path(text)
        if base is not None and not path.is_absolute() and (base / path).is_file():
            path = base / path
        shipped = path.suffix == "" and "/" not in text and \
            (EXAMPLES_DIR / f"{text}.json").is_file()
        if not shipped and not path.is_file():
            raise InputError(f"{where}: unknown column {_show(text)}: no shipped column of "
                             f"that name ({', '.join(example_names())}) and no such file")
        try:
            geometry = ColumnGeometry.load(text if shipped else path)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
    else:
        raise InputError(f"{where}: 'column' must be a shipped column's name, a file or a "
                         f"column description, got {_show(ref)}")
    if not isinstance(geometry, ColumnGeometry):
        raise InputError(f"{where}: a mesh specimen; a colonnade's columns are column "
                         "descriptions (blocks)")
    return geometry


def _beam(raw, course, where, file_where):
    if not isinstance(raw, dict):
        raise InputError(f"{where}: expected an object with name, on, length, width, "
                         "height, density")
    _keys_known(raw, BEAM_KEYS, OPTIONAL_BEAM_KEYS, where)
    name = _name(raw["name"], f"{where}: name")
    what = f"{file_where}: {course.value} {name}"
    on = raw["on"]
    kind = "capitals" if course is Course.EPISTYLE else "epistyles"
    fewest = 2 if course is Course.EPISTYLE else 1
    if not isinstance(on, list) or len(on) < fewest:
        raise InputError(f"{what} spans no {kind[:-1]}: 'on' must name the {kind} it rests "
                         f"on ({'two or more' if fewest == 2 else 'one or more'})")
    if not all(isinstance(n, str) for n in on) or len(set(on)) != len(on):
        raise InputError(f"{what}: 'on' must name each of its {kind} once, got {_show(on)}")
    sizes = [_number(raw[k], f"{what}: {k}", MIN_BEAM_SIZE_M, MAX_BEAM_SIZE_M, "m")
             for k in ("length", "width", "height")]
    density = _number(raw["density"], f"{what}: density", *DENSITY_RANGE, "kg/m^3")
    moved = {} if "shift" not in raw else {"shift": _number(
        raw["shift"], f"{what}: shift", -MAX_BEAM_SIZE_M, MAX_BEAM_SIZE_M, "m")}
    return Beam(name, course, tuple(on), *sizes, density, **moved)
