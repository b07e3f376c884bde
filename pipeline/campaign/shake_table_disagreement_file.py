"""``disagreements.csv`` of the shake-table members mode: per test where it lies (PGA,
PGV/PGA, month, split), whether its members' majority (P > 0.5) is wrong and how, and
what decided its member runs (uplift, sliding, when each began, the contact parameters
of the members that overturned and of those that stood).  One type per test
(:class:`Disagreement`), one file (:class:`DisagreementTable`: :meth:`save`, :meth:`load`).

Written are a test's own values; P, the verdict, the mechanism, the month and the bins
follow from them and are written too (a reader checks that they do)."""
import enum
import math
from dataclasses import dataclass, fields
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign.shake_table_experiments import PGA_EDGES_G, PGV_PGA_EDGES_S
from pipeline.files import InputError, csv_true, write_csv

FILE = "disagreements.csv"
SPLITS = ("calibration", "validation")


class Verdict(enum.Enum):
    """The members' majority (P > 0.5: overturned) against the laboratory."""
    RIGHT = "right"
    MISSED_OVERTURN = "missed overturn"      # overturned in the laboratory, P <= 0.5
    FALSE_OVERTURN = "false overturn"        # stood in the laboratory, P > 0.5

    @classmethod
    def of(cls, observed, p):
        if observed and not p > 0.5:
            return cls.MISSED_OVERTURN
        if not observed and p > 0.5:
            return cls.FALSE_OVERTURN
        return cls.RIGHT


class Mechanism(enum.Enum):
    """What a member run did (ordered: the first wins a tie of a test's members)."""
    TOPPLED = "toppled"
    ROCKING = "rocking"          # uplift (theta_max / alpha past the limit), stood
    SLIDING = "sliding"          # slid past the limit without uplift, stood
    STILL = "still"              # neither


def bin_label(value, edges):
    """The bin of ``value`` among ``edges`` as text, "lo-hi" (the last bin closed;
    beyond it "> last")."""
    k = int(np.searchsorted(edges, value, side="right")) - 1
    if value == edges[-1]:
        k = len(edges) - 2
    if k >= len(edges) - 1:
        return f"> {edges[-1]:g}"
    return f"{edges[k]:g}-{edges[k + 1]:g}"


def _count(value, name):
    if isinstance(value, (bool, np.bool_)) or not float(value).is_integer() or value < 0:
        raise InputError(f"{name} must be a count, got {value!r}")
    return int(value)


def _measure(value, name, minimum=0.0):
    """A finite float >= minimum, or NaN (not known)."""
    value = float(value)
    if math.isnan(value):
        return value
    if not (math.isfinite(value) and value >= minimum):
        raise InputError(f"{name} must be a finite number >= {minimum:g} or empty, "
                         f"got {value!r}")
    return value


PARAMETERS = ("kn_n_per_m", "damping", "mu_s", "footprint_tolerance_m", "motion_turn_deg")
SIGNED = ("first_uplift_s", "first_slip_s", "motion_turn_deg_overturned",
          "motion_turn_deg_standing")           # values that may be negative


@dataclass(frozen=True, kw_only=True)
class Disagreement:
    """One test (time s on the record's clock; lengths m; kn N/m): its ``runs`` member
    runs, ``overturned`` of them; ``runs_uplift`` with theta_max / alpha past the uplift
    limit (those that overturned included), ``runs_sliding`` standing that slid without
    uplift; of the ``runs_timed`` with a trajectory, ``runs_slip_first`` slid before they
    uplifted (or without); the members' median theta_max / alpha, largest base slip
    (centre of mass) and residual slide, median first uplift and first slip times; the
    median of each contact parameter over the members that overturned and those that
    stood, and of the table motion's turn (deg in (-180, 180]: a member's yaw, the sign
    reversed) (NaN: none, or not in the runs' files)."""
    test: str
    date: str
    split: str
    pga_g: float
    pgv_pga_s: float
    observed: bool
    runs: int
    overturned: int
    runs_uplift: int
    runs_sliding: int
    runs_timed: int
    runs_slip_first: int
    median_tilt_over_critical: float
    max_base_slip_m: float
    max_residual_slide_m: float
    max_residual_twist_deg: float
    first_uplift_s: float
    first_slip_s: float
    kn_n_per_m_overturned: float
    kn_n_per_m_standing: float
    damping_overturned: float
    damping_standing: float
    mu_s_overturned: float
    mu_s_standing: float
    footprint_tolerance_m_overturned: float
    footprint_tolerance_m_standing: float
    motion_turn_deg_overturned: float
    motion_turn_deg_standing: float

    def __post_init__(self):
        where = f"test {self.test}"
        if not isinstance(self.test, str) or not self.test:
            raise InputError(f"disagreement: test name {self.test!r}")
        try:
            date.fromisoformat(self.date)
        except (TypeError, ValueError):
            raise InputError(f"{where}: date {self.date!r} is not yyyy-mm-dd") from None
        if self.split not in SPLITS:
            raise InputError(f"{where}: split {self.split!r} is not one of {SPLITS}")
        if not isinstance(self.observed, (bool, np.bool_)):
            raise InputError(f"{where}: observed must be true or false")
        object.__setattr__(self, "observed", bool(self.observed))
        for f in fields(self):
            if f.type is int:
                object.__setattr__(self, f.name, _count(getattr(self, f.name),
                                                        f"{where}: {f.name}"))
            elif f.type is float:
                value = _measure(getattr(self, f.name), f"{where}: {f.name}",
                                 -math.inf if f.name in SIGNED else 0.0)
                object.__setattr__(self, f.name, value)
        for name in ("pga_g", "pgv_pga_s"):
            if math.isnan(getattr(self, name)):
                raise InputError(f"{where}: {name} must be a number")
        if self.runs < 1:
            raise InputError(f"{where}: no member run")
        if not (self.overturned <= self.runs_uplift
                and self.runs_uplift + self.runs_sliding <= self.runs):
            raise InputError(f"{where}: overturned {self.overturned} <= uplift "
                             f"{self.runs_uplift}, uplift + sliding {self.runs_uplift} + "
                             f"{self.runs_sliding} <= runs {self.runs} do not hold")
        if not self.runs_slip_first <= self.runs_timed <= self.runs:
            raise InputError(f"{where}: slip first {self.runs_slip_first} <= timed "
                             f"{self.runs_timed} <= runs {self.runs} do not hold")

    @property
    def P(self):
        """The members' probability of overturning."""
        return self.overturned / self.runs

    @property
    def verdict(self):
        return Verdict.of(self.observed, self.P)

    @property
    def majority_wrong(self):
        return self.verdict is not Verdict.RIGHT

    @property
    def month(self):
        return self.date[:7]

    @property
    def pga_bin(self):
        return bin_label(self.pga_g, PGA_EDGES_G)

    @property
    def pgv_pga_bin(self):
        return bin_label(self.pgv_pga_s, PGV_PGA_EDGES_S)

    @property
    def mechanisms(self):
        """{Mechanism: member runs}."""
        return {Mechanism.TOPPLED: self.overturned,
                Mechanism.ROCKING: self.runs_uplift - self.overturned,
                Mechanism.SLIDING: self.runs_sliding,
                Mechanism.STILL: self.runs - self.runs_uplift - self.runs_sliding}

    @property
    def mechanism(self):
        """What most of its members did (ties: the first of :class:`Mechanism`)."""
        counts = self.mechanisms
        return max(Mechanism, key=lambda m: (counts[m], -list(Mechanism).index(m)))

    def derived(self):
        """The values that follow from the test's own, as the file writes them."""
        return {"month": self.month, "pga_bin_g": self.pga_bin,
                "pgv_pga_bin_s": self.pgv_pga_bin, "P": self.P,
                "verdict": self.verdict.value, "majority_wrong": self.majority_wrong,
                "mechanism": self.mechanism.value}


OWN = tuple(f.name for f in fields(Disagreement))
DERIVED = ("month", "pga_bin_g", "pgv_pga_bin_s", "P", "verdict", "majority_wrong",
           "mechanism")
COLUMNS = OWN[:5] + DERIVED[:3] + OWN[5:8] + DERIVED[3:] + OWN[8:]


@dataclass(frozen=True)
class DisagreementTable:
    """Every test's :class:`Disagreement`, in the campaign's order of tests."""
    tests: tuple

    def __post_init__(self):
        object.__setattr__(self, "tests", tuple(self.tests))
        if not all(isinstance(t, Disagreement) for t in self.tests):
            raise InputError("disagreements: every row must be a test's Disagreement")
        names = [t.test for t in self.tests]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise InputError(f"disagreements: test {repeated[0]} appears twice")

    def frame(self):
        """The table as the file holds it (one row a test, :data:`COLUMNS`)."""
        rows = [{**{n: getattr(t, n) for n in OWN}, **t.derived()} for t in self.tests]
        return pd.DataFrame(rows, columns=list(COLUMNS))

    def save(self, directory):
        """Write ``directory``/disagreements.csv (atomically); return its path."""
        path = Path(directory) / FILE
        write_csv(path, self.frame())
        return path

    @classmethod
    def load(cls, path):
        """Read ``path`` (the file or its directory); a one-line InputError for a file
        that is not one (a column missing or unknown, a value out of range, a derived
        value that does not follow from the test's own)."""
        path = Path(path)
        path = path / FILE if path.is_dir() else path
        try:
            frame = pd.read_csv(path, dtype={"test": str, "date": str, "split": str,
                                             "month": str, "pga_bin_g": str,
                                             "pgv_pga_bin_s": str, "verdict": str,
                                             "mechanism": str}, keep_default_na=False,
                                na_values=[""])
        except FileNotFoundError:
            raise InputError(f"{FILE} not found: {path}") from None
        except (OSError, ValueError, pd.errors.ParserError) as exc:
            raise InputError(f"{path}: not a {FILE} ({str(exc).splitlines()[0]})") from None
        if list(frame.columns) != list(COLUMNS):
            missing = [c for c in COLUMNS if c not in frame.columns]
            extra = [c for c in frame.columns if c not in COLUMNS]
            raise InputError(f"{path}: not a {FILE} (" + (
                f"no column {missing[0]}" if missing else
                f"unknown column {extra[0]}" if extra else "columns out of order") + ")")
        return cls(tuple(_row(path, k, row) for k, row in enumerate(frame.to_dict("records"))))


def _row(path, k, row):
    """Row ``k`` of the file as a :class:`Disagreement`, its derived values checked."""
    where = f"{path.name} row {k + 2}"
    try:
        own = {n: row[n] for n in OWN}
        own["observed"] = _bool(row["observed"], "observed")
        for n in ("test", "date", "split"):
            own[n] = "" if pd.isna(own[n]) else str(own[n])
        test = Disagreement(**own)
        stated = {n: row[n] for n in DERIVED}
        stated["majority_wrong"] = _bool(stated["majority_wrong"], "majority_wrong")
    except (InputError, TypeError, ValueError) as exc:
        raise InputError(f"{where}: {exc}") from None
    for name, value in test.derived().items():
        same = (math.isclose(float(stated[name]), value, rel_tol=1e-9, abs_tol=1e-12)
                if name == "P" else str(stated[name]) == str(value))
        if not same:
            raise InputError(f"{where}: {name} {stated[name]!r} is not that of the test's "
                             f"own values ({value!r})")
    return test


def _bool(value, name):
    if isinstance(value, str) and value.strip().lower() not in ("true", "false"):
        raise InputError(f"{name} must be true or false, got {value!r}")
    if not isinstance(value, (str, bool, np.bool_)):
        raise InputError(f"{name} must be true or false, got {value!r}")
    return csv_true(value)
