"""survival.json and constrain.json as types: the file read back is written back byte for
byte, a route's absent fields stay absent, and a file the type does not describe is one
line naming it."""
import json

import pytest

from pipeline import cli
from pipeline.files import InputError
from pipeline.hazard.results import ABSENT, read_constrain_result, read_survival_result

HAZARD = "records/hazard/usgs_nshm2014r1_curves_-118_34_vs760.json"
TREE = "records/hazard/openquake_logictree_case_11"


def test_survival_json_read_back_is_written_back_byte_for_byte(tmp_path):
    out = tmp_path / "s"
    assert cli.main(["survival", "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3",
                     "--beta", "0.4", "--draws", "20", "--out", str(out)]) == 0
    path = out / "survival.json"
    result = read_survival_result(path)
    assert result.text() == path.read_text()
    assert result.site_set is ABSENT and result.given("hazard_curves") is None  # one curve
    assert result.survival_probability == json.loads(path.read_text())["survival_probability"]


def test_constrain_json_read_back_is_written_back_byte_for_byte(tmp_path):
    out = tmp_path / "c"
    assert cli.main(["constrain", "--logic-tree", TREE, "--median-g", "0.3", "--beta", "0.4",
                     "--age-ka", "2", "--age-sd-ka", "0.3", "--draws", "10",
                     "--out", str(out)]) == 0
    path = out / "constrain.json"
    result = read_constrain_result(path)
    assert result.text() == path.read_text()
    assert result.posterior_bayes is ABSENT          # the headline's rule is bayes
    assert result.branch_test.level == result.floor
    assert (out / "branch_test.csv").read_text() == result.branch_test.csv()


@pytest.mark.parametrize("change, said", [
    ({"unheard_of": 1}, "unknown keys unheard_of"),
    ({"survival_probability": 1.5}, "not in [0, 1]"),
    ({"warnings": None, "specimens": []}, "no specimens"),
])
def test_a_survival_json_the_type_does_not_describe_is_one_line(tmp_path, change, said):
    out = tmp_path / "s"
    assert cli.main(["survival", "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3",
                     "--beta", "0.4", "--draws", "0", "--out", str(out)]) == 0
    data = {**json.loads((out / "survival.json").read_text()), **change}
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError) as refused:
        read_survival_result(bad)
    assert said in str(refused.value) and "\n" not in str(refused.value)
    assert str(bad) in str(refused.value)


def test_a_missing_key_is_named(tmp_path):
    out = tmp_path / "s"
    assert cli.main(["survival", "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3",
                     "--beta", "0.4", "--draws", "0", "--out", str(out)]) == 0
    data = json.loads((out / "survival.json").read_text())
    del data["hazard"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError, match="no hazard"):
        read_survival_result(bad)


def _changed(data, path, value):
    """A copy of ``data`` with the key ``path`` (keys and list indices) set to ``value``
    (None: the key removed)."""
    data = json.loads(json.dumps(data))
    inner = data
    for key in path[:-1]:
        inner = inner[key]
    if value is None:
        del inner[path[-1]]
    else:
        inner[path[-1]] = value
    return data


def test_an_inner_record_the_type_does_not_describe_is_one_line_naming_it(tmp_path):
    """Each specimen, the route, the age and the hazard are types of their own: a value
    out of range, an unknown key or a key missing inside one is refused by name."""
    out = tmp_path / "s"
    assert cli.main(["survival", "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3",
                     "--beta", "0.4", "--draws", "0", "--out", str(out)]) == 0
    data = json.loads((out / "survival.json").read_text())
    for path, value, said in [
            (("specimens", 0, "survival_probability"), 1.5,
             "specimens: survival_probability 1.5 is not in [0, 1]"),
            (("specimens", 0, "unheard_of"), 1, "specimens: unknown keys unheard_of"),
            (("specimens", 0, "contribution_by_intensity", 0, "rate_per_yr"), -1.0,
             "contribution_by_intensity: rate_per_yr -1.0 < 0"),
            (("curve_ends", "share_at_last_level"), None, "curve_ends: no share_at_last_level"),
            (("age", "kind"), "interval", "an age of kind interval holds lo_yr, hi_yr"),
            (("hazard_route", "route"), "joint", "the hazard is not of the route joint"),
            (("hazard", "file"), 1, "the source's file is not a string"),
            (("hazard", "levels_g"), None, "hazard: no levels_g")]:
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(_changed(data, path, value)))
        with pytest.raises(InputError) as refused:
            read_survival_result(bad)
        assert said in str(refused.value) and "\n" not in str(refused.value), path
        assert str(bad) in str(refused.value)
