"""The colonnade description: the shipped colonnade read and placed, and every kind of bad
input refused with one line naming the problem."""
import copy
import json
import math

import pytest

from pipeline.files import InputError
from pipeline.scenario.colonnade import Course
from pipeline.scenario.colonnade_file import (COLONNADES_DIR, from_dict, load, shipped_names,
                                              to_dict)
from pipeline.scenario.geometry import ColumnGeometry

SHIPPED = "parthenon-north-flank"


@pytest.fixture(scope="module")
def shipped_data():
    return json.loads((COLONNADES_DIR / f"{SHIPPED}.json").read_text())


def test_shipped_colonnade_places_its_beams_on_the_capitals(shipped_data):
    assert SHIPPED in shipped_names()
    colonnade = load(SHIPPED)
    column = ColumnGeometry.load("doric-peristyle")
    faces = colonnade.faces()
    # capitals at the column's height (its tilt of 0.33 deg lowers the top by ~1e-4 m) and
    # moved toward the tilt (South) by height x tan(tilt)
    lean = column.height * math.tan(math.radians(0.33))
    for placed in colonnade.columns:
        capital = faces[placed.name]
        assert capital.z == pytest.approx(column.height, abs=1e-3)
        assert capital.centre == pytest.approx((placed.x, placed.y - lean), abs=2e-3)
    bay = 9 / 4 * column.base_width                      # the 4:9 proportion
    xs = [c.x for c in colonnade.columns]
    assert [b - a for a, b in zip(xs, xs[1:])] == pytest.approx([bay] * 3, abs=1e-3)
    for e, f in zip(colonnade.epistyles, colonnade.frieze):
        assert faces[e.name].z == pytest.approx(faces[e.on[0]].z + e.height)
        assert faces[f.name].z == pytest.approx(faces[e.name].z + f.height)
        first, last = faces[e.on[0]].centre, faces[e.on[-1]].centre
        assert faces[e.name].centre == pytest.approx(((first[0] + last[0]) / 2,
                                                       (first[1] + last[1]) / 2))
    beams = colonnade.epistyles + colonnade.frieze
    beam_mass = sum(b.length * b.width * b.height * b.density for b in beams)
    column_mass = sum(body.mass for c in colonnade.columns for body in c.bodies())
    assert colonnade.beam_mass_ratio == pytest.approx(beam_mass / column_mass)
    assert [b.course for b in beams] == [Course.EPISTYLE] * 3 + [Course.FRIEZE] * 3


def test_description_round_trips(shipped_data):
    colonnade = load(SHIPPED)
    again = from_dict(json.loads(json.dumps(to_dict(colonnade))))
    assert again == colonnade
    assert from_dict(shipped_data) == colonnade


def test_column_files_beside_the_colonnade_and_yaml(tmp_path, shipped_data):
    column = ColumnGeometry.load("doric-peristyle").to_dict()
    (tmp_path / "my-column.json").write_text(json.dumps(column))
    data = copy.deepcopy(shipped_data)
    for c in data["columns"]:
        c["column"] = "my-column.json"
    path = tmp_path / "colonnade.json"
    path.write_text(json.dumps(data))
    assert load(path).columns == load(SHIPPED).columns
    pytest.importorskip("yaml")
    import yaml
    (tmp_path / "colonnade.yaml").write_text(yaml.safe_dump(data))
    assert load(tmp_path / "colonnade.yaml") == load(path)


def _edited(data, edit):
    data = copy.deepcopy(data)
    edit(data)
    return data


def _set(path, value):
    def edit(data):
        *keys, last = path
        node = data
        for key in keys:
            node = node[key]
        node[last] = value
    return edit


SHORT_MONOLITH = {"name": "short", "density": 2700.0, "blocks": [
    {"shape": "frustum", "height": 10.0, "bottom_diameter": 1.9, "top_diameter": 1.9}]}

BAD = [
    ("span no capital", _set(("epistyles", 0, "on"), []), "E1 spans no capital"),
    ("one capital", _set(("epistyles", 0, "on"), ["N1"]), "E1 spans no capital"),
    ("overhangs its capitals", _set(("epistyles", 0, "length"), 6.5),
     "E1 leaves its capitals: its end at (1.036, -0.060) m"),
    ("too short", _set(("epistyles", 0, "length"), 1.5),
     "E1: its end at (3.536, -0.060) m rests on no capital"),
    ("shifted off", _set(("epistyles", 0, "shift"), 1.2),
     "E1: its end at (3.343, -0.060) m rests on no capital"),
    ("skips a capital", lambda d: (_set(("epistyles", 1, "on"), ["N1", "N3"])(d),
                                   _set(("epistyles", 1, "length"), 8.5726)(d)),
     "epistyle E2 also rests on capital N2"),
    ("unknown capital", _set(("epistyles", 0, "on"), ["N1", "N9"]),
     "rests on 'N9', which is no capital"),
    ("longer than the stylobate", _set(("epistyles", 0, "length"), 20.0),
     "longer than the stylobate"),
    ("overlapping columns", _set(("columns", 1, "x"), 3.0), "columns N1 and N2 overlap"),
    ("unknown column name", _set(("columns", 2, "column"), "ionic-nowhere"),
     "unknown column 'ionic-nowhere'"),
    ("off the stylobate", _set(("columns", 3, "y"), 2.5), "N4 at (15.0017, 2.5) m stands off"),
    ("frieze on a capital", _set(("frieze", 0, "on"), ["N1"]), "no epistyle"),
    ("capitals at two levels", _set(("columns", 1, "column"), SHORT_MONOLITH), "one level"),
    ("overlapping epistyles", _set(("epistyles", 1, "on"), ["N1", "N2"]),
     "epistyles E1 and E2 overlap"),
    ("a name twice", _set(("epistyles", 2, "name"), "N1"), "'N1' is given twice"),
    ("unknown key", _set(("stylobate", "height"), 0.5), "unknown key(s) height"),
    ("no stylobate length", _set(("stylobate", "end"), [0.0, 0.0]), "needs a length"),
    ("negative density", _set(("epistyles", 0, "density"), -1.0), "density"),
    ("bool width", _set(("frieze", 0, "width"), True), "width must be a finite number"),
    ("mesh column", _set(("columns", 0, "column"), {"name": "rock", "mesh": "rock.stl"}),
     None),
]


@pytest.mark.parametrize("case, edit, words", BAD, ids=[b[0] for b in BAD])
def test_bad_colonnades_get_one_line(shipped_data, case, edit, words):
    with pytest.raises(InputError) as info:
        from_dict(_edited(shipped_data, edit), where="c.json")
    message = str(info.value)
    assert "\n" not in message and message.startswith("c.json")
    if words is not None:
        assert words in message


def test_unknown_colonnade_and_unreadable_files(tmp_path):
    with pytest.raises(InputError, match="no such file or shipped colonnade"):
        load("no-such-colonnade")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError, match="bad.json: not a readable colonnade"):
        load(bad)
    bad.write_text("[1, 2]")
    with pytest.raises(InputError, match="expected an object"):
        load(bad)
