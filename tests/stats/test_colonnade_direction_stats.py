"""P(k columns fall) per direction and pulse (direction_statistics.json) against a
hand-counted directions table, Wilson intervals from their closed form, and the file's
one writer and reader (a stated p that its counts do not give is refused)."""
import json

import pandas as pd
import pytest

from pipeline.files import InputError
from pipeline.stats.colonnade import ColonnadeStatistics
from pipeline.stats.colonnade_counts import Proportion
from pipeline.stats.colonnade_directions import FILE, DirectionStatistics, PulseFalls
from tests.stats.test_colonnade_stats import wilson

# a row of 3 columns, two members per direction and pulse; by hand (k = 0 1 2 3):
#   in-plane 0.3 g: 1 0 1 0   in-plane 0.6 g: 0 0 0 2   out-of-plane 0.3 g: 0 1 0 1
ROWS = [("in-plane", 0.0, 90.0, 0.3, 0), ("in-plane", 0.0, 90.0, 0.3, 2),
        ("in-plane", 0.0, 90.0, 0.6, 3), ("in-plane", 0.0, 90.0, 0.6, 3),
        ("out-of-plane", 90.0, 180.0, 0.3, 1), ("out-of-plane", 90.0, 180.0, 0.3, 3)]
TABLE = pd.DataFrame(ROWS, columns=["direction", "angle_from_row_deg", "azimuth_deg",
                                    "pga_g", "columns_fallen"]).assign(
    pgv_pga_s=0.3, columns=3, colonnade="row", member=[0, 1] * 3)
HAND = {("in-plane", 0.3): [1, 0, 1, 0], ("in-plane", 0.6): [0, 0, 0, 2],
        ("out-of-plane", 0.3): [0, 1, 0, 1]}


def _check(statistics):
    assert statistics.colonnade == "row"
    assert [(c.direction, c.pga_g) for c in statistics.cases] == list(HAND)
    for case in statistics.cases:
        counts = HAND[(case.direction, case.pga_g)]
        assert case.runs == 2 and case.columns == 3 and case.pgv_pga_s == 0.3
        assert [(f.count, f.of) for f in case.fallen] == [(k, 2) for k in counts]
        for f in case.fallen:
            assert f.p == pytest.approx(f.count / 2)
            assert f.ci95 == pytest.approx(wilson(f.count, 2), abs=1e-9)
    assert statistics.cases[2].azimuth_deg == 180.0


def test_hand_counted_directions_table():
    _check(DirectionStatistics.of(TABLE))


def test_written_and_read_back(tmp_path):
    DirectionStatistics.of(TABLE).save(tmp_path)
    _check(DirectionStatistics.load(tmp_path))
    data = json.loads((tmp_path / FILE).read_text())
    data["cases"][0]["fallen"][0]["p"] = 0.25          # 1 of 2 is 0.5
    (tmp_path / FILE).write_text(json.dumps(data))
    with pytest.raises(InputError, match="are not those of 1 of 2") as caught:
        DirectionStatistics.load(tmp_path)
    assert "\n" not in str(caught.value)


def test_inconsistent_cases_refused():
    with pytest.raises(InputError, match="add up to the 2 runs"):
        PulseFalls(direction="in-plane", angle_from_row_deg=0.0, azimuth_deg=90.0,
                   pga_g=0.3, pgv_pga_s=0.3, columns=1, runs=2,
                   fallen=[Proportion(1, 2), Proportion(0, 2)])
    with pytest.raises(InputError, match="azimuth_deg 360.0 outside"):
        PulseFalls(direction="in-plane", angle_from_row_deg=0.0, azimuth_deg=360.0,
                   pga_g=0.3, pgv_pga_s=0.3, columns=1, runs=1,
                   fallen=[Proportion(1, 1), Proportion(0, 1)])
    with pytest.raises(InputError, match="one colonnade"):
        DirectionStatistics.of(TABLE.assign(colonnade=["a", "b"] * 3))


def test_one_pulse_per_direction_counts_as_the_statistics_grouped_by_direction():
    """Both files count P(k columns fall) by one rule: with one pulse per direction the
    cases and the groups by direction hold the same counts."""
    one_pulse = TABLE[TABLE["pga_g"] == 0.3].assign(parallel=None, in_sequence=None)
    cases = DirectionStatistics.of(one_pulse).cases
    groups = ColonnadeStatistics.of(one_pulse, by="direction", pooled=None).groups
    assert [c.direction for c in cases] == [g.group for g in groups]
    assert [c.fallen for c in cases] == [g.fallen for g in groups]
    assert [c.counts_json() for c in cases] == [g.counts_json() for g in groups]
    assert [[f.count for f in c.fallen] for c in cases] == [[1, 0, 1, 0], [0, 1, 0, 1]]
