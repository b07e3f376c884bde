"""The members mode of campaign shake-table without YADE: bad options refused in one line
before anything is written, the members drawn as the fragility draws them, and the scores
file of a synthetic threshold model (baselines against their closed forms)."""
import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from pipeline import cli
from pipeline.campaign import ensemble_members, member_ranges, pulse_grid
from pipeline.campaign.shake_table_experiments import EXPERIMENTS, OUTCOME, SPECIMEN
from pipeline.campaign.shake_table_members import choose_ranges, member_sets, run_params
from pipeline.campaign.shake_table_scores import write_scores
from pipeline.scenario.geometry import ColumnGeometry
from tests.campaign.tiny_members_campaign import write_member_runs


@pytest.mark.parametrize("args, said", [
    (["--members", "0"], "--members"),
    (["--seed", "5"], "--seed belongs to the members mode"),
    (["--ranges", "kn=4e7:1e8"], "--ranges belongs to the members mode"),
    (["--members", "4", "--ranges", "kn=4e7:1e8;kn=5e7:1e8"], "names kn twice"),
    (["--members", "4", "--ranges", "friction=0.1:0.2"], "unknown parameter 'friction'"),
    (["--members", "4", "--ranges", "damping=0.2:0.1"], "LO <= HI"),
    (["--members", "4", "--grid", "damping=0.05,0.1"], "names 2 parameter sets"),
    (["--members", "4", "--seed", "-1"], "seed"),
    (["--members", "4", "--ranges", "kn=1e8:1e8;damping=0.1:0.1;mu_s=0.7:0.7;"
      "footprint_tolerance_m=0.001:0.001;yaw_deg=0:0"], "nothing drawn"),
    (["--members", "4", "--tests", "Test011,Test011"], "names Test011 twice"),
    (["--candidates", "default|kn=4e7:1e9"], "--candidates belongs to the members mode"),
    (["--members", "4", "--candidates", "kn=4e7:1e9"], "give 2 to 8 ranges"),
    (["--members", "4", "--candidates", "|".join(["default"] + [f"kn=4e7:{k}e8" for k in
                                                               range(2, 10)])],
     "give 2 to 8 ranges"),
    (["--members", "4", "--candidates", "default|"], "same ranges as an earlier"),
    (["--members", "4", "--candidates", "default|kn=4e7:1.2e9"], "same ranges as an earlier"),
    (["--members", "4", "--candidates", "default|kn=4e7"], "--candidates kn='4e7': expected"),
    (["--members", "4", "--candidates", "default|kn=4e7:1e9", "--ranges", "kn=4e7:1e8"],
     "give one"),
    (["--members", "4", "--candidates", "default|kn=4e7:1e9", "--tests", "Test693"],
     "no test before --validate-from"),
])
def test_bad_options_are_refused_in_one_line(tmp_path, capsys, args, said):
    out = tmp_path / "out"
    code = cli.main(["campaign", "shake-table", *args, "--out", str(out), "--jobs", "1"])
    lines = [x for x in capsys.readouterr().err.splitlines() if not x.startswith("note:")]
    assert code == 2
    assert len(lines) == 1 and lines[0].startswith("error:") and said in lines[0], lines
    assert not out.exists()


def test_bad_providers_table_is_refused(tmp_path, capsys):
    bad = tmp_path / "p.csv"
    bad.write_text("test,model_a\nTest011,2\n")
    code = cli.main(["campaign", "shake-table", "--members", "4", "--providers", str(bad),
                     "--out", str(tmp_path / "out")])
    lines = [x for x in capsys.readouterr().err.splitlines() if not x.startswith("note:")]
    assert code == 2 and len(lines) == 1 and "column model_a must be 0 or 1" in lines[0]


def test_members_are_the_fragilitys_draws():
    """The members of SP1 are the parameter sets campaign fragility --column-file draws
    for it (same seed), over the one declaration of the members' ranges, mu_k at 0.6/0.7
    of mu_s; kn log-uniform; a member's yaw turns the table motion the other way."""
    rock = ColumnGeometry.load(SPECIMEN).to_dict()
    sets, drawn = member_sets(rock, 8, None, None)
    _, fragility_sets, azimuths, _ = pulse_grid.pulse_runs(
        rock, "monolithic", "pga_g=0.5:0.5:1;pgv_pga_s=0.1:0.1:1", 8, 1, 90.0,
        ensemble_members.DEFAULT_SEED, None)
    assert sets == fragility_sets
    declared = {r.name: (r.low, r.high) for r in member_ranges.MEMBER_RANGES}
    assert drawn == declared == pulse_grid.parse_ranges(None)
    kn_lo, kn_hi = declared["kn"]
    for point in sets:
        for name, (lo, hi) in declared.items():
            assert lo <= point[name] <= hi
        assert point["mu_k"] == pytest.approx(point["mu_s"] * 0.6 / 0.7, abs=1e-4)
    # kn is log-uniform: as many members below the geometric mean as above it
    assert sum(p["kn"] < math.sqrt(kn_lo * kn_hi) for p in sets) == 4
    # the fixed azimuth 90 turned by each member's yaw; on the table the motion the same way
    for point, row in zip(sets, azimuths):
        assert row[0] == pytest.approx((90.0 - point["yaw_deg"]) % 360.0, abs=1e-6)
        params = run_params(rock, point, None)
        assert params["rotate_deg"] == pytest.approx((-point["yaw_deg"]) % 360.0, abs=1e-6)
    assert "rotate_deg" not in run_params(rock, {"kn": 1e8}, None)


def test_scores_of_a_synthetic_threshold_model(tmp_path):
    """Shipped tests with P of a known threshold model as if from 8 members: the file has
    every split, the never-overturns baseline's Brier score is the observed rate (closed
    form: (0 - o)^2 averaged), the providers' models are scored on the same tests and the
    reliability diagram is drawn."""
    frame = pd.read_csv(EXPERIMENTS, keep_default_na=False)
    frame = frame[frame["motion_file"] != ""].iloc[::5]
    rng = np.random.default_rng(1)
    p_true = 1 / (1 + np.exp(-(np.log(frame["pga_g"].to_numpy() / 0.2) / 0.3)))
    k = rng.binomial(8, p_true)
    per_test = pd.DataFrame({
        "test": frame["test"].to_numpy(), "date": frame["date"].to_numpy(),
        "split": np.where(frame["date"] < "2021-08-01", "calibration", "validation"),
        "pga_g": frame["pga_g"].to_numpy(), "pgv_pga_s": frame["pgv_pga_s"].to_numpy(),
        "observed": frame[OUTCOME].to_numpy().astype(bool), "runs": 8, "overturned": k,
        "P": k / 8, "ci95_low": 0.0, "ci95_high": 1.0,
        "single_set_predicted": k >= 4})
    full = [SimpleNamespace(tags=SimpleNamespace(member=m, point={"m": m})) for m in (-1, 0, 1)]
    options = {"specimen": SPECIMEN, "experiments": EXPERIMENTS, "outcome": OUTCOME,
               "validate_from": "2021-08-01", "members": 8, "axis_deg": 90.0}
    write_member_runs(tmp_path, per_test)
    write_scores(per_test, tmp_path, options, full, True)
    result = json.loads((tmp_path / "shake_table_members.json").read_text())
    for split in ("calibration", "validation", "all"):
        rows = per_test if split == "all" else per_test[per_test["split"] == split]
        s = result["splits"][split]
        assert s["tests"] == len(rows)
        assert s["never_overturns"]["brier"] == pytest.approx(rows["observed"].mean())
        assert s["members"]["n"] == len(rows)
        assert set(s["providers"]) == {"kn1_ks1", "kn3_ks1", "kn5_ks1", "kn10_ks1",
                                       "kn15_ks1"}
        assert s["providers"]["kn10_ks1"]["n"] == len(rows)
    assert result["splits"]["all"]["members"]["clip"] == pytest.approx(1 / 18)
    assert (tmp_path / "shake_table_reliability.png").stat().st_size > 10_000
    assert len(pd.read_csv(tmp_path / "members.csv")) == len(per_test)
    wrong = (per_test["observed"] != (per_test["P"] > 0.5)).sum()
    assert result["disagreements"]["wrong"]["count"] == wrong


def test_a_split_without_tests_has_no_scores():
    """Only held-out tests named: the calibration split is left out, not scored empty."""
    import pandas as pd

    from pipeline.campaign.shake_table_scores import split_scores
    empty = pd.DataFrame({"observed": [], "P": [], "runs": [], "single_set_predicted": [],
                          "pga_g": [], "test": []})
    assert split_scores(empty, 0.26, {}) is None


def _rows(observed, p, runs=8):
    return pd.DataFrame({"test": [f"T{k}" for k in range(len(p))], "observed": observed,
                         "P": p, "runs": [runs] * len(p)})


def test_the_candidate_with_the_best_log_likelihood_is_chosen_not_the_best_accuracy():
    """Two candidates with the same accuracy of P > 0.5: the one whose probabilities are
    nearer the outcomes wins by log-likelihood; on a tie, the lower Brier score."""
    observed = [True, True, False, False]
    sure = _rows(observed, [1.0, 1.0, 0.0, 0.0])        # right and sure
    hedged = _rows(observed, [0.625, 0.75, 0.375, 0.25])  # right, less sure
    wrong = _rows(observed, [0.0, 0.0, 1.0, 1.0])
    choice = choose_ranges([("kn=4e7:1e9", hedged), ("", sure), ("damping=0.05:0.06", wrong)])
    assert choice["chosen"] == ""
    scores = {c["ranges"]: c for c in choice["candidates"]}
    assert scores[None]["accuracy"] == scores["kn=4e7:1e9"]["accuracy"] == 1.0
    clip = 1 / (2 * (8 + 1))                            # the Jeffreys clip of 8 agreeing runs
    assert scores[None]["log_likelihood_per_test"] == pytest.approx(math.log(1 - clip))
    assert scores["kn=4e7:1e9"]["log_likelihood_per_test"] == pytest.approx(
        np.mean(np.log([0.625, 0.75, 0.625, 0.75])))
    tie = choose_ranges([("a=1:2", hedged), ("b=1:2", hedged.assign(P=[0.625, 0.75, 0.375, 0.25]))])
    assert tie["chosen"] == "a=1:2"                     # equal scores: the first given


def test_the_long_run_gate_counts_the_runs_before_any_spec_is_built(tmp_path, capsys,
                                                                    monkeypatch):
    from pipeline.campaign import shake_table_members

    def no_specs(*args, **kwargs):
        raise AssertionError("run specs built before the long-run gate")
    monkeypatch.setattr(shake_table_members, "run_specs", no_specs)
    out = tmp_path / "out"
    code = cli.main(["campaign", "shake-table", "--members", "1000", "--candidates",
                     "default|mu_s=0.3:0.9", "--jobs", "1", "--out", str(out)])
    lines = [x for x in capsys.readouterr().err.splitlines() if not x.startswith("note:")]
    assert code == 2 and len(lines) == 1 and "add --allow-long" in lines[0], lines
    assert not out.exists()


def test_the_planned_runs_are_those_the_specs_hold(tmp_path):
    """The gate's count from the options alone is the number of distinct runs (and their
    core seconds) of the specs the members mode builds: each candidate on the calibration
    tests, then the chosen on every test (counted at the costliest candidate)."""
    from pipeline.campaign import shake_table_members as stm
    from pipeline.campaign.shake_table import ShakeTableOptions
    options = {**ShakeTableOptions().kwargs(), "members": 2, "specimen": SPECIMEN,
               "tests": ["Test011", "Test012", "Test412"]}
    specimen = ColumnGeometry.load(SPECIMEN).to_dict()
    candidates = ["", "kn=4e7:5e7"]
    calibration = ["Test011", "Test012"]
    runs, core = stm.planned_runs(specimen, options, candidates, len(calibration), 3)
    built = []
    for chosen in candidates:
        specs = [s for c in candidates for s in stm.run_specs(
            [], tmp_path, {**options, "ranges": c, "tests": calibration})]
        specs += stm.run_specs([], tmp_path, {**options, "ranges": chosen})
        distinct = {s.run_id: s.core_s for s in specs}
        built.append((len(distinct), sum(distinct.values())))
    assert runs == max(n for n, _ in built) == 2 * 2 * 2 + 2 * 1 + 3
    assert core == pytest.approx(max(c for _, c in built), rel=1e-3)
