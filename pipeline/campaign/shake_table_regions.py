"""The members' errors by region of the shake-table tests (PGA bin, PGV/PGA bin, month,
split), each a :class:`~pipeline.stats.colonnade_counts.Proportion` of the region's tests
with its Wilson 95 % interval, and what the wrong tests' members did: the
``disagreements`` of ``shake_table_members.json`` (:class:`DisagreementSummary`, written
by :meth:`~DisagreementSummary.to_json`, read by :meth:`~DisagreementSummary.from_json`),
computed from ``disagreements.csv`` alone (:meth:`DisagreementSummary.of`)."""
import enum
import math
from dataclasses import dataclass

import numpy as np

from pipeline.campaign.shake_table_disagreement_file import Mechanism, Verdict
from pipeline.files import InputError
from pipeline.stats.colonnade_counts import Proportion


class RegionKind(enum.Enum):
    """A way to cut the tests into regions: its key, the test's attribute, its label."""
    PGA = ("pga_g", "pga_bin", "PGA (g)")
    PGV_PGA = ("pgv_pga_s", "pgv_pga_bin", "PGV/PGA (s)")
    MONTH = ("month", "month", "month")
    SPLIT = ("split", "split", "split")

    @property
    def key(self):
        return self.value[0]

    @property
    def label(self):
        return self.value[2]

    def of(self, test):
        return getattr(test, self.value[1])


def _order(label):
    """Regions in order: bins by their lower edge, months and splits by name."""
    head = label.split("-")[0].lstrip("> ")
    try:
        return (float(head) + (1e9 if label.startswith(">") else 0.0), label)
    except ValueError:
        return (math.inf, label)


@dataclass(frozen=True)
class RegionErrors:
    """The tests of one region: ``wrong`` (the members' majority wrong, of the region's
    tests), of them ``missed`` overturns and ``false`` overturns."""
    kind: RegionKind
    label: str
    wrong: Proportion
    missed: int
    false: int

    def __post_init__(self):
        if not isinstance(self.kind, RegionKind) or not isinstance(self.wrong, Proportion):
            raise InputError("region errors: a RegionKind and a Proportion")
        if self.wrong.of < 1 or self.missed < 0 or self.false < 0 \
                or self.missed + self.false != self.wrong.count:
            raise InputError(f"region {self.kind.label} {self.label}: missed {self.missed} "
                             f"+ false {self.false} overturns are not the {self.wrong.count}"
                             f" wrong of {self.wrong.of} tests")

    def to_json(self):
        return {"kind": self.kind.key, "label": self.label, "wrong": self.wrong.to_json(),
                "missed_overturns": self.missed, "false_overturns": self.false}

    @classmethod
    def from_json(cls, data, where):
        kinds = {k.key: k for k in RegionKind}
        if not isinstance(data, dict) or data.get("kind") not in kinds:
            raise InputError(f"{where}: not a region's errors (kind one of {list(kinds)})")
        return cls(kinds[data["kind"]], str(data.get("label")),
                   Proportion.from_json(data.get("wrong"), f"{where}.wrong"),
                   data.get("missed_overturns"), data.get("false_overturns"))


def region_errors(tests, kind):
    """The :class:`RegionErrors` of ``tests`` (Disagreements) cut by ``kind``."""
    groups = {}
    for t in tests:
        groups.setdefault(kind.of(t), []).append(t.verdict)
    return [RegionErrors(kind, label, Proportion(sum(v is not Verdict.RIGHT for v in vs),
                                                 len(vs)),
                         vs.count(Verdict.MISSED_OVERTURN), vs.count(Verdict.FALSE_OVERTURN))
            for label, vs in sorted(groups.items(), key=lambda kv: _order(kv[0]))]


PARAMETER_LABELS = (("kn_n_per_m", "kn", "{:.3g} N/m", 1.0),
                    ("damping", "damping", "{:.3f}", 1.0), ("mu_s", "mu_s", "{:.3f}", 1.0),
                    ("footprint_tolerance_m", "footprint tolerance", "{:.2f} mm", 1e3),
                    ("motion_turn_deg", "table motion's turn", "{:.1f} deg", 1.0))


@dataclass(frozen=True)
class DisagreementSummary:
    """Every test's errors (``wrong``: a Proportion of the tests), per region, the
    mechanism most of the members of each wrong test showed, and the ``lines`` that say
    it."""
    wrong: Proportion
    regions: tuple
    lines: tuple

    def __post_init__(self):
        object.__setattr__(self, "regions", tuple(self.regions))
        object.__setattr__(self, "lines", tuple(self.lines))
        for kind in RegionKind:
            total = sum(r.wrong.of for r in self.regions if r.kind is kind)
            if self.regions and total != self.wrong.of:
                raise InputError(f"disagreements: the {kind.label} regions hold {total} "
                                 f"tests, not {self.wrong.of}")

    @classmethod
    def of(cls, table):
        """The summary of a :class:`DisagreementTable`."""
        tests = table.tests
        wrong = Proportion(sum(t.majority_wrong for t in tests), len(tests))
        regions = [r for kind in RegionKind for r in region_errors(tests, kind)]
        return cls(wrong, regions, summary_lines(tests, wrong, regions))

    def to_json(self):
        return {"wrong": self.wrong.to_json(),
                "regions": [r.to_json() for r in self.regions], "lines": list(self.lines)}

    @classmethod
    def from_json(cls, data, where="disagreements"):
        if not isinstance(data, dict) or not isinstance(data.get("regions"), list):
            raise InputError(f"{where}: not a summary of disagreements (no 'regions')")
        return cls(Proportion.from_json(data.get("wrong"), f"{where}.wrong"),
                   [RegionErrors.from_json(r, f"{where}.regions[{k}]")
                    for k, r in enumerate(data["regions"])], data.get("lines") or ())


def _rate(p):
    lo, hi = p.ci95
    return f"{p.count} of {p.of} ({'-' if p.p is None else f'{p.p:.2f}'} [{lo:.2f}, {hi:.2f}])"


def summary_lines(tests, wrong, regions):
    """What the log and the REPORT say of the disagreements."""
    out = [f"members' majority (P > 0.5) wrong on {_rate(wrong)} tests: "
           f"{sum(t.verdict is Verdict.MISSED_OVERTURN for t in tests)} missed overturns, "
           f"{sum(t.verdict is Verdict.FALSE_OVERTURN for t in tests)} false overturns"]
    for kind in RegionKind:
        mine = [r for r in regions if r.kind is kind and r.wrong.count]
        if mine:
            worst = max(mine, key=lambda r: (r.wrong.p, r.wrong.of))
            out.append(f"  by {kind.label}: highest error rate in {worst.label}, "
                       f"{_rate(worst.wrong)}")
    for verdict in (Verdict.MISSED_OVERTURN, Verdict.FALSE_OVERTURN):
        mine = [t for t in tests if t.verdict is verdict]
        if not mine:
            continue
        counts = {m: sum(t.mechanism is m for t in mine) for m in Mechanism}
        timed = sum(t.runs_timed for t in mine)
        out.append(f"  {verdict.value}s ({len(mine)} test{'' if len(mine) == 1 else 's'}): "
                   "members mostly "
                   + ", ".join(f"{m.value} in {n}" for m, n in counts.items() if n)
                   + f"; median theta_max/alpha "
                   f"{np.nanmedian([t.median_tilt_over_critical for t in mine]):.2f}; "
                   "largest residual base slide (median over the tests) "
                   f"{1e3 * np.median([t.max_residual_slide_m for t in mine]):.1f} mm with a "
                   f"twist of {np.median([t.max_residual_twist_deg for t in mine]):.2f} deg; "
                   f"slid before any uplift in {sum(t.runs_slip_first for t in mine)} of "
                   f"{timed} member runs with a trajectory")
    split = [t for t in tests if 0 < t.overturned < t.runs]
    if split:
        parts = []
        for name, label, form, scale in PARAMETER_LABELS:
            up = np.array([getattr(t, f"{name}_overturned") for t in split])
            down = np.array([getattr(t, f"{name}_standing") for t in split])
            if np.isfinite(up).any() and np.isfinite(down).any():
                parts.append(f"{label} {form.format(scale * np.nanmedian(up))} against "
                             f"{form.format(scale * np.nanmedian(down))}")
        out.append(f"  on the {len(split)} tests whose members split, the overturned "
                   "members' median contact against the standing ones': "
                   + ("; ".join(parts) or "none in the runs' files"))
    return out
