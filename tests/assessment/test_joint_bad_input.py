"""Bad input to the joint-hazard routes of survival and constrain: one line naming the
problem, a non-zero exit and nothing written (a disaggregation on levels outside its
curve; to constrain, an mrd of other intensity measures, a site beyond the files, an mrd
of another place than the curves, an age interval upside down)."""
import math

import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
MRD = str(CASE / "mrd_pga_pgv.hdf5")


def _refused(tmp_path, capsys, argv):
    out = tmp_path / "out"
    code = main([*argv, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and len(err) == 1 and err[0].startswith("error: ")
    assert not out.exists()
    return err[0]


def _curve_from(tmp_path, lowest_g):
    """The case's mean PGA curve as a plain table, its levels from ``lowest_g`` up."""
    lines = [line for line in (CASE / "hazard_curve-mean-PGA_6.csv").read_text().splitlines()
             if line.strip()]
    names, values = lines[1].split(","), lines[2].split(",")
    rows = [(float(n[4:]), -math.log1p(-float(v))) for n, v in zip(names, values)
            if n.startswith("poe-") and float(n[4:]) >= lowest_g and float(v) > 0]
    path = tmp_path / "curve.csv"
    path.write_text("pga_g,annual_rate_per_yr\n" + "".join(f"{a!r},{r!r}\n" for a, r in rows))
    return path


def test_a_disaggregation_on_levels_outside_its_curve_is_one_line(tmp_path, capsys):
    """The shipped disaggregation's first level (0.000184 g) lies below a curve from
    0.001 g: the levels do not match, refused before any work."""
    said = _refused(tmp_path, capsys, [
        "survival", "--hazard", str(_curve_from(tmp_path, 0.001)), "--disaggregation",
        str(CASE / "disaggregation" / "Mag_Dist-mean-0_7.csv"), "--logistic=-1,3,1.5",
        "--age-ka", "15"])
    assert "a level outside the curve's" in said


@pytest.mark.parametrize("extra, words", [
    (("--joint-hazard", str(CASE / "mrd_pga_sa0.05.hdf5")), "the mrd is of PGA and SA(0.05)"),
    (("--joint-hazard", MRD, "--site", "1"), "--site must be 0 to 0"),
    (("--joint-hazard", MRD, "--age-range-ka", "22", "13"), "--age-range-ka"),
])
def test_constrain_refuses_bad_joint_input_in_one_line(tmp_path, capsys, extra, words):
    age = () if "--age-range-ka" in extra else ("--age-ka", "10")
    said = _refused(tmp_path, capsys, ["constrain", "--logic-tree", str(CASE),
                                       "--logistic=-2,3,1", "--draws", "0", *age, *extra])
    assert words in said


def test_an_mrd_site_beyond_its_file_is_one_line(tmp_path, capsys):
    """A tree of two sites, the rate density of one: --site 1 is beyond the mrd."""
    rows = [line for line in _curve_from(tmp_path, 0.0001).read_text().splitlines()[1:]]
    tree = tmp_path / "tree.csv"
    tree.write_text("branch,weight,pga_g,annual_rate_per_yr,site\n" + "".join(
        f"a,1,{row},{site}\n" for site in (0, 1) for row in rows))
    said = _refused(tmp_path, capsys, ["constrain", "--logic-tree", str(tree), "--site", "1",
                                       "--joint-hazard", MRD, "--logistic=-2,3,1",
                                       "--draws", "0", "--age-ka", "10"])
    assert "site 1 beyond the file's 1 site(s)" in said


def test_a_rate_density_of_another_place_is_one_line(tmp_path, capsys):
    """OpenQuake's curves state their site (case 11 at (0, 0)), the rate density its own
    (the mrd case at (11.202, 42.424)): not one place, refused; the mrd case's own curves
    at the same place are taken."""
    said = _refused(tmp_path, capsys, [
        "constrain", "--logic-tree", str(RECORDS_DIR / "hazard" / "openquake_logictree_case_11"),
        "--joint-hazard", MRD, "--logistic=-2,3,1", "--draws", "0", "--age-ka", "10"])
    assert "lies at (11.202, 42.424), the logic tree's curves at (0, 0)" in said
    assert main(["constrain", "--logic-tree", str(CASE), "--joint-hazard", MRD,
                 "--logistic=-2,3,1", "--draws", "0", "--age-ka", "10", "--out",
                 str(tmp_path / "same")]) == 0


CASE_19 = RECORDS_DIR / "hazard" / "openquake_logictree_case_19"


@pytest.mark.parametrize("argv", [
    ["survival", "--hazard", str(CASE / "hazard_curve-mean-PGA_6.csv"), "--disaggregation",
     str(CASE_19 / "disaggregation" / "Mag_Dist-mean-0_16.csv")],
    ["constrain", "--logic-tree", str(CASE_19), "--disaggregation",
     str(CASE / "disaggregation" / "Mag_Dist-0_7.csv")],
])
def test_a_disaggregation_of_another_place_is_one_line(tmp_path, capsys, argv):
    """The mrd case's site (11.202, 42.424) and case 19's (16.2657, 39.3002), each stated
    by its curves and its disaggregation."""
    said = _refused(tmp_path, capsys, [*argv, "--logistic=-2,3,1", "--draws", "0",
                                       "--age-ka", "10"])
    assert "of another place" in said and "42.424" in said and "39.3002" in said
