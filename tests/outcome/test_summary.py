"""RunSummary and ColumnOutcome: what a run's summary.json holds, validated on the way in
and the same on the way out."""
import json

import pytest

from pipeline.files import InputError
from pipeline.outcome.columns import column_outcomes, summarise
from pipeline.outcome.summary import ColumnOutcome, RunSummary


def test_a_simulated_run_round_trips_through_its_file(tmp_path, make_lying_trajectory):
    """summarise() of a column lying toward 70 deg: the file written holds the keys
    summary.json always had, and loading it gives the same summary back."""
    traj = make_lying_trajectory(70.0)
    summary = summarise(traj, "R1", back_azimuth_deg=200.0, parameters={"hd": 6.0},
                        provenance={"code": "x"})
    path = summary.save(tmp_path / "summary.json")
    data = json.loads(path.read_text())
    assert list(data)[:4] == ["record", "back_azimuth_deg", "parameters", "columns"]
    assert {"simulated", "simulated_s", "simulated_window_s", "motion_end_s",
            "stopped_early", "time_step_s", "wall_s", "provenance"} <= set(data)
    assert "note" not in data and "quiet_after_s" not in data      # written only when set
    assert data["columns"] == [dict(c) for c in column_outcomes(traj)]
    again = RunSummary.load(tmp_path)
    assert again == summary
    (col,) = again.columns
    assert col.toppled and col.downfall_azimuth_deg == pytest.approx(70.0, abs=1.0)
    assert again.column(col.column) is col


def test_a_run_yade_never_ran_stands_everywhere():
    summary = RunSummary.still("R2", [{"name": "drums", "x": -1.0, "y": 0.0},
                                      {"name": "monolithic", "x": 1.0, "y": 0.0}],
                               note="quiet", motion_end_s=12.0)
    assert not summary.simulated and summary.note == "quiet"
    assert [(c.column, c.toppled, c.position_m) for c in summary.columns] == \
        [("drums", False, [-1.0, 0.0]), ("monolithic", False, [1.0, 0.0])]
    assert summary.to_dict()["note"] == "quiet"


@pytest.mark.parametrize("column, message", [
    ({"column": "drums", "toppled": False, "downfall_azimuth_deg": 10.0}, "not toppled"),
    ({"column": "drums", "toppled": True, "downfall_azimuth_deg": 360.0}, "[0, 360)"),
    ({"column": "drums", "toppled": "yes"}, "true or false"),
    ({"column": "drums", "toppled": False, "max_tilt_deg": -1.0}, "max_tilt_deg"),
])
def test_an_impossible_column_is_refused(column, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace(")", r"\)")):
        ColumnOutcome(**column)


def test_a_file_that_is_no_run_summary_gives_one_line_naming_it(tmp_path):
    assert RunSummary(record="a", back_azimuth_deg=float("nan")).back_azimuth_deg is None
    cases = {"missing": None, "garbage": "{", "list": "[]", "stranger": '{"record": "a", "x": 1}',
             "twice": json.dumps({"record": "a", "columns": [{"column": "d", "toppled": False}] * 2}),
             "bad_wall": '{"record": "a", "wall_s": -1}'}
    for name, text in cases.items():
        path = tmp_path / name / "summary.json"
        if text is not None:
            path.parent.mkdir()
            path.write_text(text)
        with pytest.raises(InputError) as info:
            RunSummary.load(path)
        assert str(path) in str(info.value) and "\n" not in str(info.value)
