"""The REPORT section of the three routes to the joint hazard: it says when nothing has run,
quotes each route's survival.json and constrain.json as written, each branch's PGV/PGA
its own realisation's or the mean's as the file says (with specimens at several sites, each
site's own)."""
import json

from pipeline.cli import main
from pipeline.report import hazard_routes_section
from pipeline.report.hazard_routes import HAZARD_ROUTES
from tests.assessment.test_constrain_joint_sites import _tree, _two_site_mrd

CASE = "records/hazard/openquake_postproc_case_mrd"
CURVE = f"{CASE}/hazard_curve-mean-PGA_6.csv"
ROCK = ["--logistic=-1,3,1.5", "--age-ka", "15", "--age-sd-ka", "3"]
SCENARIO = ["--magnitude", "5.75", "--distance-km", "110", "--vs30", "1000"]


def test_nothing_run_says_so(tmp_path):
    text = hazard_routes_section(tmp_path)
    assert text.startswith("## Three routes to the joint hazard of PGA and PGV at one site\n")
    assert "Not run yet (`make run-all`)" in text


def test_each_route_is_quoted_from_its_files(tmp_path):
    root = tmp_path / HAZARD_ROUTES
    runs = {"joint-survival": ["survival", "--joint-hazard", f"{CASE}/mrd_pga_pgv.hdf5"],
            "disaggregation-survival": [
                "survival", "--hazard", CURVE, "--vs30", "1000", "--disaggregation",
                f"{CASE}/disaggregation/Mag_Dist-mean-0_7.csv"],
            "scenario-survival": ["survival", "--hazard", CURVE, *SCENARIO],
            "joint-constrain": ["constrain", "--logic-tree", CASE, "--joint-hazard",
                                f"{CASE}/mrd_pga_pgv.hdf5"],
            "disaggregation-constrain": [
                "constrain", "--logic-tree", CASE, "--vs30", "1000", "--disaggregation",
                f"{CASE}/disaggregation/Mag_Dist-0_7.csv"],
            "scenario-constrain": ["constrain", "--logic-tree", CASE, *SCENARIO]}
    for name, argv in runs.items():
        assert main([*argv, *ROCK, "--out", str(root / name)]) == 0
    text = hazard_routes_section(tmp_path)
    rates = {name: json.loads((root / f"{name}-survival" / "survival.json").read_text())
             ["annual_overturning_rate_per_yr"]
             for name in ("joint", "disaggregation", "scenario")}
    assert len({f"{r:.3g}" for r in rates.values()}) == 3      # three routes, three rates
    for rate in rates.values():
        assert f" {rate:.3g} " in text
    assert "14 magnitude-distance bins" in text        # the case's bins with events
    assert "M 5.75, 110 km, correlation 0.654" in text
    for name in ("joint", "disaggregation", "scenario"):
        c = json.loads((root / f"{name}-constrain" / "constrain.json").read_text())
        for branch in c["branches"]:
            assert f" {1 - branch['survival_probability']:.3g} " in text
    assert "rate density, the mean's for every branch" in text
    assert text.count("magnitude-distance bins, its own realisation's") == 2
    assert "not run" not in text


def test_specimens_at_several_sites_are_said_to_take_each_sites_density(tmp_path):
    mrd, tree = _two_site_mrd(tmp_path / "mrd.hdf5"), _tree(tmp_path / "tree.csv", 2)
    assert main(["constrain", "--logic-tree", str(tree), "--joint-hazard", str(mrd),
                 "--logistic=-2,3,1", "--logistic=-1,3,1", "--age-ka", "10",
                 "--specimen-site", "0", "--specimen-site", "1", "--draws", "0", "--out",
                 str(tmp_path / HAZARD_ROUTES / "joint-constrain")]) == 0
    assert main(["survival", "--joint-hazard", f"{CASE}/mrd_pga_pgv.hdf5", *ROCK, "--draws",
                 "0", "--out", str(tmp_path / HAZARD_ROUTES / "joint-survival")]) == 0
    text = hazard_routes_section(tmp_path)
    assert text.count("each site's own rate density, the mean's for every branch") == 2
