"""A colonnade's runs as probabilities (colonnade_statistics.json) against hand-counted toy
tables, Wilson intervals from their closed form, and the file's one writer and reader."""
import json
import math

import pandas as pd
import pytest
from scipy import stats

from pipeline.files import InputError
from pipeline.stats.colonnade import ALL_RECORDS, FILE, ColonnadeStatistics, GroupStatistics
from pipeline.stats.colonnade_counts import Proportion

NAN = math.nan
# colonnade "row" of 4 columns; record A's nominal run (member -1) would change every count
TOY = pd.DataFrame(
    [("A", -1, 4, True, True), ("A", 0, 0, NAN, NAN), ("A", 1, 2, True, NAN),
     ("A", 2, 4, False, True), ("A", 3, 3, True, False), ("A", 4, 2, False, NAN),
     ("B", 0, 1, NAN, NAN), ("B", 1, 4, True, True)],
    columns=["record_id", "member", "columns_fallen", "parallel", "in_sequence"]).assign(
        colonnade="row", columns=4)
# by hand: A  k = 0 1 2 3 4 -> 1 0 2 1 1 of 5; parallel 2 of 4; in sequence 1 of 2, 1 of 5
#          B  k -> 0 1 0 0 1 of 2; parallel 1 of 1; in sequence 1 of 1, 1 of 2
#          all (7 runs) -> 1 1 2 1 2; parallel 3 of 5; in sequence 2 of 3, 2 of 7
HAND = {"A": ([1, 0, 2, 1, 1], (2, 4), (1, 2), (1, 5)),
        "B": ([0, 1, 0, 0, 1], (1, 1), (1, 1), (1, 2)),
        ALL_RECORDS: ([1, 1, 2, 1, 2], (3, 5), (2, 3), (2, 7))}


def wilson(k, n, z=stats.norm.ppf(0.975)):
    """The Wilson score interval's closed form."""
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


def _check(statistics):
    assert [(g.colonnade, g.group) for g in statistics.groups] == \
        [("row", "A"), ("row", "B"), ("row", ALL_RECORDS)]
    for g in statistics.groups:
        fallen, parallel, sequence, sequence_all = HAND[g.group]
        runs = sum(fallen)
        assert g.runs == runs and g.columns == 4
        assert [(f.count, f.of) for f in g.fallen] == [(k, runs) for k in fallen]
        assert [f.p for f in g.fallen] == pytest.approx([k / runs for k in fallen])
        assert (g.parallel.count, g.parallel.of) == parallel
        assert (g.in_sequence.count, g.in_sequence.of) == sequence
        assert (g.in_sequence_of_all.count, g.in_sequence_of_all.of) == sequence_all
        for q in (*g.fallen, g.parallel, g.in_sequence, g.in_sequence_of_all):
            assert q.ci95 == pytest.approx(wilson(q.count, q.of), abs=1e-9)


def test_hand_counted_toy_table():
    _check(ColonnadeStatistics.of(TOY))


def test_the_table_as_colonnades_csv_holds_it(tmp_path):
    TOY.to_csv(tmp_path / "colonnades.csv", index=False)
    _check(ColonnadeStatistics.of(pd.read_csv(tmp_path / "colonnades.csv")))


def test_a_campaign_without_members_counts_every_run_and_one_record_is_not_pooled():
    one = TOY[TOY["record_id"] == "B"].drop(columns="member")
    (group,) = ColonnadeStatistics.of(one).groups
    assert group.group == "B" and [f.count for f in group.fallen] == [0, 1, 0, 0, 1]


def test_written_and_read_back(tmp_path):
    statistics = ColonnadeStatistics.of(TOY)
    statistics.save(tmp_path)
    assert ColonnadeStatistics.load(tmp_path) == statistics
    data = json.loads((tmp_path / FILE).read_text())
    assert data["groups"][0]["fallen"][2] == {"k": 2, "count": 2, "of": 5, "p": 0.4,
                                              "ci95": pytest.approx(list(wilson(2, 5)))}


@pytest.mark.parametrize("edit, message", [
    (lambda g: g["fallen"][0].update(p=0.9), "are not those of 1 of 5"),
    (lambda g: g["fallen"].pop(), "4 counts of columns fallen"),
    (lambda g: g["parallel_given_two_fell"].update(of=9, p=2 / 9,
                                                   ci95=list(wilson(2, 9))),
     "more than those in which two or more"),
    (lambda g: g["fallen"][1].update(k=7), "k must run 0, 1"),
])
def test_a_file_that_disagrees_with_itself_is_refused_in_one_line(tmp_path, edit, message):
    ColonnadeStatistics.of(TOY).save(tmp_path)
    data = json.loads((tmp_path / FILE).read_text())
    edit(data["groups"][0])
    (tmp_path / FILE).write_text(json.dumps(data))
    with pytest.raises(InputError, match=message) as caught:
        ColonnadeStatistics.load(tmp_path / FILE)
    assert "\n" not in str(caught.value)


def test_counts_are_checked_on_construction():
    with pytest.raises(InputError, match="more than there are"):
        Proportion(3, 2)
    runs = [Proportion(1, 2), Proportion(0, 2)]
    with pytest.raises(InputError, match="do not add up"):
        GroupStatistics(colonnade="row", group="A", columns=1, runs=2, fallen=runs,
                         parallel=Proportion(0, 0), in_sequence=Proportion(0, 0),
                         in_sequence_of_all=Proportion(0, 2))
    with pytest.raises(InputError, match="runs must be a count >= 1"):
        GroupStatistics(colonnade="row", group="A", columns=1, runs=0,
                        fallen=[Proportion(0, 0), Proportion(0, 0)],
                        parallel=Proportion(0, 0), in_sequence=Proportion(0, 0),
                        in_sequence_of_all=Proportion(0, 0))


def test_grouped_by_another_column_without_pooling():
    """A direction of shaking as the group: each direction its own counts, none pooled."""
    table = TOY.assign(direction=["in", "in", "in", "across", "across", "across", "in",
                                  "across"]).drop(columns="member")
    statistics = ColonnadeStatistics.of(table, by="direction", pooled=None)
    assert statistics.grouped_by == "direction"
    assert [(g.group, [f.count for f in g.fallen]) for g in statistics.groups] == \
        [("in", [1, 1, 1, 0, 1]), ("across", [0, 0, 1, 1, 2])]
