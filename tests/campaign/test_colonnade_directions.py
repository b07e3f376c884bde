"""The colonnade-directions campaign: the same pulses along the row, across it and at
45 deg to it (the azimuths from the stylobate's axis), a still colonnade end to end
(a pulse below the columns' uplift: YADE is not started), its tables and REPORT section,
and refusals in one line."""
import json

import pandas as pd
import pytest

from pipeline import campaign, cli
from pipeline.campaign.colonnade_directions import DIRECTIONS, direction_table, row_azimuth_deg
from pipeline.files import InputError
from pipeline.scenario.colonnade_file import load, to_dict

WEAK = "pga_g=0.05:0.05:1;pgv_pga_s=0.3:0.3:1"      # below g tan(alpha) of every column


def test_the_directions_turn_with_the_row(tmp_path):
    data = to_dict(load("parthenon-north-flank"))
    assert row_azimuth_deg(data) == pytest.approx(90.0)          # laid along East
    turned = {**data, "stylobate": {**data["stylobate"], "start": [0.0, 0.0],
                                    "end": [1.0, 1.0]}}
    assert row_azimuth_deg(turned) == pytest.approx(45.0)
    specs = campaign.get("colonnade-directions").specs(
        [], tmp_path, pulses="pga_g=0.3:0.6:2;pgv_pga_s=0.3:0.3:1")
    assert len(specs) == 2 * len(DIRECTIONS)
    for spec in specs:
        angle = spec.tags.angle_from_row_deg
        assert spec.params.drive.rotate_deg == pytest.approx((90.0 + angle) % 360.0)
        assert spec.params.column.colonnade.name == "parthenon-north-flank"
    assert len({s.run_id for s in specs}) == len(specs)


@pytest.mark.parametrize("options, message", [
    ({"column_file": "doric-peristyle"}, "one column"),
    ({"pulses": "pga_g=0.3"}, "--pulses"),
])
def test_refused_in_one_line(tmp_path, options, message):
    with pytest.raises(InputError, match=message) as caught:
        campaign.get("colonnade-directions").specs([], tmp_path / "out", **options)
    assert "\n" not in str(caught.value)
    assert not (tmp_path / "out" / "runs").exists()


def test_direction_table_counts_by_hand():
    table = pd.DataFrame({
        "direction": ["in-plane", "in-plane", "out-of-plane", "out-of-plane", "oblique"],
        "azimuth_deg": [90.0, 90.0, 180.0, 180.0, 135.0], "pga_g": [0.4, 0.8, 0.4, 0.8, 0.4],
        "pgv_pga_s": 0.3, "columns": 4, "columns_fallen": [0, 1, 2, 4, 0]})
    out = direction_table(table).set_index("direction")
    assert list(out.index) == ["in-plane", "oblique", "out-of-plane"]
    assert out.loc["in-plane", ["runs", "runs_with_a_fall", "columns_fallen",
                                "columns_shaken"]].tolist() == [2, 1, 1, 8]
    assert out.loc["out-of-plane", "p_fall"] == 1.0 and out.loc["oblique", "p_fall"] == 0.0
    assert out.loc["out-of-plane", "fallen_per_pulse"] == \
        "0.4 g, 0.3 s: 2 of 4; 0.8 g, 0.3 s: 4 of 4"


def test_a_still_colonnade_end_to_end(tmp_path):
    out = tmp_path / "colonnade-directions"                  # the report's folder
    assert cli.main(["campaign", "colonnade-directions", "--pulses", WEAK, "--out", str(out),
                     "--jobs", "1", "--animations", "0"]) == 0
    done = json.loads((out / "campaign.json").read_text())
    assert not done["failed"]
    whole = pd.read_csv(out / "colonnades.csv")
    assert sorted(whole["direction"]) == sorted(d for d, _ in DIRECTIONS)
    assert (whole["columns_fallen"] == 0).all()
    directions = pd.read_csv(out / "directions.csv")
    assert (directions["runs"] == 1).all() and (directions["runs_with_a_fall"] == 0).all()
    assert (out / "colonnade_falls.png").exists()
    statistics = json.loads((out / "colonnade_statistics.json").read_text())
    assert statistics["grouped_by"] == "direction"
    assert [g["group"] for g in statistics["groups"]] == [d for d, _ in DIRECTIONS]
    from pipeline.report.colonnades import directions_section
    text = directions_section(tmp_path)
    row = next(line for line in text.splitlines() if line.startswith("| out-of-plane"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:4] == ["180", "1", "0 of 1"]
    assert "Not run yet" in directions_section(tmp_path / "nothing")
