"""constrain with specimens at several sites of one logic tree: the set's survival under a
branch is the product of each site's (two far sites equal two single-site runs
multiplied), one site for all gives today's result, and the branch test names the
branches and specimens below the level."""
import csv
import json
import shutil

import numpy as np
import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main

CASE = RECORDS_DIR / "hazard" / "openquake_logictree_case_11"


def _two_sites(tmp_path):
    """case 11's export with a second site 1 degree east whose poes are half site 0's."""
    out = tmp_path / "tree"
    shutil.copytree(CASE, out)
    for path in out.glob("hazard_curve-smltp*.csv"):
        lines = path.read_text().splitlines()
        cells = lines[2].split(",")
        second = ["1.00000", *cells[1:3]] + [f"{0.5 * float(v):.6E}" for v in cells[3:]]
        path.write_text("\n".join(lines[:3] + [",".join(second)]) + "\n")
    return out


def _constrain(tmp_path, capsys, tree, name, *argv):
    out = tmp_path / name
    code = main(["constrain", "--logic-tree", str(tree), "--draws", "0", "--out", str(out),
                 *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 0, err
    return json.loads((out / "constrain.json").read_text()), out


def test_two_far_sites_multiply_and_the_branch_test(tmp_path, capsys):
    tree = _two_sites(tmp_path)
    both, out = _constrain(tmp_path, capsys, tree, "both", "--median-g", "0.3", "--beta",
                           "0.4", "--median-g", "0.2", "--beta", "0.3", "--age-ka", "2",
                           "--age-ka", "5", "--specimen-site", "0", "--specimen-site", "1")
    first, _ = _constrain(tmp_path, capsys, tree, "first", "--median-g", "0.3", "--beta",
                          "0.4", "--age-ka", "2", "--site", "0")
    second, _ = _constrain(tmp_path, capsys, tree, "second", "--median-g", "0.2", "--beta",
                           "0.3", "--age-ka", "5", "--site", "1")
    p = [np.array([b["survival_probability"] for b in run["branches"]])
         for run in (both, first, second)]
    np.testing.assert_allclose(p[0], p[1] * p[2], rtol=1e-12)
    assert both["sites"] == [{"site": 0, "specimens": [0]}, {"site": 1, "specimens": [1]}]
    rows = list(csv.DictReader((out / "branch_test.csv").open()))
    level = both["branch_test"]["level"]
    assert [r["below_level"] == "true" for r in rows] == list(p[0] < level)
    for r, one, two in zip(rows, p[1], p[2]):
        assert float(r["lowest_specimen_survival"]) == pytest.approx(min(one, two), rel=1e-8)
        assert r["specimens_below_level"] == ";".join(
            str(j) for j, v in enumerate((one, two)) if v < level)


def test_one_site_for_all_is_the_one_site_set(tmp_path, capsys):
    tree = _two_sites(tmp_path)
    args = ("--median-g", "0.3", "--beta", "0.4", "--median-g", "0.2", "--beta", "0.3",
            "--age-ka", "2")
    named, _ = _constrain(tmp_path, capsys, tree, "named", *args, "--specimen-site", "1")
    plain, _ = _constrain(tmp_path, capsys, tree, "plain", *args, "--site", "1")
    assert [b["survival_probability"] for b in named["branches"]] == \
        [b["survival_probability"] for b in plain["branches"]]


def test_a_specimen_site_beyond_the_file_is_one_line(tmp_path, capsys):
    tree = _two_sites(tmp_path)
    code = main(["constrain", "--logic-tree", str(tree), "--median-g", "0.3", "--beta",
                 "0.4", "--age-ka", "2", "--specimen-site", "2", "--out",
                 str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and "2" in err[0]
    assert not (tmp_path / "out").exists()


def test_a_plain_table_with_a_site_column_is_read_site_by_site(tmp_path, capsys):
    """A plain table of two sites (site column): two far sites multiply as with
    OpenQuake's curves, and each site alone is the table of that site without the
    column."""
    rows = {0: (1e-3, 2e-4, 1e-5), 1: (5e-4, 1e-4, 2e-6)}
    levels = (0.1, 0.3, 0.8)
    table = ["branch,weight,pga_g,annual_rate_per_yr,site"]
    alone = {s: ["branch,weight,pga_g,annual_rate_per_yr"] for s in rows}
    for s, rates in rows.items():
        for b, (w, k) in enumerate(((0.4, 1.0), (0.6, 2.0))):
            for x, r in zip(levels, rates):
                table.append(f"b{b},{w},{x},{r * k:.6g},{s}")
                alone[s].append(f"b{b},{w},{x},{r * k:.6g}")
    (tmp_path / "tree.csv").write_text("\n".join(table) + "\n")
    for s in rows:
        (tmp_path / f"site{s}.csv").write_text("\n".join(alone[s]) + "\n")
    args = ("--median-g", "0.3", "--beta", "0.4", "--age-ka", "2")
    both, _ = _constrain(tmp_path, capsys, tmp_path / "tree.csv", "both", *args,
                         "--median-g", "0.2", "--beta", "0.3", "--specimen-site", "0",
                         "--specimen-site", "1")
    first, _ = _constrain(tmp_path, capsys, tmp_path / "site0.csv", "first", *args)
    second, _ = _constrain(tmp_path, capsys, tmp_path / "site1.csv", "second",
                           "--median-g", "0.2", "--beta", "0.3", "--age-ka", "2")
    p = [np.array([b["survival_probability"] for b in run["branches"]])
         for run in (both, first, second)]
    np.testing.assert_allclose(p[0], p[1] * p[2], rtol=1e-12)
    code = main(["constrain", "--logic-tree", str(tmp_path / "tree.csv"), *args,
                 "--out", str(tmp_path / "none")])
    said = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and said == [f"error: {tmp_path / 'tree.csv'}: 2 sites in the table: "
                                  "name one (--site, --specimen-site)"]
