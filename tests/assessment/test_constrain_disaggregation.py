"""constrain --disaggregation (PGV/PGA over the magnitude-distance bins): each branch its
own realisation's column where the file holds every branch's, against survival's route
(b) on that realisation's curve and column; the mean's for every branch otherwise, said
in constrain.json; bad input refused in one line with nothing written."""
import json
import math

import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main
from tests.refusal import refused

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
PER_RLZ = CASE / "disaggregation" / "Mag_Dist-0_7.csv"
MEAN = CASE / "disaggregation" / "Mag_Dist-mean-0_7.csv"
AGE_KA = 10.0
ROCK = ["--logistic=4,3,1", "--age-ka", f"{AGE_KA:g}", "--draws", "0", "--vs30", "1000"]


def _constrain(tmp_path, name, *extra):
    out = tmp_path / name
    assert main(["constrain", "--logic-tree", str(CASE), *ROCK, *map(str, extra),
                 "--out", str(out)]) == 0
    return json.loads((out / "constrain.json").read_text())


def _rate(p_s):
    """The annual overturning rate (1/yr) of a known age's survival P_s = exp(-rate t)."""
    return -math.log(p_s) / (AGE_KA * 1000.0)


def test_each_branch_its_own_column_as_survival_gives_it(tmp_path):
    c = _constrain(tmp_path, "own", "--disaggregation", PER_RLZ)
    assert c["pgv_pga"]["per_branch"] is True and "rlzK" in c["pgv_pga"]["branches"]
    for k, branch in enumerate(c["branches"]):
        out = tmp_path / f"survival{k}"
        assert main(["survival", "--hazard", str(CASE / f"hazard_curve-rlz-00{k}-PGA_6.csv"),
                     "--disaggregation", str(PER_RLZ), "--disaggregation-column", f"rlz{k}",
                     *ROCK, "--out", str(out)]) == 0
        s = json.loads((out / "survival.json").read_text())
        assert _rate(branch["survival_probability"]) == pytest.approx(
            s["annual_overturning_rate_per_yr"], rel=1e-3)    # the tree's common levels


def test_a_column_named_for_every_branch_and_the_mean_file(tmp_path):
    own = _constrain(tmp_path, "own", "--disaggregation", PER_RLZ)["branches"]
    named = _constrain(tmp_path, "named", "--disaggregation", PER_RLZ,
                       "--disaggregation-column", "rlz1")
    assert named["pgv_pga"]["per_branch"] is False
    assert "rlz1 for every branch" in named["pgv_pga"]["branches"]
    assert named["branches"][1]["survival_probability"] == own[1]["survival_probability"]
    assert named["branches"][0]["survival_probability"] != own[0]["survival_probability"]
    mean = _constrain(tmp_path, "mean", "--disaggregation", MEAN)
    assert mean["pgv_pga"]["per_branch"] is False
    assert "the file holds mean, not a column rlzK" in mean["pgv_pga"]["branches"]


def _unbalanced(tmp_path):
    """The per-realisation file with realisation 1's bins at the top level doubled."""
    lines = PER_RLZ.read_text().splitlines()
    top = max(float(line.split(",")[1]) for line in lines[2:])
    out = []
    for line in lines:
        cells = line.split(",")
        if len(cells) == 7 and cells[0] == "PGA" and float(cells[1]) == top:
            cells[6] = f"{min(2 * float(cells[6]), 0.5):.5E}"
        out.append(",".join(cells))
    path = tmp_path / "Mag_Dist-unbalanced.csv"
    path.write_text("\n".join(out) + "\n")
    return path


@pytest.mark.parametrize("extra, words", [
    (["--disaggregation-column", "rlz0"], "applies with --disaggregation"),
    (["--disaggregation", PER_RLZ, "--magnitude", "6", "--distance-km", "20"], "one of them"),
    (["--disaggregation", PER_RLZ, "--joint-hazard", CASE / "mrd_pga_pgv.hdf5"],
     "one of them"),
    (["--disaggregation", PER_RLZ, "--disaggregation-column", "rlz7"], "no branch"),
    (["--disaggregation", PER_RLZ, "--disaggregation-column", "rlz1x"], "no branch"),
    (["--disaggregation", PER_RLZ, "--logistic=4,3,2", "--specimen-site", "0",
      "--specimen-site", "1"], "several sites"),
    (["--disaggregation", "UNBALANCED"], "add up"),
])
def test_bad_input_one_line_nothing_written(tmp_path, capsys, extra, words):
    extra = [_unbalanced(tmp_path) if e == "UNBALANCED" else e for e in extra]
    out = tmp_path / "out"
    refused(capsys, ["constrain", "--logic-tree", CASE, *ROCK, *extra, "--out", out],
            words, out)
