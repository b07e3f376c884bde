"""constrain --joint-hazard with specimens at several sites: each specimen takes PGV/PGA
from its own site's rate density, so the set's survival under a branch equals the
single-site runs (each at its site of the file) multiplied, and the file's top-level
pgv_pga says that each site takes its own; a site index beyond the file is refused in one
line with nothing written."""
import json

import h5py
import numpy as np

from pipeline import RECORDS_DIR
from pipeline.cli import main
from pipeline.hazard.ratio_described import SitesRatio
from pipeline.hazard.results import read_constrain_result
from tests.refusal import refused

SHIPPED = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / "mrd_pga_pgv.hdf5"
SHIFT = 4                      # PGV cells the second site's events are moved up by


def _two_site_mrd(path):
    """The shipped rate density at site 0 and, at a site 2 degrees east, the same with
    every event's PGV SHIFT cells higher (a larger PGV/PGA at each PGA)."""
    with h5py.File(SHIPPED, "r") as f:
        mrd = f["mrd"][()]
        oqparam = f["oqparam"][()]
        lon, lat = f["sitecol/lon"][()], f["sitecol/lat"][()]
    assert json.loads(oqparam)["postproc_args"]["imt2"] == "PGV"      # axis 0 is PGV
    second = np.zeros_like(mrd)
    second[SHIFT:] = mrd[:-SHIFT]
    with h5py.File(path, "w") as f:
        f["mrd"] = np.concatenate([mrd, second], axis=2)
        f["oqparam"] = oqparam
        f["sitecol/lon"] = np.array([lon[0], lon[0] + 2.0])
        f["sitecol/lat"] = np.array([lat[0], lat[0]])
    return path


def _tree(path, sites):
    """A plain table of two branches at ``sites`` sites (power-law curves)."""
    rows = ["branch,weight,pga_g,annual_rate_per_yr,site"]
    for s in range(sites):
        for b, (k, rate) in enumerate(((2.2, 2e-3), (3.0, 5e-3))):
            rows += [f"b{b},0.5,{x:.6g},{rate * (1 + s) * (x / 0.1) ** -k:.6g},{s}"
                     for x in np.geomspace(0.01, 2.0, 15)]
    path.write_text("\n".join(rows) + "\n")
    return path


def _survival(capsys, tree, mrd, out, *argv):
    code = main(["constrain", "--logic-tree", str(tree), "--joint-hazard", str(mrd),
                 "--draws", "0", "--out", str(out), *argv])
    assert code == 0, capsys.readouterr().err
    summary = json.loads((out / "constrain.json").read_text())
    return summary, np.array([b["survival_probability"] for b in summary["branches"]])


def test_two_far_sites_each_with_its_density_multiply(tmp_path, capsys):
    mrd, tree = _two_site_mrd(tmp_path / "mrd.hdf5"), _tree(tmp_path / "tree.csv", 2)
    both, p = _survival(capsys, tree, mrd, tmp_path / "both", "--logistic=-2,3,1",
                        "--logistic=-1,3,1", "--age-ka", "10", "--age-ka", "12",
                        "--specimen-site", "0", "--specimen-site", "1")
    _, first = _survival(capsys, tree, mrd, tmp_path / "first", "--logistic=-2,3,1",
                         "--age-ka", "10", "--site", "0")
    _, second = _survival(capsys, tree, mrd, tmp_path / "second", "--logistic=-1,3,1",
                          "--age-ka", "12", "--site", "1")
    _, by_specimen_site = _survival(capsys, tree, mrd, tmp_path / "alone", "--logistic=-1,3,1",
                                    "--age-ka", "12", "--specimen-site", "1")
    np.testing.assert_allclose(p, first * second, rtol=1e-12)
    np.testing.assert_allclose(by_specimen_site, second, rtol=1e-12)
    assert [s["pgv_pga"]["site_index"] for s in both["sites"]] == [0, 1]
    # the sites' densities differ: under site 0's the second specimen's survival is not its own
    _, under_first = _survival(capsys, tree, _one_site(tmp_path / "site0.hdf5", mrd),
                               tmp_path / "site0", "--logistic=-1,3,1", "--age-ka", "12",
                               "--site", "1")
    assert not np.allclose(under_first, second, rtol=1e-3)


def _one_site(path, two):
    """``two``'s first site alone (the shipped density), under a second site index."""
    with h5py.File(two, "r") as f:
        mrd, oqparam = f["mrd"][()], f["oqparam"][()]
        lon, lat = f["sitecol/lon"][()], f["sitecol/lat"][()]
    with h5py.File(path, "w") as f:
        f["mrd"] = np.concatenate([mrd[..., :1], mrd[..., :1]], axis=2)
        f["oqparam"] = oqparam
        f["sitecol/lon"], f["sitecol/lat"] = lon, lat
    return path


def test_a_site_beyond_the_file_is_refused_in_one_line(tmp_path, capsys):
    mrd, tree = _two_site_mrd(tmp_path / "mrd.hdf5"), _tree(tmp_path / "tree.csv", 3)
    out = tmp_path / "out"
    refused(capsys, ["constrain", "--logic-tree", tree, "--joint-hazard", mrd, "--draws",
                     "0", "--out", out, "--logistic=-2,3,1", "--logistic=-1,3,1", "--age-ka", "10",
                     "--specimen-site", "0", "--specimen-site", "2"],
            "site 2 beyond the file's 2 site(s)", out)


def test_the_top_level_says_each_site_takes_its_own_density(tmp_path, capsys):
    mrd, tree = _two_site_mrd(tmp_path / "mrd.hdf5"), _tree(tmp_path / "tree.csv", 2)
    out = tmp_path / "both"
    code = main(["constrain", "--logic-tree", str(tree), "--joint-hazard", str(mrd),
                 "--draws", "0", "--out", str(out), "--logistic=-2,3,1", "--logistic=-1,3,1",
                 "--age-ka", "10", "--specimen-site", "0", "--specimen-site", "1"])
    printed = capsys.readouterr().out
    assert code == 0
    data = json.loads((out / "constrain.json").read_text())
    top, sites = data["pgv_pga"], data["sites"]
    assert [s["pgv_pga"]["site_index"] for s in sites] == [0, 1]
    # the route, every site, and no one site's density described as if it held for all
    assert top["per_site"] is True and top["site_indices"] == [0, 1]
    assert "mrd" in top["source"] and top["file"] == str(mrd)
    assert "sites[].pgv_pga" in top["sites"]
    assert "site_index" not in top and "pga_cells_with_events" not in top
    assert top["per_branch"] is sites[0]["pgv_pga"]["per_branch"] is False
    assert top["branches"] == sites[1]["pgv_pga"]["branches"]
    assert "PGV/PGA: rate density of PGA and PGV (mrd) at each specimen's site (sites 0, 1)" \
        in printed
    result = read_constrain_result(out / "constrain.json")
    assert isinstance(result.pgv_pga, SitesRatio)
    assert result.text() == (out / "constrain.json").read_text()


def test_one_site_keeps_that_sites_density_at_the_top(tmp_path, capsys):
    mrd, tree = _two_site_mrd(tmp_path / "mrd.hdf5"), _tree(tmp_path / "tree.csv", 2)
    by_site, _ = _survival(capsys, tree, mrd, tmp_path / "site", "--logistic=-1,3,1",
                           "--age-ka", "12", "--site", "1")
    by_specimen, _ = _survival(capsys, tree, mrd, tmp_path / "specimen", "--logistic=-1,3,1",
                               "--age-ka", "12", "--specimen-site", "1")
    assert by_site["pgv_pga"]["site_index"] == 1 and "per_site" not in by_site["pgv_pga"]
    assert by_specimen["pgv_pga"] == by_specimen["sites"][0]["pgv_pga"] == by_site["pgv_pga"]
    assert not isinstance(read_constrain_result(tmp_path / "site" / "constrain.json").pgv_pga,
                          SitesRatio)
