"""The colonnade-directions campaign: the same pulses along the row, across it and at
45 deg to it (the azimuths from the stylobate's axis), its members (seeded, each drawn on
its own: more members keep the runs done), a still colonnade end to end (a pulse below
the columns' uplift: YADE is not started) with members and resumed, its tables and REPORT
section, and refusals in one line with nothing written."""
import json

import pandas as pd
import pytest

from pipeline import campaign, cli
from pipeline.campaign.colonnade_directions import DIRECTIONS, direction_table, row_azimuth_deg
from pipeline.files import InputError
from pipeline.scenario.colonnade_file import load, to_dict
from tests.refusal import refused

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


def test_members_are_seeded_and_more_of_them_keep_the_runs_done(tmp_path):
    get = campaign.get("colonnade-directions").specs
    pulses = "pga_g=0.3:0.3:1;pgv_pga_s=0.3:0.3:1"
    nominal = get([], tmp_path, pulses=pulses)
    assert [s.tags.member for s in nominal] == [-1] * 3
    three = get([], tmp_path, pulses=pulses, members=3)
    assert len(three) == 9 and len({s.run_id for s in three}) == 9
    assert not {s.run_id for s in three} & {s.run_id for s in nominal}
    for direction, _ in DIRECTIONS:            # the same members in every direction
        mine = [s for s in three if s.tags.direction == direction]
        assert [s.tags.member for s in mine] == [0, 1, 2]
        assert len({s.params.contact.mu_s for s in mine}) == 3
    first = [s for s in three if s.tags.direction == "in-plane"]
    assert [s.params.contact.mu_s for s in first] == \
        [s.params.contact.mu_s for s in three if s.tags.direction == "out-of-plane"]
    four = get([], tmp_path, pulses=pulses, members=4)
    assert {s.run_id for s in three} < {s.run_id for s in four}           # resumable
    assert [s.run_id for s in get([], tmp_path, pulses=pulses, members=3)] == \
        [s.run_id for s in three]
    other = get([], tmp_path, pulses=pulses, members=3, seed=1)
    assert not {s.run_id for s in other} & {s.run_id for s in three}


@pytest.mark.parametrize("flags, words", [
    (["--members", "-1"], "--members"), (["--members", "1001"], "--members"),
    (["--seed", "-3"], "--seed"),
    (["--pulses", "pga_g=0.3:0.2:2;pgv_pga_s=0.3:0.3:1"], "--pulses"),
])
def test_options_out_of_range_refused_with_nothing_written(flags, words, tmp_path, capsys):
    out = tmp_path / "out"
    refused(capsys, ["campaign", "colonnade-directions", *flags, "--out", out], words, out)


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
    members = pd.concat([table, table.assign(columns_fallen=[1, 0, 0, 4, 3])])
    again = direction_table(members).set_index("direction")     # two runs of each pulse
    assert again.loc["out-of-plane", "fallen_per_pulse"] == \
        "0.4 g, 0.3 s: 2 of 8; 0.8 g, 0.3 s: 8 of 8"
    assert again.loc["in-plane", ["runs", "runs_with_a_fall"]].tolist() == [4, 2]


def test_a_still_colonnade_with_members_end_to_end_and_resumed(tmp_path, capsys):
    out = tmp_path / "members"
    argv = ["campaign", "colonnade-directions", "--pulses", WEAK, "--out", str(out),
            "--jobs", "1", "--animations", "0", "--members", "2"]
    assert cli.main(argv) == 0
    whole = pd.read_csv(out / "colonnades.csv")
    assert sorted(whole["member"]) == [0, 0, 0, 1, 1, 1]
    from pipeline.stats.colonnade_directions import DirectionStatistics
    cases = DirectionStatistics.load(out).cases
    assert [c.direction for c in cases] == [d for d, _ in DIRECTIONS]
    assert all(c.runs == 2 and c.fallen[0].count == 2 and c.pga_g == 0.05 for c in cases)
    capsys.readouterr()
    assert cli.main(argv) == 0
    assert "6 already done, 0 to run" in capsys.readouterr().out
    from pipeline.report.colonnades import directions_section
    text = directions_section(tmp_path, "members")
    assert "2 members per pulse and direction" in text and "colonnade_falls.png" in text
    row = [line for line in text.splitlines() if line.startswith("| oblique ")][-1]
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:5] == ["0.05", "0.3", "2", "1.00 [0.34, 1.00]"]    # 2 of 2 stood, Wilson


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
