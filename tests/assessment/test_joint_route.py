"""survival --joint-hazard (OpenQuake's mean rate density of PGA and PGV at a site): a
fragility over PGA alone gives the rate the same calculation's PGA curve gives; a set
overturns with 1 - prod(1 - P_i) per event; bad input is one line and nothing written."""
import json
import math

import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main
from pipeline.hazard.joint_hazard import load_joint_hazard
from pipeline.hazard.joint_survival import joint_overturning_rate
from pipeline.hazard.fragility import Logistic

CASE = "records/hazard/openquake_postproc_case_mrd"
MRD = f"{CASE}/mrd_pga_pgv.hdf5"


def _run(tmp_path, capsys, *argv, out="out"):
    code = main(["survival", *argv, "--out", str(tmp_path / out)])
    err = capsys.readouterr().err.strip().splitlines()
    if code != 0:
        return code, err[-1]
    return code, json.loads((tmp_path / out / "survival.json").read_text())


def test_a_pga_fragility_under_the_joint_hazard_is_the_pga_curve_s(tmp_path, capsys):
    """Over PGV the mrd gives back the PGA curve of its calculation (the engine's mean
    curve, exported as CSV): a fragility over PGA alone meets the same rate to the
    integration error of the cells (1 % here)."""
    fragility = ("--median-g", "0.05", "--beta", "0.5", "--age-ka", "15", "--draws", "0")
    _, joint = _run(tmp_path, capsys, "--joint-hazard", MRD, *fragility, out="joint")
    _, curve = _run(tmp_path, capsys, "--hazard", f"{CASE}/hazard_curve-mean-PGA_6.csv",
                    *fragility, out="curve")
    assert joint["hazard_route"]["route"] == "joint"
    assert curve["hazard_route"]["route"] == "curve"
    assert joint["annual_overturning_rate_per_yr"] == pytest.approx(
        curve["annual_overturning_rate_per_yr"], rel=0.02)
    rate = joint["annual_overturning_rate_per_yr"]
    assert joint["survival_probability"] == pytest.approx(math.exp(-rate * 15e3))


def test_a_set_under_the_joint_hazard_overturns_with_any_of_it(tmp_path, capsys):
    """Two surfaces at the site: the set's rate is that of 1 - (1 - P_1)(1 - P_2) in each
    event, between the larger single rate and their sum."""
    first, second = "-1,3,1.5", "0,2.5,1"
    _, result = _run(tmp_path, capsys, "--joint-hazard", MRD, f"--logistic={first}",
                     f"--logistic={second}", "--age-min-ka", "10", "--draws", "0")
    joint = load_joint_hazard(MRD).site(0)
    surfaces = [Logistic(tuple(float(v) for v in s.split(","))) for s in (first, second)]

    def any_overturns(a, r):
        return 1 - (1 - surfaces[0].probability(a, r)) * (1 - surfaces[1].probability(a, r))
    expected = joint_overturning_rate(joint.pga_levels_m_s2, joint.pgv_levels_m_s,
                                      joint.cell_rates_per_yr[0], any_overturns).rate_per_yr
    singles = [s["annual_overturning_rate_per_yr"] for s in result["specimens"]]
    assert result["annual_overturning_rate_per_yr"] == pytest.approx(expected, rel=1e-12)
    assert max(singles) <= expected <= sum(singles)
    assert result["age"]["kind"] == "lower_bound"


@pytest.mark.parametrize("argv, words", [
    (("--joint-hazard", f"{CASE}/mrd_pga_sa0.05.hdf5"), "the mrd is of PGA and SA(0.05)"),
    (("--joint-hazard", MRD, "--site", "2"), "site 2 beyond the file's 1 site(s)"),
    (("--joint-hazard", MRD, "--magnitude", "6", "--distance-km", "10"),
     "--magnitude does not apply with --joint-hazard"),
    (("--joint-hazard", MRD, "--hazard", f"{CASE}/hazard_curve-mean-PGA_6.csv"),
     "give --hazard or --joint-hazard, not both"),
])
def test_bad_joint_input_is_one_line_and_nothing_written(tmp_path, capsys, argv, words):
    code, said = _run(tmp_path, capsys, *argv, "--median-g", "0.05", "--beta", "0.5",
                      "--age-ka", "15")
    assert code == 2 and words in said and said.startswith("error: ")
    assert not (tmp_path / "out").exists()


def _one_bin(tmp_path, curve_csv, magnitude, distance_km):
    """A Mag_Dist export of one bin (magnitude, distance) holding the whole rate of the
    curve at three of its levels (its probabilities of exceedance in 1 year)."""
    lines = [line for line in curve_csv.read_text().splitlines() if line.strip()]
    names, values = lines[1].split(","), lines[2].split(",")
    picks = [k for k, n in enumerate(names) if n.startswith("poe-")][10:25:7]
    rows = [f"PGA,{names[k][4:]},{float(values[k]):.6E},{magnitude:.5E},{distance_km:.5E},"
            f"{float(values[k]):.6E}" for k in picks]
    path = tmp_path / "Mag_Dist-mean-0_1.csv"
    path.write_text(
        '#,,,,,"generated_by=\'OpenQuake engine 3.26.2\', investigation_time=1.0, '
        f"mag_bin_edges=[{magnitude - 0.25}, {magnitude + 0.25}], dist_bin_edges=[0.0, "
        f"{2 * distance_km}], lon=11.202, lat=42.424\"\nimt,iml,poe,mag,dist,mean\n"
        + "\n".join(rows) + "\n")
    return path


def test_one_disaggregation_bin_is_todays_one_scenario(tmp_path, capsys):
    """--disaggregation of one bin at (M, R): at every PGA level the mixture is the one
    model at M, R, so the survival is --magnitude M --distance-km R's."""
    curve = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / \
        "hazard_curve-mean-PGA_6.csv"
    base = ("--hazard", str(curve), "--logistic=-1,3,1.5", "--age-ka", "15", "--draws", "0")
    _, mixed = _run(tmp_path, capsys, *base, "--disaggregation",
                    str(_one_bin(tmp_path, curve, 6.25, 10.0)), out="mixed")
    _, today = _run(tmp_path, capsys, *base, "--magnitude", "6.25", "--distance-km", "10",
                    out="today")
    assert mixed["annual_overturning_rate_per_yr"] == pytest.approx(
        today["annual_overturning_rate_per_yr"], rel=1e-9)
    assert mixed["pgv_pga"]["source"] == "magnitude-distance disaggregation"
    assert "disaggregation" in mixed["hazard_route"]["what"]
    assert "one scenario" in today["hazard_route"]["what"]


def test_a_disaggregation_that_does_not_add_up_is_one_line(tmp_path, capsys):
    """Bins whose rates do not sum to the curve's rate at their level: refused."""
    curve = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / \
        "hazard_curve-mean-PGA_6.csv"
    other = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / \
        "hazard_curve-rlz-000-PGA_6.csv"
    code, said = _run(tmp_path, capsys, "--hazard", str(other), "--logistic=-1,3,1.5",
                      "--age-ka", "15", "--disaggregation",
                      str(_one_bin(tmp_path, curve, 6.25, 10.0)))
    assert code == 2 and "add up to" in said and said.startswith("error: ")
    assert not (tmp_path / "out").exists()
