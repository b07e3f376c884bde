"""The REPORT section of the members mode: the scores it quotes are the file's, and its
verdict on the held-out tests follows from them, and where the members and the laboratory
disagree is read from disagreements.csv (files written here, not by a run)."""
import json
import math

from scipy.stats import norm

from pipeline.campaign.shake_table_disagreements import FIGURE, write_disagreements
from pipeline.report.shake_table_scores import (FULL, QUICK, HELD_OUT_ACCURACY_GOAL,
                                                shake_table_scores_section)
from tests.campaign.tiny_members_campaign import member_run, write_campaign


def _scores(ll, brier, accuracy):
    return {"log_likelihood_per_test": ll, "brier": brier, "reliability": 0.01,
            "resolution": 0.05, "uncertainty": 0.2, "accuracy": accuracy,
            "balanced_accuracy": accuracy}


def _write(results, name, members_accuracy, provider_ll, provider_brier):
    validation = {"tests": 10, "member_runs": 40,
                  "members": _scores(-0.312, 0.0734, members_accuracy),
                  "single_set": _scores(-0.40, 0.08, 0.9),
                  "providers": {"kn1": _scores(provider_ll, provider_brier, 0.9)}}
    (results / name).mkdir(parents=True)
    (results / name / "shake_table_members.json").write_text(json.dumps(
        {"specimen": "SP1", "members": 8, "runs": 50, "validate_from": "2021-08-01",
         "splits": {"validation": validation}}))


def test_not_run_yet_names_the_command(tmp_path):
    text = shake_table_scores_section(tmp_path, FULL)
    assert "Not run yet" in text and "make shake-table-scores" in text
    assert "make run-all" in shake_table_scores_section(tmp_path, QUICK)


def test_quotes_the_files_scores_and_judges_the_held_out_tests(tmp_path):
    _write(tmp_path, FULL, members_accuracy=0.95, provider_ll=-0.2, provider_brier=0.06)
    text = shake_table_scores_section(tmp_path, FULL)
    assert "-0.312" in text and "0.073" in text
    # the provider has the better log-likelihood: not beaten, and named
    assert "better than those of 1 of the 2 other forecasts (not: the providers' kn1)" in text
    assert f"0.950, at or above the {HELD_OUT_ACCURACY_GOAL:.2f}" in text


def test_an_accuracy_under_the_goal_is_said(tmp_path):
    _write(tmp_path, QUICK, members_accuracy=0.8, provider_ll=-0.9, provider_brier=0.09)
    text = shake_table_scores_section(tmp_path, QUICK)
    assert "(reduced)" in text and "2 of the 2 other forecasts" in text
    assert "0.800, below the" in text


def test_the_candidate_ranges_are_quoted_with_the_chosen_marked(tmp_path):
    _write(tmp_path, FULL, members_accuracy=0.95, provider_ll=-0.2, provider_brier=0.06)
    path = tmp_path / FULL / "shake_table_members.json"
    summary = json.loads(path.read_text())
    summary["ranges_choice"] = {"chosen": "kn=4e7:1.2e9", "candidates": [
        {"ranges": None, "tests": 259, "member_runs": 1268, "log_likelihood_per_test": -0.5641,
         "brier": 0.2043, "accuracy": 0.7992},
        {"ranges": "kn=4e7:1.2e9", "tests": 259, "member_runs": 1300,
         "log_likelihood_per_test": -0.4987, "brier": 0.1811, "accuracy": 0.8301}]}
    path.write_text(json.dumps(summary))
    text = shake_table_scores_section(tmp_path, FULL)
    rows = [line for line in text.splitlines() if "-0.564" in line or "-0.499" in line]
    assert len(rows) == 2
    assert "default" in rows[0] and "yes" not in rows[0]
    assert "kn=4e7:1.2e9" in rows[1] and "yes" in rows[1] and "0.83 " in rows[1]


def test_the_folds_are_quoted_with_the_bins_their_interval_misses(tmp_path):
    _write(tmp_path, FULL, members_accuracy=0.95, provider_ll=-0.2, provider_brier=0.06)
    path = tmp_path / FULL / "shake_table_members.json"
    summary = json.loads(path.read_text())
    held = {"tests": 58, "log_likelihood_per_test": -0.4321, "brier": 0.15, "accuracy": 0.81}
    summary["ranges_choice"] = {
        "chosen": None, "cross_validated_log_likelihood_per_test": -0.4567,
        "candidates": [{"ranges": None, "tests": 259, "member_runs": 1268,
                        "log_likelihood_per_test": -0.5641, "brier": 0.2043,
                        "accuracy": 0.7992, "worst_fold_log_likelihood": -0.7777}],
        "folds": [{"fold": 0, "days": ["2021-06-21", "2021-06-25"], "chosen_without": None,
                   "held_out": held,
                   "reliability": [{"label": "P = 0", "covers": False},
                                   {"label": "P = 1", "covers": True}]}]}
    path.write_text(json.dumps(summary))
    text = shake_table_scores_section(tmp_path, FULL)
    assert "-0.778" in text and "-0.457 per test" in text
    row = [line for line in text.splitlines() if "-0.432" in line]
    assert len(row) == 1 and "2021-06-21 to 2021-06-25" in row[0]
    assert row[0].rstrip(" |").endswith("P = 0")


def test_the_disagreements_are_quoted_from_their_file_with_the_figure(tmp_path):
    """The section quotes disagreements.csv: its regions' counts, each error rate's
    Wilson interval (closed form), the summary's lines, and shows the figure."""
    _write(tmp_path, QUICK, members_accuracy=0.8, provider_ll=-0.9, provider_brier=0.09)
    directory = tmp_path / QUICK
    slid = member_run(tilt_deg=0.1, residual_slide_m=0.005)
    toppled = member_run(toppled=True, tilt_deg=90.0, residual_slide_m=0.2)
    write_campaign(directory, [
        {"test": "Test001", "date": "2021-07-13", "split": "calibration", "pga_g": 0.15,
         "pgv_pga_s": 0.1, "observed": True, "runs": [slid, slid]},
        {"test": "Test002", "date": "2021-07-13", "split": "calibration", "pga_g": 0.12,
         "pgv_pga_s": 0.1, "observed": False, "runs": [toppled, toppled]},
        {"test": "Test003", "date": "2021-08-13", "split": "validation", "pga_g": 0.18,
         "pgv_pga_s": 0.1, "observed": False, "runs": [slid, slid]}])
    write_disagreements(directory, "tiny")
    text = shake_table_scores_section(tmp_path, QUICK)
    assert f"]({QUICK}/{FIGURE})" in text
    k, n, z = 2, 3, norm.ppf(0.975)
    centre = (k / n + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(k / n * (1 - k / n) / n + z * z / (4 * n * n))
    row = next(line for line in text.splitlines() if "| PGA (g) 0.1-0.2" in line)
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:4] == ["3", "2", f"0.67 [{centre - half:.2f}, {centre + half:.2f}]"]
    assert cells[4:] == ["1", "1"]                   # one missed, one false overturn
    assert "wrong on 2 of 3" in text and "missed overturns (1 test): members mostly " \
        "sliding in 1" in text
