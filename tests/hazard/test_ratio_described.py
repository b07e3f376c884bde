"""PGV/PGA as the results describe it, one record per route: each route's survival.json or
constrain.json read back is written back byte for byte and holds that route's record; a
route part the records do not describe is refused in one line naming the file; the
REPORT's words for a route come from its record."""
import json
import shutil

import h5py
import numpy as np
import pytest

from pipeline.cli import main
from pipeline.files import InputError
from pipeline.hazard.ratio_described import (DensityRatio, GroupsRatio, MixtureRatio,
                                             ScenarioRatio, SitesRatio, StatedRatio,
                                             read_ratio)
from pipeline.hazard.results import read_constrain_result, read_survival_result
from pipeline.report import hazard_routes_section
from pipeline.report.hazard_routes import HAZARD_ROUTES
from tests.assessment.test_constrain_joint_sites import _tree, _two_site_mrd
from tests.assessment.test_constrain_mrd_per_branch import _file, _mrds

CASE = "records/hazard/openquake_postproc_case_mrd"
CURVE = ["--hazard", f"{CASE}/hazard_curve-mean-PGA_6.csv"]
TREE = ["--logic-tree", CASE]
MRD = ["--joint-hazard", f"{CASE}/mrd_pga_pgv.hdf5"]
BINS = ["--vs30", "1000", "--disaggregation"]
ROCK = ["--logistic=-1,3,1.5", "--age-ka", "15", "--age-sd-ka", "3", "--draws", "0"]
STATED = ["--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.5"]
SCENARIO = ["--magnitude", "5.75", "--distance-km", "110", "--vs30", "1000"]
ROUTES = {   # name: (command and route, the record of its pgv_pga)
    "stated": (["survival", *CURVE, *STATED], StatedRatio),
    "scenario": (["survival", *CURVE, *SCENARIO], ScenarioRatio),
    "mixture": (["survival", *CURVE, *BINS, f"{CASE}/disaggregation/Mag_Dist-mean-0_7.csv"],
                MixtureRatio),
    "joint": (["survival", *MRD], type(None)),
    "tree-stated": (["constrain", *TREE, *STATED], StatedRatio),
    "tree-scenario": (["constrain", *TREE, *SCENARIO], ScenarioRatio),
    "tree-mixtures": (["constrain", *TREE, *BINS, f"{CASE}/disaggregation/Mag_Dist-0_7.csv"],
                      GroupsRatio),
    "tree-one-column": (["constrain", *TREE, *BINS, f"{CASE}/disaggregation/Mag_Dist-0_7.csv",
                         "--disaggregation-column", "rlz1"], MixtureRatio),
    "tree-density": (["constrain", *TREE, *MRD], DensityRatio),
}


def _run(argv, out):
    assert main([*argv, *ROCK, "--out", str(out)]) == 0
    name = "survival.json" if argv[0] == "survival" else "constrain.json"
    read = read_survival_result if argv[0] == "survival" else read_constrain_result
    return out / name, read


@pytest.fixture(scope="module")
def routed(tmp_path_factory):
    """Each route's result file, run once for the module (the tests only read it)."""
    done = {}

    def run(name):
        if name not in done:
            done[name] = _run(ROUTES[name][0], tmp_path_factory.mktemp(name))
        return done[name]
    return run


@pytest.mark.parametrize("name", ROUTES)
def test_each_route_read_back_is_written_back_byte_for_byte(routed, name):
    kind = ROUTES[name][1]
    path, read = routed(name)
    result = read(path)
    assert result.text() == path.read_text()
    assert type(result.pgv_pga) is kind
    if result.pgv_pga is not None:
        said = json.loads(path.read_text())["pgv_pga"]
        assert result.pgv_pga.as_json() == said
        assert read_ratio(said) == result.pgv_pga


def test_groups_of_densities_and_sites_read_back_byte_for_byte(tmp_path):
    mrd, other = _mrds()
    per_branch = _file(tmp_path, "both.hdf5", realisations=np.stack([mrd, other], -1))
    path, _ = _run(["constrain", *TREE, "--joint-hazard", str(per_branch)], tmp_path / "g")
    result = read_constrain_result(path)
    assert result.text() == path.read_text()
    assert isinstance(result.pgv_pga, GroupsRatio)
    assert [type(g) for g in result.pgv_pga.groups] == [DensityRatio, DensityRatio]
    assert [g.branch_indices for g in result.pgv_pga.groups] == [[0], [1]]
    two, tree = _two_site_mrd(tmp_path / "two.hdf5"), _tree(tmp_path / "tree.csv", 2)
    assert main(["constrain", "--logic-tree", str(tree), "--joint-hazard", str(two),
                 "--logistic=-2,3,1", "--logistic=-1,3,1", "--age-ka", "10",
                 "--specimen-site", "0", "--specimen-site", "1", "--draws", "0",
                 "--out", str(tmp_path / "s")]) == 0
    result = read_constrain_result(tmp_path / "s" / "constrain.json")
    assert result.text() == (tmp_path / "s" / "constrain.json").read_text()
    assert isinstance(result.pgv_pga, SitesRatio) and result.pgv_pga.site_indices == [0, 1]
    assert [s.pgv_pga.site_index for s in result.sites] == [0, 1]


@pytest.mark.parametrize("route, change, said", [
    ("scenario", lambda r: r.pop("median_pgv_m_s"), "pgv_pga: no median_pgv_m_s"),
    ("scenario", lambda r: r.update(magnitude="6"), "magnitude is not float"),
    ("scenario", lambda r: r.update(pga_pgv_correlation=1.5), "not in [-1, 1]"),
    ("scenario", lambda r: r.update(source="somewhere"), "source 'somewhere'"),
    ("stated", lambda r: r.update(median_s=0), "median_s 0 is not above 0"),
    ("stated", lambda r: r.pop("median_s"), "no route of PGV/PGA"),
    ("mixture", lambda r: r.update(bins_used=3), "bins_used 3: not as many"),
    ("mixture", lambda r: r.update(per_branch=True), "per_branch and branches go together"),
    ("tree-mixtures", lambda r: r["groups"][0].pop("branch_indices"),
     "with its branch_indices"),
    ("tree-mixtures", lambda r: r.update(per_branch="yes"), "per_branch is not bool"),
    ("tree-density", lambda r: r.update(pga_cells_with_events=0), "< 1"),
    ("tree-density", lambda r: r.update(wobble=1), "unknown keys wobble"),
])
def test_a_malformed_route_is_refused_in_one_line(tmp_path, routed, route, change, said):
    path, read = routed(route)
    data = json.loads(path.read_text())
    change(data["pgv_pga"])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError) as refused:
        read(bad)
    message = str(refused.value)
    assert said in message and "\n" not in message and message.startswith(f"{bad}: ")


@pytest.mark.parametrize("route, where, value, said", [
    ("joint", "pgv_pga", [1], "not a JSON object"),
    ("scenario", "pgv_pga", None, None),                          # null: no PGV/PGA taken
    ("stated", "pgv_pga", "density", "not a JSON object"),
])
def test_the_route_part_is_an_object_or_null(tmp_path, routed, route, where, value, said):
    path, read = routed(route)
    data = {**json.loads(path.read_text()), where: value}
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    if said is None:
        assert read(bad).pgv_pga is None
        return
    with pytest.raises(InputError, match=said):
        read(bad)


def test_a_route_of_another_result_is_refused(tmp_path, routed):
    """survival.json holds no rate density's PGV/PGA (its joint route takes each event's
    own), a site of constrain.json no stated one."""
    path, _ = routed("tree-density")
    density = json.loads(path.read_text())["pgv_pga"]
    survival, _ = routed("stated")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({**json.loads(survival.read_text()), "pgv_pga": density}))
    with pytest.raises(InputError, match="pgv_pga is not StatedRatio or ScenarioRatio or "
                                         "MixtureRatio or null"):
        read_survival_result(bad)
    data = json.loads(path.read_text())
    data["sites"][0]["pgv_pga"] = json.loads(survival.read_text())["pgv_pga"]
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError, match="pgv_pga is not DensityRatio or GroupsRatio"):
        read_constrain_result(bad)


def test_the_reports_words_are_the_records(tmp_path):
    """The scenario's magnitude, distance and correlation as the record states them (here
    edited in the file and read back), and a tree of one branch that takes its own
    realisation's rate density said so."""
    root = tmp_path / HAZARD_ROUTES
    path, _ = _run(ROUTES["scenario"][0], root / "scenario-survival")
    data = json.loads(path.read_text())
    data["pgv_pga"].update(magnitude=6.25, distance_jb_km=42.5, pga_pgv_correlation=0.5)
    path.write_text(json.dumps(data))
    rows = ["branch,weight,pga_g,annual_rate_per_yr"] + [
        f"0,1,{x:.6g},{2e-3 * (x / 0.1) ** -2.2:.6g}" for x in np.geomspace(0.01, 2.0, 15)]
    (tmp_path / "tree.csv").write_text("\n".join(rows) + "\n")
    own = tmp_path / "own.hdf5"
    shutil.copyfile(f"{CASE}/mrd_pga_pgv.hdf5", own)
    with h5py.File(own, "r+") as f:
        f["mrd-rlzs"] = f["mrd"][()][..., None]          # realisation 0: branch "0"
    _run(["constrain", "--logic-tree", str(tmp_path / "tree.csv"), "--joint-hazard",
          str(own)], root / "joint-constrain")
    text = hazard_routes_section(tmp_path)
    assert "M 6.25, 42.5 km, correlation 0.5" in text
    assert "rate density, its own realisation's" in text
