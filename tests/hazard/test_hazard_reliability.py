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
