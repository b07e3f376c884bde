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

from pipeline.files import InputError, csv_true, read_run_json, write_json
from pipeline.stats.ensemble import wilson_interval

FILE = "colonnade_statistics.json"
ALL_RECORDS = "all records"
CONFIDENCE = 0.95
_TOLERANCE = 1e-9            # a stated probability or interval bound against its counts


@dataclass(frozen=True)
class Proportion:
    """``count`` runs of ``of``: the fraction (None without runs) and its Wilson 95 %
    interval ([0, 1] without runs)."""
    count: int
    of: int

    def __post_init__(self):
        for key in ("count", "of"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InputError(f"{key} must be a count, got {value!r}")
        if self.count > self.of:
            raise InputError(f"count {self.count} of {self.of}: more than there are")

    @property
    def p(self):
        return self.count / self.of if self.of else None

    @property
    def ci95(self):
        return wilson_interval(self.count, self.of, CONFIDENCE)

    def to_json(self):
        return {"count": self.count, "of": self.of, "p": self.p, "ci95": self.ci95}

    @classmethod
    def from_json(cls, data, where):
        if not isinstance(data, dict):
            raise InputError(f"{where} must be an object")
        try:
            out = cls(data.get("count"), data.get("of"))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        stated = [data.get("p"), *(data.get("ci95") or [None, None])]
        for value, own in zip(stated, [out.p, *out.ci95]):
            if (value is None) != (own is None) or (
                    own is not None and not abs(float(value) - own) <= _TOLERANCE):
                raise InputError(f"{where}: p and ci95 {stated} are not those of "
                                 f"{out.count} of {out.of}")
        return out


@dataclass(frozen=True, kw_only=True)
class GroupStatistics:
    """A colonnade of ``columns`` columns over ``runs`` runs of one ``group`` (a record,
    :data:`ALL_RECORDS`, or a direction of shaking): ``fallen`` the runs with k columns fallen, k = 0..columns (a
    :class:`Proportion` of the runs each), ``parallel`` of the runs in which at least two
    fell with azimuths, ``in_sequence`` of the runs in which at least three fell with
    impact times, ``in_sequence_of_all`` the same count of all runs."""
    colonnade: str
    group: str
    columns: int
    runs: int
    fallen: tuple
    parallel: Proportion
    in_sequence: Proportion
    in_sequence_of_all: Proportion

    def __post_init__(self):
        object.__setattr__(self, "fallen", tuple(self.fallen))
        where = f"{self.colonnade}, {self.group}"
        if isinstance(self.columns, bool) or not isinstance(self.columns, int) or \
                self.columns < 1:
            raise InputError(f"{where}: columns must be a count >= 1, got {self.columns!r}")
        if len(self.fallen) != self.columns + 1:
            raise InputError(f"{where}: {len(self.fallen)} counts of columns fallen, not "
                             f"{self.columns + 1} (0 to {self.columns})")
        if any(f.of != self.runs for f in self.fallen) or \
                sum(f.count for f in self.fallen) != self.runs:
            raise InputError(f"{where}: the counts of columns fallen do not add up to the "
                             f"{self.runs} runs")
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

    def to_json(self):
        return {"colonnade": self.colonnade, "group": self.group, "columns": self.columns,
                "runs": self.runs,
                "fallen": [{"k": k, **f.to_json()} for k, f in enumerate(self.fallen)],
                "parallel_given_two_fell": self.parallel.to_json(),
                "in_sequence_given_three_fell": self.in_sequence.to_json(),
                "in_sequence": self.in_sequence_of_all.to_json()}

    @classmethod
    def from_json(cls, data, where):
        if not isinstance(data, dict) or not isinstance(data.get("fallen"), list):
            raise InputError(f"{where} must be an object with 'fallen'")
        fallen = data["fallen"]
        if [f.get("k") if isinstance(f, dict) else None for f in fallen] != \
                list(range(len(fallen))):
            raise InputError(f"{where}.fallen: k must run 0, 1, ... in order")
        try:
            return cls(colonnade=str(data.get("colonnade")), group=str(data.get("group")),
                       columns=data.get("columns"), runs=data.get("runs"),
                       fallen=[Proportion.from_json(f, f"fallen[{k}]")
                               for k, f in enumerate(fallen)],
                       parallel=Proportion.from_json(data.get("parallel_given_two_fell"),
                                                     "parallel_given_two_fell"),
                       in_sequence=Proportion.from_json(
                           data.get("in_sequence_given_three_fell"),
                           "in_sequence_given_three_fell"),
                       in_sequence_of_all=Proportion.from_json(data.get("in_sequence"),
                                                               "in_sequence"))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None


@dataclass(frozen=True)
class ColonnadeStatistics:
    """``groups``: a :class:`GroupStatistics` per colonnade and group (record, or
    ``grouped_by``'s value), then per colonnade over all its records when it ran under
    several (``pooled``)."""
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

    def to_json(self):
        return {"confidence": CONFIDENCE, "interval": "Wilson score",
                "grouped_by": self.grouped_by, "groups": [g.to_json() for g in self.groups]}

    def save(self, directory):
        """Write ``directory``/colonnade_statistics.json (atomically)."""
        write_json(directory / FILE, self.to_json())

    @classmethod
    def load(cls, path):
        """Read a colonnade_statistics.json (``path`` the file or its directory); a
        one-line InputError for a file that is not one."""
        path = path / FILE if path.is_dir() else path
        path, data = read_run_json(path, FILE)
        if not isinstance(data, dict) or not isinstance(data.get("groups"), list):
            raise InputError(f"{path}: not a {FILE} (no 'groups')")
        return cls(tuple(GroupStatistics.from_json(g, f"{path}: groups[{k}]")
                         for k, g in enumerate(data["groups"])),
                   data.get("grouped_by", "record_id"))


def _group(name, group, rows):
    """The :class:`GroupStatistics` of the colonnade ``name``'s ``rows`` (one group's,
    or all)."""
    counts = set(int(c) for c in rows["columns"])
    if len(counts) != 1:
        raise InputError(f"colonnades.csv: colonnade {name} has {sorted(counts)} columns "
                         "in different runs")
    n, runs = counts.pop(), len(rows)
    fallen = [int(k) for k in rows["columns_fallen"]]
    parallel = [csv_true(v) for v in rows["parallel"] if _known(v)]
    sequence = [csv_true(v) for v in rows["in_sequence"] if _known(v)]
    in_sequence = sum(sequence)
    return GroupStatistics(
        colonnade=str(name), group=str(group), columns=n, runs=runs,
        fallen=[Proportion(fallen.count(k), runs) for k in range(n + 1)],
        parallel=Proportion(sum(parallel), len(parallel)),
        in_sequence=Proportion(in_sequence, len(sequence)),
        in_sequence_of_all=Proportion(in_sequence, runs))


def _known(value):
    """Whether a parallel or in_sequence cell holds a value (not None, NaN or empty)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return False
    return not (isinstance(value, str) and not value.strip())
