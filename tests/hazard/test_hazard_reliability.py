"""constrain and survival as a careless user drives them: a second run into the same
folder leaves no result of the first beside its own, one specimen given twice is
refused, absurd values in a hazard or fragility file are refused by its loader (as the
command line refuses them) before anything is written, and each message names what is
wrong."""
import json

import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main
from tests.refusal import refused

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
    refused(capsys, ["survival", "--hazard", CASE_14, "--hazard", CASE_14, "--site", "0",
                     "--median-g", "0.3", "--beta", "0.4", "--age-ka", "2", "--out", out],
            "the same curve twice", out)


def test_campaign_columns_refuses_one_description_given_twice(tmp_path):
    from pipeline.campaign.definitions import columns_specs
    from pipeline.files import InputError
    from pipeline.scenario.geometry import EXAMPLES_DIR
    with pytest.raises(InputError, match="the same specimen twice"):
        columns_specs([], tmp_path, column_files=["roman-granite",
                                                  str(EXAMPLES_DIR / "roman-granite.json")])


# ---------------------------------------------------------------- absurd hazard values
@pytest.mark.parametrize("table, words", [
    ("pga_g,annual_rate_per_yr\n0.1,1e300\n0.2,1e299\n0.5,1e298\n1.0,1e297\n",
     "annual rate 1e+300 at 0.1 g: at most 1000 per year"),
    ("pga_g,annual_rate_per_yr\n1e-9,1e-1\n0.2,1e-3\n", "level 1e-09 g"),
    ("pga_m_s2,annual_rate_per_yr\n1e-7,1e-1\n2,1e-3\n", "(1e-6 g to 100 g)"),
])
def test_survival_refuses_absurd_curve_values_and_writes_nothing(tmp_path, capsys, table,
                                                                  words):
    curve = tmp_path / "curve.csv"
    curve.write_text(table)
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(curve), "--median-g", "0.3", "--beta", "0.4",
                 "--age-ka", "2", "--age-sd-ka", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_constrain_refuses_absurd_rates_of_a_branch_and_writes_nothing(tmp_path, capsys):
    tree = tmp_path / "tree.csv"
    tree.write_text("branch,weight,pga_g,annual_rate_per_yr\n"
                    "a,0.5,0.1,1e-2\na,0.5,0.5,1e-3\nb,0.5,0.1,1e300\nb,0.5,0.5,1e299\n")
    out = tmp_path / "out"
    assert main(["constrain", "--logic-tree", str(tree), *DOC, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "branch 'b': annual rate 1e+300" in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_an_openquake_curve_of_a_tiny_investigation_time_is_refused(tmp_path):
    """poe 0.5 in 1e-6 yr is a rate of 6.9e5 per year: refused as the plain table's."""
    from pipeline.files import InputError
    from pipeline.hazard import load_hazard
    curve = tmp_path / "oq.csv"
    curve.write_text("#,,,\"kind='mean', investigation_time=1e-6, imt='PGA'\"\n"
                     "lon,lat,poe-0.1,poe-0.2\n0.0,0.0,0.5,0.1\n")
    with pytest.raises(InputError, match="at most 1000 per year"):
        load_hazard(curve)


# ---------------------------------------------------------------- values from files
@pytest.mark.parametrize("change, words", [
    ({"beta": 50.0, "beta_ci95": [40.0, 60.0]}, "PGA beta 50 outside the allowed range [0.01, 3]"),
    ({"median": 1e300, "median_ci95": [1e299, 1e301]}, "PGA median 1e+300 outside"),
    ({"median": 1e-12, "median_ci95": [1e-13, 1e-11]}, "PGA median 1e-12 outside"),
])
def test_a_files_pga_fit_gets_the_command_lines_ranges(tmp_path, change, words):
    from pipeline.files import InputError
    from pipeline.hazard.fragility import load_campaign_fragility
    from tests.hazard.test_reader_robustness import COLUMN
    data = json.loads(json.dumps(COLUMN))
    data["columns"]["monolithic"]["PGA"].update(change)
    path = tmp_path / "fragility.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match=words.replace("[", r"\[").replace("+", r"\+")):
        load_campaign_fragility(path, None, "pga")


@pytest.mark.parametrize("argv, words", [
    (["--median-g", "1e-12", "--beta", "0.4"], "--median-g 1e-12 outside"),
    (["--median-g", "0.3", "--beta", "50"], "--beta 50 outside"),
])
def test_the_command_line_refuses_what_a_file_is_refused(tmp_path, capsys, argv, words):
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(CASE_14), "--site", "0", *argv,
                 "--age-ka", "2", "--out", str(out)]) == 2
    assert words in capsys.readouterr().err and not out.exists()


def test_a_column_without_a_pga_fit_is_said_so(tmp_path):
    from pipeline.files import InputError
    from pipeline.hazard.fragility import load_campaign_fragility
    from tests.hazard.test_reader_robustness import COLUMN
    data = json.loads(json.dumps(COLUMN))
    del data["columns"]["monolithic"]["PGA"]
    path = tmp_path / "fragility.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="column monolithic: no PGA fit in the file") as err:
        load_campaign_fragility(path, None, "pga")
    assert "None" not in str(err.value)


def _grid(cells_p_per_set, overturned, n=20, headings=None):
    from tests.hazard.test_reader_robustness import grid_document
    data = grid_document(n=n)
    cell = data["pulse_grid"]["models"]["monolithic"]["cells"][0]
    cell.update(overturned=overturned, P=overturned / n, ci95=[0.0, 1.0],
                P_per_set=cells_p_per_set)
    if headings is not None:
        data["pulse_grid"]["headings"] = headings
    return data


@pytest.mark.parametrize("data, words", [
    (_grid([1.0, 1.0], 10), "from 1 to 1 contradicts overturned / n = 10/20"),
    (_grid([0.0, 0.1], 10), "from 0 to 0.1 contradicts"),
    (_grid([0.3, 0.5], 10, headings=10), "gives 8 overturned runs (10 headings per set), "
                                         "the cell 10"),
    (_grid([0.5, 0.5], 10, headings=5), "n 20 is more than 2 sets x 5 headings"),
])
def test_sets_p_that_contradict_the_cells_counts_are_refused(tmp_path, data, words):
    from pipeline.files import InputError
    from pipeline.hazard.fragility.file import check_fragility
    with pytest.raises(InputError, match=r"cells\[0\]") as err:
        check_fragility(data, "fragility.json")
    assert words in str(err.value)


def test_what_the_pulse_campaign_writes_agrees_with_the_counts_check():
    """Cells of a campaign's table where some sets ran only some headings (the adaptive
    stages): the campaign's own cell table passes the check; every set all headings
    too."""
    import numpy as np
    import pandas as pd

    from pipeline.campaign.pulse_summary import cell_table
    from pipeline.hazard.fragility.check import Checker, _check_set_counts
    from pipeline.hazard.fragility.rows import GridCell
    rng = np.random.default_rng(3)
    for full in (False, True):
        rows = [{"model": "monolithic", "pgv_pga_s": 0.1, "pga_g": a, "member": m,
                 "heading": h, "toppled": bool(rng.random() < a)}
                for a in (0.2, 0.5, 0.8) for m in range(4) for h in range(6)
                if full or rng.random() < 0.6]
        for k, cell in enumerate(cell_table(pd.DataFrame(rows), "monolithic")):
            _check_set_counts(Checker("fragility.json"), GridCell.of(cell), f"cells[{k}]", 6)


def test_curves_of_two_investigation_times_are_not_one_tree(tmp_path):
    import shutil

    from pipeline.files import InputError
    from pipeline.hazard.logictree import load_logic_tree
    tree = tmp_path / "tree"
    shutil.copytree(CASE_11, tree)
    curve = tree / "hazard_curve-smltp_b1_b3-gsimltp_b1.csv"
    curve.write_text(curve.read_text().replace("investigation_time=1.0",
                                               "investigation_time=50.0"))
    with pytest.raises(InputError, match="investigation_time 50 yr, .*: 1 yr"):
        load_logic_tree(tree)


def test_a_pulse_grid_of_its_2d_block_alone_is_not_taken_for_the_rock(tmp_path):
    from pipeline.files import InputError
    from pipeline.hazard.fragility import load_campaign_fragility
    from tests.hazard.test_reader_robustness import grid_document
    data = grid_document()
    models = data["pulse_grid"]["models"]
    models["block2d"] = models.pop("monolithic")
    path = tmp_path / "fragility.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="holds only its 2D rigid block's model"):
        load_campaign_fragility(path)
    assert "block2d pulse grid" in load_campaign_fragility(path, "block2d").label


# ---------------------------------------------------------------- messages
@pytest.mark.parametrize("extra, words", [
    (["--floor", "0"], "--floor 0 outside the allowed range (0, 1)"),
    (["--floor", "1"], "--floor 1 outside the allowed range (0, 1)"),
    (["--age-ka", "10000.001"], "--age-ka 10000.001 outside the allowed range (0, 10000] ka"),
    (["--fragility-form", "grid"], "--fragility-form applies to --fragility files"),
    (["--below-grid", "zero"], "--below-grid applies to a pulse-grid fragility"),
])
def test_constrain_says_what_it_checks(tmp_path, capsys, extra, words):
    out = tmp_path / "out"
    ages = [] if "--age-ka" in extra else ["--age-ka", "2"]
    assert main(["constrain", "--logic-tree", str(CASE_11), "--median-g", "0.3", "--beta",
                 "0.4", *ages, *extra, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_survival_refuses_a_fragility_form_without_a_fragility_file(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(CASE_14), "--site", "0", "--median-g", "0.3",
                 "--beta", "0.4", "--age-ka", "2", "--fragility-form", "grid",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "--fragility-form applies to --fragility files" in err
    assert len(err.splitlines()) == 1 and not out.exists()


def test_a_weight_0_branch_that_survives_is_named_not_called_below_the_floor(tmp_path,
                                                                              capsys):
    """Branches a and b (weights 0.5) give the specimen a survival far below 0.05, z
    (weight 0, rates a million times lower) far above: elimination leaves no weight, and
    the warning says it is z's weight, not that every branch lies below the floor."""
    tree = tmp_path / "tree.csv"
    tree.write_text("branch,weight,pga_g,annual_rate_per_yr\n"
                    "a,0.5,0.1,1e-1\na,0.5,1.0,1e-2\nb,0.5,0.1,2e-1\nb,0.5,1.0,2e-2\n"
                    "z,0,0.1,1e-7\nz,0,1.0,1e-8\n")
    out = tmp_path / "out"
    assert main(["constrain", "--logic-tree", str(tree), "--median-g", "0.3", "--beta", "0.4",
                 "--age-ka", "2", "--rule", "eliminate", "--draws", "0",
                 "--out", str(out)]) == 0
    summary = json.loads((out / "constrain.json").read_text())
    p = {b["branch"]: b["survival_probability"] for b in summary["branches"]}
    assert p["a"] < 0.05 and p["b"] < 0.05 < p["z"]
    said = [w for w in summary["warnings"] if "elimination" in w]
    assert said == ["only branches of weight 0 (z) give a survival probability of at least "
                    "0.05: elimination leaves no weight on any branch, no constrained curve "
                    "under that rule"]


@pytest.mark.parametrize("axis, values, words", [
    ("pga_g", [1e-12, 0.2, 0.4], "pulse_grid.pga_g 1e-12 outside the allowed range [1e-06, 20]"),
    ("pgv_pga_s", [1e-9, 0.2], "pulse_grid.pgv_pga_s 1e-09 outside the allowed range "
                               "[0.001, 10]"),
])
def test_a_pulse_grids_axes_take_the_hazard_inputs_lower_bounds(axis, values, words):
    from pipeline.files import InputError
    from pipeline.hazard.fragility.file import check_fragility
    from tests.hazard.test_reader_robustness import grid_document
    data = grid_document()
    old = data["pulse_grid"][axis]
    data["pulse_grid"][axis] = values
    for model in data["pulse_grid"]["models"].values():
        for cell in model["cells"]:
            cell[axis] = values[old.index(cell[axis])]
    with pytest.raises(InputError) as err:
        check_fragility(data, "fragility.json")
    assert words in str(err.value)


def test_survival_says_when_its_curves_state_different_investigation_times(tmp_path):
    """One curve written for 1 yr and for 50 yr (poe = 1 - exp(-50 rate)): the annual
    rates are the same, so is the survival under each, and the warning says the times
    differ and how each was converted."""
    import math
    levels = [0.05, 0.1, 0.2, 0.4, 0.8]
    rates = [2e-2, 6e-3, 1.5e-3, 3e-4, 4e-5]
    paths = []
    for years in (1.0, 50.0):
        poe = [-math.expm1(-r * years) for r in rates]
        path = tmp_path / f"curve_{years:g}.csv"
        path.write_text(f"#,,\"kind='mean', investigation_time={years}, imt='PGA'\"\n"
                        "lon,lat," + ",".join(f"poe-{x}" for x in levels) + "\n"
                        "0.0,0.0," + ",".join(f"{p!r}" for p in poe) + "\n")
        paths += ["--hazard", str(path)]
    out = tmp_path / "out"
    assert main(["survival", *paths, "--median-g", "0.3", "--beta", "0.4", "--age-ka", "2",
                 "--draws", "0", "--out", str(out)]) == 0
    summary = json.loads((out / "survival.json").read_text())
    rows = summary["hazard_curves"]
    assert [r["investigation_time_yr"] for r in rows] == [1.0, 50.0]
    assert rows[0]["survival_probability"] == pytest.approx(rows[1]["survival_probability"],
                                                            rel=1e-9)
    assert any("investigation times of 1, 50 yr" in w for w in summary["warnings"])
