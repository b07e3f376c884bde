"""The statistics of a colonnade's runs (``colonnade_statistics.json``, beside a campaign's
``colonnades.csv``): per record (and over all records when there are several), or per
group of another column of the table (a direction of shaking), the
probability that k of its n columns fell, k = 0..n, whether the fallen columns fell
parallel given that at least two fell, and whether they fell in sequence (given at least
three, and of all runs), each a proportion with its Wilson 95 % interval, the Monte Carlo
error of a probability from that many runs.  An ensemble's nominal run (member -1) is not
a sample and is left out, as in ``ensemble_summary.json``.

:class:`ColonnadeStatistics` is the one type: built from the table by :meth:`of`,
written by :meth:`save`, read only by :meth:`load`.
"""
import math
from dataclasses import dataclass

from pipeline.files import InputError, csv_true
from pipeline.stats.colonnade_counts import FallCounts, Proportion, WilsonFile

FILE = "colonnade_statistics.json"
ALL_RECORDS = "all records"


@dataclass(frozen=True, kw_only=True)
class GroupStatistics(FallCounts):
    """A colonnade of ``columns`` columns over ``runs`` runs of one ``group`` (a record,
    :data:`ALL_RECORDS`, or a direction of shaking): ``fallen`` the runs with k columns
    fallen, k = 0..columns (a :class:`~pipeline.stats.colonnade_counts.Proportion` of the
    runs each), ``parallel`` of the runs in which at least two fell with azimuths,
    ``in_sequence`` of the runs in which at least three fell with impact times,
    ``in_sequence_of_all`` the same count of all runs."""
    colonnade: str
    group: str
    parallel: Proportion
    in_sequence: Proportion
    in_sequence_of_all: Proportion

    def __post_init__(self):
        super().__post_init__()
        where = self.where()
        if self.parallel.of > sum(f.count for f in self.fallen[2:]):
            raise InputError(f"{where}: parallel of {self.parallel.of} runs, more than "
                             "those in which two or more columns fell")
        if self.in_sequence.of > sum(f.count for f in self.fallen[3:]):
            raise InputError(f"{where}: in sequence of {self.in_sequence.of} runs, more "
                             "than those in which three or more columns fell")
        if (self.in_sequence_of_all.count, self.in_sequence_of_all.of) != \
                (self.in_sequence.count, self.runs):
            raise InputError(f"{where}: in_sequence_of_all must count the runs in "
                             "sequence of all runs")

    def where(self):
        return f"{self.colonnade}, {self.group}"

    def to_json(self):
        return {"colonnade": self.colonnade, "group": self.group, **self.counts_json(),
                "parallel_given_two_fell": self.parallel.to_json(),
                "in_sequence_given_three_fell": self.in_sequence.to_json(),
                "in_sequence": self.in_sequence_of_all.to_json()}

    @classmethod
    def own_from_json(cls, data):
        return {"colonnade": str(data.get("colonnade")), "group": str(data.get("group")),
                "parallel": Proportion.from_json(data.get("parallel_given_two_fell"),
                                                 "parallel_given_two_fell"),
                "in_sequence": Proportion.from_json(data.get("in_sequence_given_three_fell"),
                                                    "in_sequence_given_three_fell"),
                "in_sequence_of_all": Proportion.from_json(data.get("in_sequence"),
                                                           "in_sequence")}


@dataclass(frozen=True)
class ColonnadeStatistics(WilsonFile):
    """``groups``: a :class:`GroupStatistics` per colonnade and group (record, or
    ``grouped_by``'s value), then per colonnade over all its records when it ran under
    several (``pooled``)."""
    FILE, ITEMS, ITEM = FILE, "groups", GroupStatistics
    groups: tuple
    grouped_by: str = "record_id"

    def __post_init__(self):
        object.__setattr__(self, "groups", tuple(self.groups))
        if not all(isinstance(g, GroupStatistics) for g in self.groups):
            raise InputError("colonnade statistics: groups must be GroupStatistics")
        if not isinstance(self.grouped_by, str) or not self.grouped_by:
            raise InputError("colonnade statistics: grouped_by must name a column")

    @classmethod
    def of(cls, table, by="record_id", pooled=ALL_RECORDS):
        """The statistics of ``table``, rows as colonnades.csv holds them (a DataFrame
        with colonnade, ``by``, columns, columns_fallen, parallel, in_sequence; an
        ensemble's with member, its nominal run -1 left out), grouped by ``by``, and
        over all groups as ``pooled`` (None: not) when there are several."""
        rows = table if "member" not in table else table[table["member"] >= 0]
        groups = []
        for name in dict.fromkeys(rows["colonnade"]):
            sub = rows[rows["colonnade"] == name]
            keys = list(dict.fromkeys(sub[by]))
            for key in keys:
                groups.append(_group(name, key, sub[sub[by] == key]))
            if len(keys) > 1 and pooled is not None:
                groups.append(_group(name, pooled, sub))
        return cls(tuple(groups), by)

    def head_json(self):
        return {"grouped_by": self.grouped_by}

    @classmethod
    def from_items(cls, items, data):
        return cls(items, data.get("grouped_by", "record_id"))


def _group(name, group, rows):
    """The :class:`GroupStatistics` of the colonnade ``name``'s ``rows`` (one group's,
    or all)."""
    parallel = [csv_true(v) for v in rows["parallel"] if _known(v)]
    sequence = [csv_true(v) for v in rows["in_sequence"] if _known(v)]
    in_sequence = sum(sequence)
    return GroupStatistics.counted(
        rows, f"colonnade {name}", colonnade=str(name), group=str(group),
        parallel=Proportion(sum(parallel), len(parallel)),
        in_sequence=Proportion(in_sequence, len(sequence)),
        in_sequence_of_all=Proportion(in_sequence, len(rows)))


def _known(value):
    """Whether a parallel or in_sequence cell holds a value (not None, NaN or empty)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return False
    return not (isinstance(value, str) and not value.strip())
