"""constrain and survival as a careless user drives them: a second run into the same
folder leaves no result of the first beside its own, one specimen given twice is
refused, absurd values in a hazard or fragility file are refused by its loader (as the
command line refuses them) before anything is written, and each message names what is
wrong."""
import json

import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main

CASE_11 = RECORDS_DIR / "hazard" / "openquake_logictree_case_11"
CASE_14 = RECORDS_DIR / "hazard" / "oq_classical_case_14_hazard_curve-rlz-000_PGA.csv"
DOC = ["--median-g", "0.3", "--beta", "0.4", "--age-ka", "2", "--age-sd-ka", "0.3"]


def _names(directory):
    return sorted(p.name for p in directory.iterdir())


# ---------------------------------------------------------------- stale results
def test_constrain_leaves_no_curve_of_an_earlier_run(tmp_path):
    """Bayes writes constrained curves; elimination of every branch writes none: the
    first run's constrained_curves.csv is gone, the folder holds what constrain.json
    lists (and a file of the user's stays)."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["constrain", "--logic-tree", str(CASE_11), *DOC, "--draws", "0",
                 "--out", str(out)]) == 0
    assert (out / "constrained_curves.csv").exists()
    assert main(["constrain", "--logic-tree", str(CASE_11), *DOC, "--draws", "0",
                 "--rule", "eliminate", "--floor", "0.999", "--out", str(out)]) == 0
    summary = json.loads((out / "constrain.json").read_text())
    assert summary["posterior"] is None
    assert _names(out) == sorted([*summary["files"], "notes.txt"])
    assert not (out / "constrained_curves.csv").exists()


def test_survival_leaves_no_site_motion_of_an_earlier_run(tmp_path):
    observations = tmp_path / "obs.json"
    observations.write_text(json.dumps({"sites": [{"name": "A", "east_km": 0, "north_km": 0,
                                                   "columns": [{"column": "monolithic",
                                                                "state": "standing"}]}]}))
    out = tmp_path / "out"
    assert main(["survival", "--observations", str(observations), "--median-g", "0.3",
                 "--beta", "0.4", "--out", str(out)]) == 0
    assert _names(out) == ["site_motion.json"]
    assert main(["survival", "--hazard", str(CASE_14), "--site", "0", "--median-g", "0.3",
                 "--beta", "0.4", "--age-ka", "2", "--draws", "0", "--out", str(out)]) == 0
    assert _names(out) == ["survival.json", "survival.png"]
    assert main(["survival", "--observations", str(observations), "--median-g", "0.3",
                 "--beta", "0.4", "--out", str(out)]) == 0
    assert _names(out) == ["site_motion.json"]


# ---------------------------------------------------------------- one rock twice
def _fragility(path):
    from tests.hazard.test_reader_robustness import COLUMN
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(COLUMN))
    return path


@pytest.mark.parametrize("as_directory", [False, True])
def test_constrain_refuses_one_fragility_given_twice(tmp_path, capsys, as_directory):
    fragility = _fragility(tmp_path / "campaign" / "fragility.json")
    other = fragility.parent if as_directory else fragility
    out = tmp_path / "out"
    assert main(["constrain", "--logic-tree", str(CASE_11), "--fragility", str(fragility),
                 "--fragility", str(other), "--fragility-form", "pga", "--age-ka", "2",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "the same specimen twice" in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_survival_refuses_one_hazard_curve_given_twice(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(CASE_14), "--hazard", str(CASE_14), "--site",
                 "0", "--median-g", "0.3", "--beta", "0.4", "--age-ka", "2",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "the same curve twice" in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_campaign_columns_refuses_one_description_given_twice(tmp_path):
    from pipeline.campaign.definitions import columns_specs
    from pipeline.files import InputError
    from pipeline.scenario.geometry import EXAMPLES_DIR
    with pytest.raises(InputError, match="the same specimen twice"):
        columns_specs([], tmp_path, column_files=["roman-granite",
                                                  str(EXAMPLES_DIR / "roman-granite.json")])
