"""The hidden-truth test: its file's checks, the strike frame of its sites, and one small
run through pyprop8, YADE and the inversion against a toy table."""
import json
import math

import numpy as np
import pytest

from pipeline import cli
from pipeline.files import InputError
from pipeline.inversion.grid import TableGrid
from pipeline.inversion.truth import check_hidden, parse_truth

SOURCE = {"mechanism": "strike-slip", "strike_deg": 30.0, "depth_km": 10.0, "mw": 6.5,
          "east_km": 0.0, "north_km": 0.0}


def test_sites_in_the_strike_frame():
    """A site due East of the epicentre of a source striking 30 deg lies 60 deg from the
    strike; due North, 330 deg."""
    truth = parse_truth({"source": SOURCE, "sites": [
        {"name": "E", "east_km": 5.0, "north_km": 0.0, "twins": 1},
        {"name": "N", "east_km": 0.0, "north_km": 3.0, "twins": 2}]})
    r, a = truth.strike_frame()
    assert np.allclose(r, [5.0, 3.0]) and np.allclose(a, [60.0, 330.0])
    t = truth.as_truth()           # from the first site (E) the epicentre lies due West
    assert t["back_azimuth_deg"] == pytest.approx(270.0) and t["distance_km"] == 5.0


@pytest.mark.parametrize("change, message", [
    ({"source": dict(SOURCE, mechanism="oblique")}, "mechanism must be one of"),
    ({"source": dict(SOURCE, mw=8.5)}, r"mw 8.5 outside the allowed range \[4.5, 7.5\]"),
    ({"sites": [{"name": "A", "east_km": 0.0, "north_km": 0.0, "twins": 1}]},
     "from the epicentre"),
    ({"sites": [{"name": "A", "east_km": 5.0, "north_km": 0.0, "twins": 0}]}, "twins"),
    ({"seed": -1}, "seed"),
    ({"colour": 1}, "unknown key"),
])
def test_bad_truth_files_are_one_line(change, message):
    data = {"source": SOURCE,
            "sites": [{"name": "A", "east_km": 5.0, "north_km": 0.0, "twins": 1}], **change}
    with pytest.raises(InputError, match=message):
        parse_truth(data)


def test_a_seed_the_table_used_is_refused():
    truth = parse_truth({"source": SOURCE, "seed": 20091002,
                         "sites": [{"name": "A", "east_km": 5.0, "north_km": 0.0, "twins": 1}]})
    with pytest.raises(InputError, match="would have seen these runs"):
        check_hidden(truth, TableGrid(members=12))          # batches 20091001, 20091002


@pytest.mark.yade
def test_hidden_truth_end_to_end_on_a_toy_table(make_away_table, tmp_path, capsys):
    """One site 4 km East of an Mw 6.5 strike-slip source, two twins: pyprop8, four column
    runs, observations.json and the inversion with the truth marked and checked."""
    table = make_away_table(members=6)
    path = tmp_path / "forward_table_toy.npz"
    table.save(path)
    truth_file = tmp_path / "truth.json"
    truth_file.write_text(json.dumps({"source": dict(SOURCE, east_km=-4.0), "sites": [
        {"name": "A", "east_km": 0.0, "north_km": 0.0, "twins": 2}]}))
    out = tmp_path / "out"
    assert cli.main(["invert", "--hidden-truth", str(truth_file), "--table", str(path),
                     "--quick", "--duration", "6", "--fmax", "2", "--radius", "10",
                     "--jobs", "2", "--out", str(out)]) == 0
    observations = json.loads((out / "observations.json").read_text())
    columns = observations["sites"][0]["columns"]
    assert sorted(c["column"] for c in columns) == ["drums", "drums", "monolithic",
                                                    "monolithic"]
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert summary["truth"]["back_azimuth_deg"] == pytest.approx(270.0)
    assert set(summary["truth"]["check"]) >= {"epicentre_in_95", "back_azimuth_in_95",
                                              "mw_in_95", "map_epicentre_error_km",
                                              "within_reach", "reach_warning",
                                              "epicentre_in_95_or_warned"}
    assert summary["truth"]["check"]["within_reach"]       # 4 km: within the 20 km rings
    assert math.isfinite(summary["truth"]["check"]["map_epicentre_error_km"])
    assert "simulated columns fell" in capsys.readouterr().out
