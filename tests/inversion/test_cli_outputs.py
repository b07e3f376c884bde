"""`invert` end to end on a toy forward table file (no YADE): outputs and their keys; the
demo machinery on a toy table; one YADE smoke run of two forward runs."""
import json
import math

import numpy as np
import pandas as pd
import pytest

from pipeline import cli
from pipeline.inversion import EXAMPLES_DIR
from pipeline.inversion.demo import bound_answer, narrowing, split_members, truth_tests
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.candidates import CandidateGrid

SUMMARY_KEYS = {"map_epicentre_km", "back_azimuth_map_deg", "back_azimuth_ci68_deg",
                "back_azimuth_ci95_deg", "distance_ci95_km", "mechanism_posterior",
                "credible_area_95_km2"}


def test_invert_writes_the_outputs(tmp_path, capsys, make_away_table):
    table = make_away_table().save(tmp_path / "toy.npz")
    out = tmp_path / "out"
    code = cli.main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--table", str(table),
                     "--out", str(out), "--radius", "15", "--step", "1.5"])
    assert code == 0, capsys.readouterr().err
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert SUMMARY_KEYS <= set(summary)
    lo, hi = summary["back_azimuth_ci95_deg"]
    assert 0 <= lo < 360 and 0 <= hi <= 360
    assert sum(summary["mechanism_posterior"].values()) == pytest.approx(1.0)
    assert summary["forward_table"]["reused_file"] is True
    posterior = pd.read_csv(out / "posterior.csv")
    assert {"mechanism", "strike_deg", "east_km", "north_km", "log_likelihood",
            "posterior"} <= set(posterior.columns)
    assert posterior["posterior"].sum() == pytest.approx(1.0)
    assert len(posterior) == summary["candidates"]
    for name in ("posterior_map.png", "marginals.png"):
        assert (out / name).stat().st_size > 10000
    # the candidate subset: one mechanism
    cli.main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--table", str(table),
              "--out", str(tmp_path / "thrust"), "--radius", "10", "--mechanisms", "thrust"])
    assert json.loads((tmp_path / "thrust" / "inversion_summary.json").read_text())[
        "mechanism_posterior"] == {"thrust": pytest.approx(1.0)}


def test_demo_machinery_on_a_toy_table(make_away_table):
    table = make_away_table(members=6, p_fall=(1.0, 0.8, 0.5, 0.2))
    model_half, pool = split_members(table)
    assert list(model_half.members) == [0, 2, 4] and list(pool.members) == [1, 3, 5]
    grid = CandidateGrid(radius_km=22, step_km=1.5, strike_step_deg=30)
    trials = truth_tests(ForwardModel(model_half), pool, grid, trials=3,
                         fallen_per_site=(1, 10), site_counts=(1, 3))
    assert len(trials) == 2 * 2 * 2 * 3
    narrow = narrowing(trials)
    # more fallen columns: a narrower back azimuth (falls away from the source)
    for (mech, sites), g in narrow.groupby(["mechanism", "sites"]):
        g = g.sort_values("fallen_per_site")
        assert g["width_median_deg"].iloc[-1] < g["width_median_deg"].iloc[0]
    assert trials["back_azimuth_in_95"].mean() >= 0.8
    answers = bound_answer(narrow)
    assert all(a["fallen_per_site"] in (1, 10) for a in answers)


@pytest.mark.yade
def test_quick_smoke_two_yade_runs_and_reuse(tmp_path, capsys):
    """Two forward runs (one ring, two node azimuths, one member) through the campaign; the
    second inversion with other observations reuses them."""
    args = ["--quick", "--mechanisms", "strike-slip", "--distances", "3",
            "--azimuth-step", "180", "--members", "1", "--jobs", "1",
            "--forward-dir", str(tmp_path / "forward")]
    assert cli.main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--out",
                     str(tmp_path / "a"), *args]) == 0
    first = capsys.readouterr().out
    assert "2 runs, 0 already done" in first
    summary = json.loads((tmp_path / "a" / "inversion_summary.json").read_text())
    assert SUMMARY_KEYS <= set(summary)
    assert summary["forward_table"]["runs"] == 2
    assert cli.main(["invert", str(EXAMPLES_DIR / "geographic.json"), "--out",
                     str(tmp_path / "b"), *args]) == 0
    assert "2 runs, 2 already done, 0 to run" in capsys.readouterr().out
    tables = list((tmp_path / "forward" / "tables").glob("forward_table_*.npz"))
    assert len(tables) == 1


def test_demo_outputs_feed_the_report(tmp_path, make_away_table):
    """run_demo on a toy table with nominal runs (the paper's thrust source at 10 km is one
    of its slices), then the report section from its demo_summary.json."""
    import dataclasses

    from pipeline.inversion.demo import run_demo
    from pipeline.report import inversion_section
    table = make_away_table(members=4, p_fall=(1.0, 0.75, 0.5, 0.25))
    shape = table.toppled.shape[:4]
    fell = np.indices(shape).sum(axis=0) % 2 == 0
    table = dataclasses.replace(
        table, nominal_toppled=fell, nominal_valid=np.ones(shape, bool),
        nominal_azimuth_deg=np.where(fell, table.azimuths_deg[None, None, :, None], np.nan))
    grid = CandidateGrid(radius_km=21, step_km=3, strike_step_deg=90)
    out = tmp_path / "results" / "inversion"
    summary = run_demo(table, out, grid, {"thrust": table}, trials=1)
    for kind in ("independent", "predictive"):
        assert summary["coverage"][kind]["trials"] == 2 * 2 * 4
    assert {row["source"] for row in summary["paper_scenario"]["per_source"]} == {"thrust"}
    sites = pd.read_csv(out / "paper_scenario_sites.csv")
    assert len(sites) == 3 * 12                      # rings 5, 10, 20 km every 30 deg
    text = inversion_section(tmp_path / "results")
    for phrase in ("(a) Coverage", "(b) How the back azimuth narrows",
                   "(c) The paper's question", "The paper's scenario", "narrowing.png"):
        assert phrase in text
    # the reach: the joint inversion takes the sites within half the table's last ring
    # (the rings 5 and 10 of 20 km), and the coverage says what a warning answered
    assert [j["sites"] for j in summary["paper_scenario"]["joint"]] == [2 * 12]
    assert "the 24 sites within 10 km (half the forward table's last ring" in text
    assert "or the inversion warned that it may lie farther in" in text


def _column_fragility(directory, columns=("monolithic", "drums"), median=3.0, beta=0.4):
    """A column fragility.json of campaign fragility: the same lognormal PGA fit (m/s^2, the
    horizontal vector peak) for each column type, scaled records the project does not hold
    (so RotD50 comes from Boore & Kishida 2017 at their reference M 5.5, 50 km)."""
    directory.mkdir()
    fit = {"unit": "m/s^2", "median": median, "beta": beta}
    (directory / "fragility.json").write_text(json.dumps(
        {"records": ["not-a-record"], "columns": {c: {"PGA": fit} for c in columns}}))
    return directory


def test_invert_reports_each_sites_motion_beside_the_source(tmp_path, capsys, make_away_table):
    from scipy import stats
    table = make_away_table().save(tmp_path / "toy.npz")
    out = tmp_path / "out"
    code = cli.main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--table", str(table),
                     "--out", str(out), "--radius", "10", "--step", "2",
                     "--site-fragility", str(_column_fragility(tmp_path / "fragility"))])
    assert code == 0, capsys.readouterr().err
    motion = json.loads((out / "site_motion.json").read_text())
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert summary["site_motion"] == motion and "site_motion.json" in summary["outputs"]
    assert SUMMARY_KEYS <= set(summary)
    # identical lognormal columns, k of n fallen: the most likely PGA is median
    # exp(beta Phi^-1(k/n)) on the campaign's PGA; on RotD50 times 1 / exp(0.18577), the
    # RotD100/RotD50 of PGA of Boore & Kishida (2017) at M 5.5, 50 km
    to_rotd50 = math.exp(-0.185774509)
    sites = {s["site"]: s for s in motion["sites"]}
    assert (sites["A"]["fallen"], sites["A"]["columns"]) == (1, 2)
    assert sites["A"]["pga_ml_m_s2"] == pytest.approx(3.0 * to_rotd50, rel=1e-5)
    assert (sites["B"]["fallen"], sites["B"]["columns"]) == (2, 3)
    assert sites["B"]["pga_ml_m_s2"] == pytest.approx(
        3.0 * math.exp(0.4 * stats.norm.ppf(2 / 3)) * to_rotd50, rel=1e-5)


@pytest.mark.parametrize("extra, message", [
    (["--at-pgv-pga", "0.1"], "go with --site-fragility"),
    (["--site-fragility", "FRAG", "--site-fragility-form", "pga-pgv"], "needs --at-pgv-pga"),
    (["--site-fragility", "FRAG", "--at-pgv-pga", "0.1"], "goes with --site-fragility-form"),
    (["--site-fragility", "MONO"], "no column 'drums'"),
    (["--site-fragility", "FRAG", "--site-fragility-form", "pga-pgv", "--at-pgv-pga", "0"],
     "--at-pgv-pga 0 outside the allowed range [0.001, 10] s"),
    (["--site-fragility", "FRAG", "--site-fragility-form", "pga-pgv", "--at-pgv-pga", "11"],
     "--at-pgv-pga 11 outside the allowed range [0.001, 10] s"),
    (["--site-fragility", "FRAG", "--site-fragility-form", "pga-pgv", "--at-pgv-pga", "nan"],
     "--at-pgv-pga must be a finite number"),
    (["--site-fragility", "FRAG", "--site-fragility-form", "pga-pgv", "--at-pgv-pga", "0.1",
      "--at-pgv-pga", "0.2"], "--at-pgv-pga given more than once"),
])
def test_invert_site_motion_refuses_in_one_line(tmp_path, capsys, extra, message,
                                                 make_away_table):
    table = make_away_table().save(tmp_path / "toy.npz")
    paths = {"FRAG": str(_column_fragility(tmp_path / "f")),
             "MONO": str(_column_fragility(tmp_path / "m", columns=("monolithic",)))}
    out = tmp_path / "out"
    argv = ["invert", str(EXAMPLES_DIR / "two_sites.json"), "--table", str(table),
            "--out", str(out)] + [paths.get(a, a) for a in extra]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_invert_help_states_the_at_pgv_pga_range_survival_states(capsys, monkeypatch):
    """--at-pgv-pga is the PGV/PGA (s) at which the site's PGA range is stated, in invert
    as in survival: one range, 0.001-10 s, in both helps."""
    monkeypatch.setenv("COLUMNS", "200")            # no flag broken at its hyphen
    said = {}
    for command in ("invert", "survival"):
        with pytest.raises(SystemExit):
            cli.main([command, "--help"])
        said[command] = " ".join(capsys.readouterr().out.split()) + " "
    assert "--at-pgv-pga S the PGV/PGA at which the PGA range is stated for " \
        "--site-fragility-form pga-pgv (s); 0.001-10 " in said["invert"]
    assert "--at-pgv-pga S the PGV/PGA at which the PGA range is stated (for a fragility " \
        "over PGA and PGV/PGA) (s); 0.001-10 " in said["survival"]


def test_invert_refuses_a_damage_state_its_site_fragility_cannot_weigh(tmp_path, capsys,
                                                                      make_away_table):
    # --site-fragility holds P(topple) only: a column seen in a damage state needs the
    # fragilities of its states, refused in one line before any work
    table = make_away_table().save(tmp_path / "toy.npz")
    data = json.loads((EXAMPLES_DIR / "two_sites.json").read_text())
    data["sites"][0]["columns"].append({"column": "monolithic", "state": "standing",
                                        "damage_state": "slight"})
    obs = tmp_path / "obs.json"
    obs.write_text(json.dumps(data))
    out = tmp_path / "out"
    assert cli.main(["invert", str(obs), "--table", str(table), "--out", str(out),
                     "--site-fragility", str(_column_fragility(tmp_path / "f"))]) == 2
    err = capsys.readouterr().err.strip()
    assert "observed slight, which needs the fragility of damage state 'slight'" in err
    assert len(err.splitlines()) == 1 and not out.exists()
