"""The members' ranges chosen over folds of test days, without YADE: the folds cut by
day against hand counts, the choice by the worst fold and its cross-validation against
log-likelihoods computed by hand, the reliability bins (P = 0 and P = 1 apart) against
the Wilson interval's closed form, and the files the scores write."""
import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from pipeline import cli
from pipeline.campaign.shake_table_experiments import EXPERIMENTS, OUTCOME, SPECIMEN
from pipeline.campaign.shake_table_folds import choose_ranges, date_folds
from pipeline.campaign.shake_table_scores import write_scores
from pipeline.files import InputError
from pipeline.stats.forecast import reliability_with_ends
from tests.campaign.tiny_members_campaign import write_member_runs

Z = 1.959963984540054                 # the normal quantile of a two-sided 95 % interval


def wilson(k, n, z=Z):
    """The Wilson score interval, closed form (Wilson 1927)."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


def test_folds_are_blocks_of_whole_days_of_about_equal_size():
    days = ["2021-06-23", "2021-06-21", "2021-06-22", "2021-06-21", "2021-06-24",
            "2021-06-22", "2021-06-24", "2021-06-23"]
    # 2 tests a day, 2 folds: the first two days, then the last two
    assert list(date_folds(days, 2)) == [1, 0, 0, 0, 1, 0, 1, 1]
    # a day of 5 tests and three of 1: its middle test (2.5 of 8) is in the first half,
    # the next day's (5.5 of 8) in the second
    days = ["d1"] * 5 + ["d2", "d3", "d4"]
    days = [{"d1": "2021-06-21", "d2": "2021-06-22", "d3": "2021-06-23",
             "d4": "2021-06-24"}[d] for d in days]
    assert list(date_folds(days, 2)) == [0] * 5 + [1, 1, 1]
    assert list(date_folds(days, 1)) == [0] * 8


def test_a_day_is_never_split_and_folds_follow_the_calendar():
    rng = np.random.default_rng(3)
    days = pd.Timestamp("2021-06-01") + pd.to_timedelta(rng.integers(0, 40, 300), "D")
    folds = date_folds(days, 5)
    frame = pd.DataFrame({"day": days, "fold": folds})
    assert (frame.groupby("day")["fold"].nunique() == 1).all()
    by_day = frame.groupby("day")["fold"].first()
    assert (np.diff(by_day.to_numpy()) >= 0).all()
    assert sorted(set(folds)) == [0, 1, 2, 3, 4]
    assert frame["fold"].value_counts().max() <= 300 / 5 + frame.groupby("day").size().max()


def test_too_few_days_for_the_folds_is_refused():
    with pytest.raises(InputError, match="fill only 1 block"):
        date_folds(["2021-06-21"] * 6, 2)


def _candidate(fold0, fold1):
    """members.csv rows: (observed, P) of fold 0's then fold 1's tests, 8 runs each."""
    rows = [(f"A{k}", o, p) for k, (o, p) in enumerate(fold0)]
    rows += [(f"B{k}", o, p) for k, (o, p) in enumerate(fold1)]
    return pd.DataFrame({"test": [r[0] for r in rows], "observed": [r[1] for r in rows],
                         "P": [r[2] for r in rows], "runs": 8,
                         "date": ["2021-06-21" if r[0][0] == "A" else "2021-07-01"
                                  for r in rows]})


def test_the_best_worst_fold_wins_where_the_pooled_score_prefers_a_narrow_range():
    """Narrow: sure and right on fold 0's 20 tests, sure and once wrong on fold 1's 2;
    wide: 0.75 for what happened everywhere.  Pooled, narrow scores higher; its worst fold
    is far worse, so wide is chosen.  Cross-validated: fold 1 alone chooses wide (scored
    on fold 0), fold 0 alone chooses narrow (scored on fold 1)."""
    fold0 = [(k % 2 == 0, 1.0 if k % 2 == 0 else 0.0) for k in range(20)]
    narrow = _candidate(fold0, [(True, 1.0), (True, 0.0)])
    wide = _candidate([(o, 0.75 if o else 0.25) for o, _ in fold0], [(True, 0.75)] * 2)
    fold_of = {t: 0 if t[0] == "A" else 1 for t in narrow["test"]}
    sure, wrong, hedged = math.log(17 / 18), math.log(1 / 18), math.log(0.75)
    choice = choose_ranges([("footprint_tolerance_m=0.001:0.0011", narrow),
                            ("footprint_tolerance_m=0.001:0.003", wide)], fold_of)
    by = {c["ranges"]: c for c in choice["candidates"]}
    n = by["footprint_tolerance_m=0.001:0.0011"]
    assert n["log_likelihood_per_test"] == pytest.approx((21 * sure + wrong) / 22)
    assert n["per_fold_log_likelihood"] == pytest.approx([sure, (sure + wrong) / 2])
    assert n["log_likelihood_per_test"] > hedged          # pooled: narrow is better
    assert choice["chosen"] == "footprint_tolerance_m=0.001:0.003"
    first, second = choice["folds"]
    assert first["chosen_without"] == "footprint_tolerance_m=0.001:0.003"
    assert first["held_out"]["log_likelihood_per_test"] == pytest.approx(hedged)
    assert second["chosen_without"] == "footprint_tolerance_m=0.001:0.0011"
    assert second["held_out"]["log_likelihood_per_test"] == pytest.approx((sure + wrong) / 2)
    assert choice["cross_validated_log_likelihood_per_test"] == pytest.approx(
        (20 * hedged + (sure + wrong)) / 22)
    # fold 1's reliability (narrow): its P = 0 overturned, its P = 1 overturned
    p0, p1 = second["reliability"]
    assert (p0["label"], p0["n"], p0["overturned"]) == ("P = 0", 1, 1)
    assert p0["observed_ci95"] == pytest.approx([1 / (1 + Z * Z), 1.0])
    assert p0["mean_forecast_held"] == pytest.approx(1 / 18) and not p0["covers"]
    assert (p1["label"], p1["covers"]) == ("P = 1", True)


def test_reliability_bins_hold_the_certain_forecasts_apart():
    p = [0.0, 0.0, 0.0, 0.0, 0.05, 0.1, 0.125, 0.95, 0.999, 1.0]
    observed = [1, 0, 0, 0, 0, 0, 1, 1, 1, 1]
    rows = reliability_with_ends(observed, p, runs=[8] * 10)
    assert [r["label"] for r in rows] == ["P = 0", "(0, 0.1)", "[0.1, 0.2)", "[0.9, 1)",
                                          "P = 1"]
    assert [r["n"] for r in rows] == [4, 1, 2, 2, 1]
    zero = rows[0]
    assert zero["observed_rate"] == 0.25 and zero["mean_forecast"] == 0.0
    assert zero["observed_ci95"] == pytest.approx(wilson(1, 4), abs=1e-9)
    # held as for the log-likelihood: 1/(2 (8 + 1)) = 0.056, inside [0.046, 0.70]
    assert zero["mean_forecast_held"] == pytest.approx(1 / 18)
    assert zero["covers"] is True
    tenth = rows[2]
    assert tenth["mean_forecast"] == pytest.approx(0.1125) and tenth["overturned"] == 1
    assert tenth["observed_ci95"] == pytest.approx(wilson(1, 2), abs=1e-9)
    # without runs a P = 0 is held at 0.01 only, below the interval of 1 in 4
    assert reliability_with_ends(observed, p)[0]["covers"] is False


def test_the_scores_write_the_folds_table_and_diagram(tmp_path):
    frame = pd.read_csv(EXPERIMENTS, keep_default_na=False)
    frame = frame[frame["motion_file"] != ""].iloc[::7]
    k = (frame["pga_g"].to_numpy() > 0.3).astype(int) * 8
    per_test = pd.DataFrame({
        "test": frame["test"].to_numpy(), "date": frame["date"].to_numpy(),
        "split": np.where(frame["date"] < "2021-08-01", "calibration", "validation"),
        "pga_g": frame["pga_g"].to_numpy(), "pgv_pga_s": frame["pgv_pga_s"].to_numpy(),
        "observed": frame[OUTCOME].to_numpy().astype(bool), "runs": 8, "overturned": k,
        "P": k / 8, "ci95_low": 0.0, "ci95_high": 1.0, "single_set_predicted": k >= 4})
    calibration = per_test[per_test["split"] == "calibration"]
    fold_of = dict(zip(calibration["test"], date_folds(calibration["date"], 3)))
    choice = choose_ranges([("", calibration), ("kn=4e7:1e8", calibration.assign(P=0.5))],
                           fold_of)
    full = [SimpleNamespace(tags=SimpleNamespace(member=m, point={"m": m})) for m in (-1, 0)]
    options = {"specimen": SPECIMEN, "experiments": EXPERIMENTS, "outcome": OUTCOME,
               "validate_from": "2021-08-01", "members": 8, "axis_deg": 90.0}
    write_member_runs(tmp_path, per_test)
    write_scores(per_test, tmp_path, options, full, True, choice)
    table = pd.read_csv(tmp_path / "folds.csv")
    assert sorted(set(table["fold"])) == [0, 1, 2]
    assert table.groupby("fold")["n"].sum().sum() == len(calibration)
    assert set(table["bin"]) <= {"P = 0", "P = 1", "[0.5, 0.6)"}
    result = json.loads((tmp_path / "shake_table_members.json").read_text())
    assert len(result["ranges_choice"]["folds"]) == 3
    assert (tmp_path / "shake_table_folds_reliability.png").stat().st_size > 10_000


def test_folds_the_calibration_days_cannot_fill_are_refused_before_any_run(tmp_path, capsys):
    out = tmp_path / "out"
    code = cli.main(["campaign", "shake-table", "--members", "4", "--candidates",
                     "default|kn=4e7:1e8", "--tests", "Test011,Test012,Test693", "--folds",
                     "2", "--out", str(out), "--jobs", "1"])
    lines = [x for x in capsys.readouterr().err.splitlines() if not x.startswith("note:")]
    assert code == 2 and len(lines) == 1 and "--folds 2" in lines[0], lines
    assert not out.exists()


def test_the_driver_chooses_over_the_calibration_days_folds(tmp_path, monkeypatch):
    """The members mode's driver, its runs replaced by a P per test that is right for the
    'default' candidate and wrong for the other: the folds are the calibration tests' days
    (two blocks), the August test stays out of them, and the choice reaches the scores."""
    from pipeline.campaign import shake_table_members as stm
    from pipeline.campaign.shake_table import ShakeTableOptions
    tests = ["Test011", "Test012", "Test044", "Test075", "Test131", "Test178", "Test693"]
    options = {**ShakeTableOptions().kwargs(), "members": 2, "specimen": SPECIMEN,
               "tests": tests, "candidates": "default|yaw_deg=0:0", "folds": 2, "jobs": 1}

    def members(run, campaign_dir, opts, full, frame):
        right = not opts.get("ranges")
        rows = frame.assign(runs=2, overturned=0, ci95_low=0.0, ci95_high=1.0,
                            single_set_predicted=False)
        rows["P"] = np.where(rows["observed"] == right, 1.0, 0.0)
        return rows[["test", "date", "split", "pga_g", "pgv_pga_s", "observed", "runs",
                     "overturned", "P", "ci95_low", "ci95_high", "single_set_predicted"]], True
    written = {}
    monkeypatch.setattr(stm, "_members", members)
    monkeypatch.setattr(stm, "write_scores", lambda *args: written.update(choice=args[-1]))
    stm.drive(lambda o: None, [], tmp_path, options)
    choice = written["choice"]
    assert choice["chosen"] == ""
    days = [f["days"] for f in choice["folds"]]
    assert days == [["2021-06-21", "2021-06-23"], ["2021-06-25", "2021-07-06"]]
    assert sum(f["held_out"]["tests"] for f in choice["folds"]) == 6
    assert all(f["chosen_without"] is None for f in choice["folds"])
