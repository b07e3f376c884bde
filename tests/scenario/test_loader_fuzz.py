"""The loaders of the files a user writes (column descriptions, JSON or YAML, and
observation files) against malformed content: whatever a file holds, the loader returns
a valid object or raises one InputError whose message is one line naming the file; never
another exception, never a hang.  Explicit cases for each known way to break a parser or
a validator, then property-based fuzzing (Hypothesis) of arbitrary JSON-like values,
arbitrary bytes and text, and shipped files with one field changed to anything."""
import copy
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pipeline import cli
from pipeline.files import InputError
from pipeline.inversion import EXAMPLES_DIR as OBSERVATION_EXAMPLES
from pipeline.inversion.observations import COLUMN_KEYS as COLUMN_KEYS_OBS
from pipeline.inversion.observations import (
    MAX_SITES,
    SITE_KEYS,
    Observations,
    load_observations,
    parse_observations,
)
from pipeline.userfiles import MAX_FILE_BYTES
from pipeline.scenario.column_format import (
    BLOCK_KEYS,
    EXAMPLES_DIR,
    OPTIONAL_BLOCK_KEYS,
    TOP_KEYS,
    example_names,
)
from pipeline.scenario.geometry import ColumnGeometry

yaml = pytest.importorskip("yaml")

FUZZ = settings(max_examples=200, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
GOOD_SITE = {"name": "A", "east_km": 0, "north_km": 0,
             "columns": [{"column": "drums", "state": "fallen", "downfall_azimuth_deg": 240,
                          "uncertainty_deg": 10}, {"column": "monolithic", "state": "standing"}]}
SHIPPED = {name: json.loads((EXAMPLES_DIR / f"{name}.json").read_text())
           for name in example_names()}
OBSERVATIONS = [{"sites": [GOOD_SITE, dict(GOOD_SITE, name="B", east_km=4.0, north_km=-3.0)]},
                json.loads((OBSERVATION_EXAMPLES / "two_sites.json").read_text()),
                json.loads((OBSERVATION_EXAMPLES / "geographic.json").read_text())]


def write(path, content):
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        path.write_text(content, encoding="utf-8", errors="surrogatepass")
    elif path.suffix in (".yaml", ".yml"):
        path.write_text(yaml.safe_dump(content, allow_unicode=False, sort_keys=False))
    else:
        path.write_text(json.dumps(content))
    return path


def outcome(loader, path, valid_type):
    """The loader's result on ``path``: "ok" or the InputError's message, after checking
    the contract (a valid object, or a one-line message naming the file)."""
    try:
        result = loader(path)
    except InputError as exc:
        message = str(exc)
        assert message and message.isprintable() and len(message.splitlines()) == 1, message
        assert path.name in message, message
        assert len(message) < 1000, message
        return message
    assert isinstance(result, valid_type)
    return "ok"


def load_column(path):
    return outcome(ColumnGeometry.load, path, ColumnGeometry)


def load_obs(path):
    return outcome(load_observations, path, Observations)


def mutated(doc, path, value):
    """A deep copy of ``doc`` with the item at ``path`` (keys and indices) set to
    ``value`` (deleted for the sentinel DELETE)."""
    doc = copy.deepcopy(doc)
    *parents, last = path
    target = doc
    for key in parents:
        target = target[key]
    if value is DELETE:
        del target[last]
    else:
        target[last] = value
    return doc


DELETE = object()


def paths_of(doc, prefix=()):
    """Every path (tuple of keys and indices) to an item of a parsed document."""
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) \
        if isinstance(doc, list) else ()
    for key, value in items:
        yield prefix + (key,)
        yield from paths_of(value, prefix + (key,))


# ---------------------------------------------------------------- column descriptions
def good(**changes):
    return dict(copy.deepcopy(SHIPPED["roman-granite"]), **changes)


def good_block(index=2, **changes):
    doc = good()
    doc["blocks"][index].update(changes)
    return doc


COLUMN_FILES = [
    # (file name, content, words expected in the message)
    ("syntax.yaml", "name: [x\n", "line 2, column 1"),
    ("syntax2.yaml", "name: x\n  density: 2700\n- blocks\n", "line"),
    ("tab.yaml", "name:\t\tx\n\tdensity: 1\n", "line"),
    ("python-tag.yaml", "!!python/object/apply:os.system ['echo pwned']\n",
     "could not determine a constructor"),
    ("python-name.yaml", "name: !!python/name:os.system\n", "line 1, column 7"),
    ("int-key.yaml", "{1: 2}\n", "keys must be strings, got 1"),
    ("int-key-among-strings.yaml", "name: x\ndensity: 2700\n1: 2\nblocks: []\n",
     "keys must be strings"),
    ("null-key.yaml", "~: 1\n", "keys must be strings, got None"),
    ("date-key.yaml", "2020-01-01: 1\n", "keys must be strings"),
    ("bool-key-in-block.yaml", "name: x\ndensity: 2700\nblocks:\n- {true: 1}\n",
     "blocks[0]: keys must be strings"),
    ("sequence-key.yaml", "? [a, b]\n: 1\n", "unhashable key"),
    ("mapping-key.yaml", "? {a: 1}\n: 1\n", "unhashable key"),
    ("bad-bool.yaml", "name: x\ndensity: !!bool maybe\n", "line 2, column 10"),
    ("bad-int.yaml", "name: x\ndensity: !!int ''\n", "line 2"),
    ("bad-timestamp.yaml", "name: x\ndensity: !!timestamp soon\n", "line 2"),
    ("13th-month.yaml", "name: 2020-13-45\n", "line 1, column 7"),
    ("bad-binary.yaml", "name: !!binary 'a'\n", "line 1"),
    ("bad-merge.yaml", "<<: 1\n", "line 1"),
    ("control-char.yaml", "name: x\x00\n", "special characters"),
    ("deep.yaml", "[" * 5000 + "]" * 5000, "nested"),
    ("deep-under-recursion-limit.yaml", "[" * 40 + "]" * 40, "nested more than 16"),
    ("refers-to-itself.yaml", "&a [*a]\n", "refers to itself"),
    ("merge-into-itself.yaml", "&a {<<: *a}\n", "missing key 'name'"),
    ("long-int.yaml", "name: x\ndensity: " + "9" * 5000 + "\n", "an integer of 5000 digits"),
    ("long-sexagesimal.yaml", "density: " + "1:" * 5000 + "1\n", "an integer of"),
    ("int-beyond-float.yaml", "name: x\ndensity: " + "9" * 99 + "\nblocks: []\n",
     "outside the allowed range"),
    ("nan.yaml", "name: x\ndensity: .nan\nblocks: []\n", "must be a finite number, got nan"),
    ("inf.yaml", "name: x\ndensity: -.inf\nblocks: []\n", "must be a finite number"),
    ("set.yaml", "name: x\ndensity: !!set {a, b}\nblocks: []\n", "must be a finite number"),
    ("empty.yaml", "", "expected a JSON object"),
    ("deep.json", "[" * 100_000 + "]" * 100_000, "nested"),
    ("deep-under-recursion-limit.json", "[" * 40 + "]" * 40, "nested more than 16"),
    ("deep-object.json", '{"a":' * 40 + "1" + "}" * 40, "nested more than 16"),
    ("huge-int.json", json.dumps(good(density=10 ** 400)), "an integer of 401 digits"),
    ("huge-int-block.json", json.dumps(good_block(height=-10 ** 400)), "an integer of"),
    ("huge-int-offset.json", json.dumps(good_block(offset_m=[10 ** 400, 0])), "an integer"),
    ("very-long-int.json", '{"density": ' + "9" * 5000 + "}", "an integer of 5000 digits"),
    ("int-beyond-float.json", json.dumps(good(density=10 ** 99)), "density 1e+99 outside"),
    ("float-overflow.json", '{"name": "x", "density": 1e400, "blocks": []}',
     "must be a finite number, got inf"),
    ("nan.json", '{"name": "x", "density": NaN, "blocks": []}', "got nan"),
    ("not-utf8.json", b'{"name": "\xff\xfe", "density": 2700}', "not UTF-8"),
    ("latin1.json", '{"name": "Säule"}'.encode("latin-1"), "byte 12 is 0xe4"),
    ("utf16.json", json.dumps(good()).encode("utf-16"), "not UTF-8"),
    ("binary.json", bytes(range(256)), "not UTF-8"),
    ("nul.json", b"\x00" * 10, "not a readable column description"),
    ("too-large.json", b" " * MAX_FILE_BYTES + b"{}", "larger than 1 MB"),
    ("too-large.yaml", b"#" * (MAX_FILE_BYTES + 1), "larger than 1 MB"),
    ("truncated.json", json.dumps(good())[:100], "line 1, column"),
    ("empty.json", "", "line 1, column 1"),
    ("list.json", "[1, 2]", "expected a JSON object"),
    ("string.json", '"column"', "expected a JSON object"),
    ("key-with-newline.json", json.dumps(good(**{"a\nb": 1})), "unknown key(s) 'a\\nb'"),
    ("many-unknown-keys.json", json.dumps(good(**{f"k{i}": i for i in range(500)})),
     "and 492 more"),
    ("lone-surrogate.json", '{"name": "x", "density": 2700, "blocks": [], "\\ud800": 1}',
     "unknown key(s) '\\ud800'"),
]


@pytest.mark.parametrize("field, words", [
    ("blocks: *i", "blocks[0]: expected an object"),
    ("blocks: [{shape: frustum, height: *i, bottom_diameter: 1, top_diameter: 1}]",
     "blocks[0]: height must be a finite number, got [[[...], [...], [...], [...], ...], "),
    ("blocks: []\nname: *i", "'name' must be a non-empty string"),
    ("blocks: [*i, *i]\nnotes: *i", "blocks[0]: expected an object")])
def test_yaml_alias_bomb_is_quick(tmp_path, field, words):
    """'Billion laughs': nine levels of nine aliases are 9^9 strings if expanded; they are
    neither expanded nor walked (the nesting check visits each list once)."""
    anchors = ['a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for prev, key in zip("abcdefgh", "bcdefghi"):
        anchors.append(f"{key}: &{key} [" + ", ".join([f"*{prev}"] * 9) + "]")
    name = "" if "name:" in field else "name: x\n"
    doc = name + "density: 2700\nsource:\n  " + "\n  ".join(anchors) + "\n" + field + "\n"
    message = load_column(write(tmp_path / "bomb.yaml", doc))
    assert words in message, message


def test_yaml_aliases_for_repeated_drums_are_fine(tmp_path):
    doc = ("name: seven drums\ndensity: 2960\nblocks:\n"
           "- &drum {shape: frustum, height: 0.5, bottom_diameter: 0.5833333333333334, "
           "top_diameter: 0.5833333333333334}\n" + "- *drum\n" * 6)
    assert load_column(write(tmp_path / "drums.yaml", doc)) == "ok"
    assert ColumnGeometry.load(tmp_path / "drums.yaml").blocks == \
        ColumnGeometry.load("hinzen2009-drums").blocks


def test_a_utf8_bom_is_accepted(tmp_path):
    path = write(tmp_path / "bom.json", b"\xef\xbb\xbf" + json.dumps(good()).encode())
    assert ColumnGeometry.load(path) == ColumnGeometry.load("roman-granite")
    path = write(tmp_path / "bom-bad.json", b"\xef\xbb\xbf{\xff}")
    assert "byte 5 is 0xff" in load_column(path)


@pytest.mark.parametrize("arg", ["a\x00b", "x" * 5000, "a/" + "y" * 300 + ".json"])
def test_impossible_file_names_are_one_line_errors(arg):
    with pytest.raises(InputError) as info:
        ColumnGeometry.load(arg)
    assert "no such file or shipped example" in str(info.value)
    assert len(str(info.value).splitlines()) == 1 and str(info.value).isprintable()


WRONG_TYPES = [
    # (change to the Roman granite column, words expected in the message)
    ({"blocks": {"a": 1}}, "'blocks' must be a non-empty list"),
    ({"blocks": "frustum"}, "'blocks' must be a non-empty list"),
    ({"blocks": [[1, 2]]}, "blocks[0]: expected an object"),
    ({"blocks": ["frustum"]}, "blocks[0]: expected an object"),
    ({"blocks": [None]}, "blocks[0]: expected an object"),
    ({"blocks": [{}] * 61}, "61 blocks, at most 60"),
    ({"name": 5}, "'name' must be a non-empty string"),
    ({"name": ["x"]}, "'name' must be a non-empty string"),
    ({"name": "x" * 81}, "'name' must be a non-empty string"),
    ({"density": "2700"}, "density must be a finite number, got '2700'"),
    ({"density": True}, "density must be a finite number, got True"),
    ({"density": None}, "density must be a finite number, got None"),
    ({"density": {}}, "density must be a finite number"),
    ({"density": float("nan")}, "density must be a finite number, got nan"),
    ({"density": float("-inf")}, "density must be a finite number, got -inf"),
    ({"density": 10 ** 400}, "density 100000000000000000...0000000000000000000 outside"),
    ({"density": -10 ** 400}, "outside the allowed range"),
    ({"density": "x" * 10_000}, "..."),
    ({"source": 5}, "'source' must be a string"),
    ({"notes": ["a"]}, "'notes' must be a string"),
    ({1: 2}, "keys must be strings, got 1"),
    ({None: 2}, "keys must be strings, got None"),
    ({("a", "b"): 2}, "keys must be strings, got ('a', 'b')"),
]
WRONG_BLOCK_TYPES = [
    ({"shape": ["frustum"]}, "unknown shape ['frustum']"),
    ({"shape": {"a": 1}}, "unknown shape {'a': 1}"),
    ({"shape": 5}, "unknown shape 5"),
    ({"shape": None}, "missing key 'shape'"),
    ({"height": "1"}, "height must be a finite number, got '1'"),
    ({"height": True}, "height must be a finite number, got True"),
    ({"height": None}, "height must be a finite number, got None"),
    ({"height": [1]}, "height must be a finite number, got [1]"),
    ({"height": float("nan")}, "height must be a finite number, got nan"),
    ({"height": float("inf")}, "height must be a finite number, got inf"),
    ({"height": float("-inf")}, "height must be a finite number, got -inf"),
    ({"height": 10 ** 400}, "height 100000000000000000...0000000000000000000 outside"),
    ({"height": -10 ** 400}, "height must be positive, got -1000"),
    ({"bottom_diameter": 10 ** 20}, "bottom_diameter 1e+20 outside"),
    ({"density": "heavy"}, "density must be a finite number"),
    ({"density": 10 ** 400}, "outside the allowed range"),
    ({"offset_m": "ab"}, "offset_m must be [east, north]"),
    ({"offset_m": {"east": 1, "north": 2}}, "offset_m must be [east, north]"),
    ({"offset_m": [1, "x"]}, "offset_m must be a finite number, got 'x'"),
    ({"offset_m": [10 ** 400, 0]}, "offset_m 1000"),
    ({"offset_m": [float("nan"), 0]}, "offset_m must be a finite number, got nan"),
    ({"offset_m": None}, "offset_m must be [east, north]"),
    ({"tilt_deg": [1]}, "tilt_deg must be a finite number, got [1]"),
    ({"tilt_deg": None}, "tilt_deg must be a finite number, got None"),
    ({"tilt_azimuth_deg": 10 ** 400}, "tilt_azimuth_deg 1000"),
    ({"tilt_azimuth_deg": True}, "tilt_azimuth_deg must be a finite number, got True"),
    ({"tilt_mode": ["edge"]}, "tilt_mode must be one of wedge, edge, got ['edge']"),
    ({"tilt_mode": {}}, "tilt_mode must be one of wedge, edge, got {}"),
    ({"tilt_mode": None}, "tilt_mode must be one of wedge, edge, got None"),
    ({"joined": "yes"}, "joined must be true or false"),
    ({"joined": 1}, "joined must be true or false"),
    ({"joined": 10 ** 400}, "joined must be true or false"),
    ({"name": 5}, "name must be a string"),
    ({"name": {"a": 1}}, "name must be a string"),
    ({"a\nb": 1}, "unknown key(s) 'a\\nb' for a frustum"),
    ({1: 2}, "blocks[2]: keys must be strings, got 1"),
]


def assert_one_line_error(doc, words):
    """``doc`` read as col.json raises one printable line naming the file and ``words``."""
    with pytest.raises(InputError) as info:
        ColumnGeometry.from_dict(doc, where="col.json")
    message = str(info.value)
    assert message.startswith("col.json: ") and len(message.splitlines()) == 1, message
    assert message.isprintable() and len(message) < 1000, message
    assert words in message, message


@pytest.mark.parametrize("change, words", WRONG_TYPES)
def test_wrong_types_in_a_description_are_one_line_errors(change, words):
    doc = good()
    doc.update(change)
    assert_one_line_error(doc, words)


@pytest.mark.parametrize("change, words", WRONG_BLOCK_TYPES)
def test_wrong_types_in_a_block_are_one_line_errors(change, words):
    doc = good()
    doc["blocks"][2].update(change)
    if change.get("shape", "frustum") is None:
        del doc["blocks"][2]["shape"]
    assert_one_line_error(doc, words)


def test_a_malformed_described_column_stops_invert_with_one_line(tmp_path, capsys):
    """Through the command line: a YAML column file with a Python tag beside the
    observations, and an observations file nested too deeply: exit 2, one line."""
    write(tmp_path / "evil.yaml", "!!python/object/apply:os.system ['echo pwned']\n")
    obs = write(tmp_path / "obs.json", {"sites": [dict(GOOD_SITE, columns=[
        {"column": "evil.yaml", "state": "standing"}])]})
    deep = write(tmp_path / "deep.json", "[" * 100_000 + "]" * 100_000)
    for path, words in ((obs, "column 'evil.yaml'"), (deep, "deep.json: nested more than 16")):
        out = tmp_path / "out"
        code = cli.main(["invert", str(path), "--out", str(out), "--table",
                         str(tmp_path / "never-read.npz")])
        captured = capsys.readouterr()
        assert code == 2 and captured.err.count("\n") == 1, captured.err
        assert captured.err.startswith("error: ") and words in captured.err, captured.err
        assert not out.exists()


# ---------------------------------------------------------------- observation files
def site(**changes):
    return dict(copy.deepcopy(GOOD_SITE), **changes)


def column(**changes):
    return dict({"column": "drums", "state": "fallen", "downfall_azimuth_deg": 240}, **changes)


OBSERVATION_FILES = [
    ("deep.json", "[" * 100_000 + "]" * 100_000, "nested more than 16 levels deep"),
    ("deep-under-recursion-limit.json", "[" * 40 + "]" * 40, "nested more than 16"),
    ("deep-in-a-note.json", json.dumps({"sites": [site(columns=[
        column(note=[[[[[[[[[[[[[[[[["x"]]]]]]]]]]]]]]]]])])]}), "nested more than 16"),
    ("huge-int.json", json.dumps({"sites": [site(east_km=10 ** 400)]}),
     "an integer of 401 digits"),
    ("very-long-int.json", '{"sites": [{"east_km": ' + "9" * 5000 + "}]}",
     "an integer of 5000 digits"),
    ("int-beyond-range.json", json.dumps({"sites": [site(east_km=10 ** 99)]}),
     "east_km 1e+99 outside the allowed range [-10000, 10000]"),
    ("float-overflow.json", '{"sites": [{"name": "A", "east_km": 1e400, "north_km": 0, '
     '"columns": [{"column": "drums", "state": "standing"}]}]}', "east_km must be a finite number, got inf"),
    ("nan.json", '{"sites": [{"name": "A", "east_km": NaN, "north_km": 0, '
     '"columns": [{"column": "drums", "state": "standing"}]}]}', "east_km must be a finite number, got nan"),
    ("not-utf8.json", b'{"sites": "\xff"}', "not a text (JSON) file (byte 12 is 0xff"),
    ("utf16.json", json.dumps({"sites": [GOOD_SITE]}).encode("utf-16"), "not a text"),
    ("binary.json", bytes(range(256)), "not a text"),
    ("nul.json", b"\x00" * 10, "not valid JSON"),
    ("too-large.json", b" " * MAX_FILE_BYTES + b"{}", "larger than 1 MB"),
    ("empty.json", "", "not valid JSON (line 1, column 1"),
    ("truncated.json", json.dumps({"sites": [GOOD_SITE]})[:50], "not valid JSON (line 1"),
    ("sites-object.json", {"sites": {"A": GOOD_SITE}}, "'sites' must be a non-empty list"),
    ("sites-string.json", {"sites": "A"}, "'sites' must be a non-empty list"),
    ("site-list.json", {"sites": [[1, 2]]}, "site 1: must be an object, got list"),
    ("site-null.json", {"sites": [None]}, "site 1: must be an object, got NoneType"),
    ("name-list.json", {"sites": [site(name=["A"])]}, "'name' must be a non-empty string"),
    ("name-long.json", {"sites": [site(name="A\n" * 10_000, east_km="x")]},
     "east_km must be a finite number, got 'x'"),
    ("east-string.json", {"sites": [site(east_km="3")]}, "east_km must be a finite number, got '3'"),
    ("east-bool.json", {"sites": [site(east_km=True)]}, "east_km must be a finite number, got True"),
    ("east-null.json", {"sites": [site(east_km=None)]}, "east_km must be a finite number, got None"),
    ("east-list.json", {"sites": [site(east_km=[1] * 1000)]}, "got [1, 1, 1, 1, ...]"),
    ("latitude-object.json", {"sites": [{"name": "A", "latitude": {}, "longitude": 1,
                                         "columns": GOOD_SITE["columns"]}]},
     "latitude must be a finite number"),
    ("columns-string.json", {"sites": [site(columns="drums")]}, "'columns' must be a non-empty"),
    ("columns-object.json", {"sites": [site(columns={"column": "drums"})]}, "'columns' must"),
    ("column-list.json", {"sites": [site(columns=[["drums"]])]}, "a column must be an object"),
    ("column-name-list.json", {"sites": [site(columns=[column(column=["drums"])])]},
     "'column' must be drums, monolithic or a column file name"),
    ("column-name-nul.json", {"sites": [site(columns=[column(column="a\x00b")])]},
     "'column' must be drums, monolithic or a column file name"),
    ("column-name-long.json", {"sites": [site(columns=[column(column="c" * 300)])]},
     "'column' must be drums, monolithic or a column file name"),
    ("state-list.json", {"sites": [site(columns=[column(state=["fallen"])])]},
     "'state' must be 'fallen' or 'standing', got ['fallen']"),
    ("state-object.json", {"sites": [site(columns=[column(state={"a": 1})])]},
     "got {'a': 1}"),
    ("azimuth-string.json", {"sites": [site(columns=[column(downfall_azimuth_deg="240")])]},
     "downfall_azimuth_deg must be a finite number, got '240'"),
    ("azimuth-bool.json", {"sites": [site(columns=[column(downfall_azimuth_deg=False)])]},
     "downfall_azimuth_deg must be a finite number, got False"),
    ("sigma-list.json", {"sites": [site(columns=[column(uncertainty_deg=[10])])]},
     "uncertainty_deg must be a finite number, got [10]"),
    ("key-with-newline.json", {"sites": [site(**{"a\nb": 1})]}, "unknown key(s) 'a\\nb'"),
    ("column-key-with-newline.json", {"sites": [site(columns=[column(**{"x\ry": 1})])]},
     "unknown key(s) 'x\\ry'"),
    ("too-many-sites.json", {"sites": [site(name=f"s{k}", east_km=k)
                                       for k in range(MAX_SITES + 1)]},
     f"{MAX_SITES + 1} sites, at most {MAX_SITES}"),
    ("too-many-columns.json", {"sites": [site(columns=[column()] * 1001)]},
     "1001 columns, at most 1000"),
]


MALFORMED_FILES = ([(load_column, *case) for case in COLUMN_FILES]
                   + [(load_obs, *case) for case in OBSERVATION_FILES])


@pytest.mark.parametrize("load, name, content, words", MALFORMED_FILES,
                         ids=[f"{c[0].__name__}-{c[1]}" for c in MALFORMED_FILES])
def test_malformed_files_are_one_line_errors(tmp_path, load, name, content, words):
    message = load(write(tmp_path / name, content))
    assert message != "ok" and words in message, message


def test_observations_beyond_any_float_are_one_line_errors():
    for bad in (site(east_km=10 ** 400), site(north_km=-10 ** 400),
                site(columns=[column(downfall_azimuth_deg=10 ** 400)]),
                site(columns=[column(uncertainty_deg=10 ** 400)]),
                {"name": "A", "latitude": 10 ** 400, "longitude": 0, "columns": [column()]},
                {**site(), 1: 2}, site(columns=[{**column(), None: 2}])):
        with pytest.raises(InputError) as info:
            parse_observations({"sites": [bad]}, "obs.json")
        message = str(info.value)
        assert message.startswith("obs.json: ") and message.isprintable(), message


def test_observations_with_a_bom_are_read(tmp_path):
    path = write(tmp_path / "bom.json", b"\xef\xbb\xbf" + json.dumps(OBSERVATIONS[0]).encode())
    assert load_obs(path) == "ok"


# ---------------------------------------------------------------- fuzzing
SCALARS = (st.none() | st.booleans() | st.integers()
           | st.integers(min_value=-10 ** 400, max_value=10 ** 400)
           | st.floats(allow_nan=True, allow_infinity=True)
           | st.sampled_from([0, -1, 1e-9, 0.5, 1.0, 2700, 360, 1e308, -0.0, 10 ** 309,
                              "frustum", "box", "wedge", "edge", "fallen", "standing",
                              "drums", "monolithic", "doric-peristyle", "", " ", "\n"])
           | st.text(max_size=20))
JSON_VALUES = st.recursive(
    SCALARS, lambda inner: st.lists(inner, max_size=5)
    | st.dictionaries(st.text(max_size=12), inner, max_size=5), max_leaves=25)
# YAML can also give keys that are not strings
YAML_KEYS = st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=12)
YAML_VALUES = st.recursive(
    SCALARS, lambda inner: st.lists(inner, max_size=5)
    | st.dictionaries(YAML_KEYS, inner, max_size=5), max_leaves=25)
YAML_TOKENS = st.lists(st.sampled_from([
    "!!python/object/apply:os.system ['true']", "!!python/name:os.system", "!!int", "!!float",
    "!!bool", "!!timestamp", "!!binary", "!!set", "!!omap", "!!pairs", "!!str", "!!map",
    "!!seq", "!<tag:yaml.org,2002:int>", "!local", "&a ", "*a", "&b ", "*b", "<<: ", "? ",
    ": ", "- ", "[", "]", "{", "}", ", ", "\n", "  ", "\t", "name", "density", "blocks",
    "shape", "height", "frustum", "2020-13-45", "2001-12-14t21:59:43.10-05:00", ".nan",
    ".inf", "1:2:3", "0x1F", "0o17", "0b101", "1_000", "~", "'", '"', "|", ">", "#",
    "%YAML 1.1\n", "%TAG ! tag:x,2000:\n", "---\n", "...\n", "9" * 120, "\\", "\x00",
    "\ufeff", "\x85", "é"]), max_size=40).map("".join)


def structured(documents, values, keys=()):
    """A shipped document with one item (at any depth) replaced by a value, deleted, or
    joined by a key (one of ``keys`` or any text)."""
    @st.composite
    def build(draw):
        doc = draw(st.sampled_from(documents))
        paths = list(paths_of(doc))
        path = draw(st.sampled_from(paths))
        what = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        if what == "delete":
            return mutated(doc, path, DELETE)
        if what == "add":
            parent = path[:-1]
            target = doc
            for key in parent:
                target = target[key]
            if isinstance(target, dict):
                key = draw(st.sampled_from(sorted(keys)) | st.text(max_size=12)
                           if keys else st.text(max_size=12))
                return mutated(doc, parent + (key,), draw(values))
        return mutated(doc, path, draw(values))
    return build()


def spliced(data, text, pieces):
    """``text`` (bytes) with up to 8 bytes from a drawn place replaced by one of ``pieces``."""
    start = data.draw(st.integers(0, len(text)))
    stop = data.draw(st.integers(start, min(len(text), start + 8)))
    return text[:start] + data.draw(pieces) + text[stop:]


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@FUZZ
@given(value=JSON_VALUES)
def test_fuzz_column_json_values(fuzz_dir, value):
    load_column(write(fuzz_dir / "fuzzed.json", value))


@FUZZ
@given(value=YAML_VALUES)
def test_fuzz_column_yaml_values(fuzz_dir, value):
    load_column(write(fuzz_dir / "fuzzed.yaml", value))


@FUZZ
@given(content=st.binary(max_size=200), suffix=st.sampled_from([".json", ".yaml", ".yml"]))
def test_fuzz_column_bytes(fuzz_dir, content, suffix):
    load_column(write(fuzz_dir / ("fuzzed" + suffix), content))


@FUZZ
@given(content=YAML_TOKENS | st.text(max_size=200))
def test_fuzz_column_yaml_text(fuzz_dir, content):
    load_column(write(fuzz_dir / "fuzzed.yaml", content))


# plausible numbers and offsets too, so that changed files reach the statics
COLUMN_VALUES = (JSON_VALUES | st.floats(-5.0, 45.0) | st.integers(-5, 400)
                 | st.lists(st.floats(-2.5, 2.5), min_size=2, max_size=2)
                 | st.sampled_from([True, False, "edge", "wedge", "box", "frustum"]))
COLUMN_KEYS = TOP_KEYS | OPTIONAL_BLOCK_KEYS | set().union(*BLOCK_KEYS.values())


@FUZZ
@given(doc=structured(list(SHIPPED.values()), COLUMN_VALUES, COLUMN_KEYS),
       suffix=st.sampled_from([".json", ".yaml"]))
def test_fuzz_shipped_columns_with_one_field_changed(fuzz_dir, doc, suffix):
    load_column(write(fuzz_dir / ("mutated" + suffix), doc))


@FUZZ
@given(doc=structured(list(SHIPPED.values()), YAML_VALUES | COLUMN_VALUES, COLUMN_KEYS))
def test_fuzz_shipped_columns_with_one_yaml_field_changed(fuzz_dir, doc):
    load_column(write(fuzz_dir / "mutated.yaml", doc))


@FUZZ
@given(data=st.data(), name=st.sampled_from(sorted(SHIPPED)),
       suffix=st.sampled_from([".json", ".yaml"]))
def test_fuzz_shipped_column_text_with_a_splice(fuzz_dir, data, name, suffix):
    """The text of a shipped file (as JSON or YAML) with a few bytes replaced."""
    doc = SHIPPED[name]
    text = (json.dumps(doc, indent=1) if suffix == ".json" else yaml.safe_dump(doc)).encode()
    load_column(write(fuzz_dir / ("spliced" + suffix),
                      spliced(data, text, st.binary(max_size=8) | YAML_TOKENS.map(str.encode))))


@FUZZ
@given(value=JSON_VALUES)
def test_fuzz_observation_values(fuzz_dir, value):
    load_obs(write(fuzz_dir / "fuzzed.json", value))


@FUZZ
@given(content=st.binary(max_size=200) | st.text(max_size=200).map(str.encode))
def test_fuzz_observation_bytes(fuzz_dir, content):
    load_obs(write(fuzz_dir / "fuzzed.json", content))


@FUZZ
@given(doc=structured(OBSERVATIONS, JSON_VALUES | st.floats(-400.0, 400.0)
                      | st.sampled_from(["ionic.json", "a/b.yaml", "doric-peristyle"]),
                      SITE_KEYS | COLUMN_KEYS_OBS))
def test_fuzz_observations_with_one_field_changed(fuzz_dir, doc):
    load_obs(write(fuzz_dir / "mutated.json", doc))


@FUZZ
@given(data=st.data(), doc=st.sampled_from(OBSERVATIONS))
def test_fuzz_observation_text_with_a_splice(fuzz_dir, data, doc):
    text = json.dumps(doc, indent=1).encode()
    load_obs(write(fuzz_dir / "spliced.json", spliced(data, text, st.binary(max_size=8))))
