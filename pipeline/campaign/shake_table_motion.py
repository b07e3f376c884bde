"""What the shipped 200 Hz shake-table motions lose against the providers' 800 Hz records.

``records/shake_table/table_motion_800hz.csv`` (written by
``records/tools/derive_table_motion.py``; its columns in records/shake_table/README.md)
holds one :class:`TableMotionLoss` per test with a motion file, read only by
:func:`load_table_motion`.  :func:`table_motion_summary` gives the numbers the docs
quote and :func:`write_table_motion_figure` draws them against the tests' PGA and
PGV/PGA.
"""
import io
import math
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign.shake_table_experiments import AXIS_DEG, CALIBRATION_NEIGHBOURHOOD
from pipeline.constants import MODEL_GRAVITY, STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records import RECORDS_DIR
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.stats.fragility import logistic_surface
from pipeline.userfiles import DATA_FILE_BYTES, read_user_text, show

TABLE_MOTION = RECORDS_DIR / "shake_table" / "table_motion_800hz.csv"
RATIO_RTOL = 2e-5          # the file's 6 significant digits, twice (a quotient of two)


@dataclass(frozen=True)
class TableMotionLoss:
    """One test's table motion, 800 Hz source against the shipped 200 Hz file: raw peaks
    (g) and their ratio; the peak velocity (m/s) of each as a run processes it and the
    ratio of their processed peaks; the 800 Hz signal's energy share above 25, 80 and
    100 Hz; the time (s) the 800 Hz |a| spends above the shipped peak and the velocity
    (m/s) it carries there; the duration (s) of the one-sided pulse holding its peak.  Checks itself on construction (one-line InputError)."""
    test: str
    pga_800hz_g: float
    pga_200hz_g: float
    pga_ratio: float
    pgv_800hz_m_s: float
    pgv_200hz_m_s: float
    run_pga_ratio: float
    energy_above_25hz: float
    energy_above_80hz: float
    energy_above_100hz: float
    above_shipped_s: float
    above_shipped_m_s: float
    peak_pulse_s: float

    def __post_init__(self):
        if not (isinstance(self.test, str) and self.test.strip() and self.test.isprintable()):
            raise InputError(f"table motion: test name {show(self.test)} must be printable, "
                             "not blank")
        for f in fields(self)[1:]:
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not math.isfinite(value) or value < 0:
                raise InputError(f"table motion {self.test}: {f.name} {value!r} must be a "
                                 "finite number >= 0")
        for name in ("pga_800hz_g", "pga_200hz_g", "run_pga_ratio", "peak_pulse_s"):
            if getattr(self, name) == 0:
                raise InputError(f"table motion {self.test}: {name} must be above 0")
        self._check_relations()

    def _check_relations(self):
        quotient = self.pga_200hz_g / self.pga_800hz_g
        if abs(self.pga_ratio - quotient) > RATIO_RTOL * quotient:
            raise InputError(f"table motion {self.test}: pga_ratio {self.pga_ratio:g} is not "
                             f"pga_200hz_g / pga_800hz_g = {quotient:.6g}")
        shares = (self.energy_above_25hz, self.energy_above_80hz, self.energy_above_100hz)
        if not 1.0 >= shares[0] >= shares[1] >= shares[2]:
            raise InputError(f"table motion {self.test}: energy shares above 25, 80, 100 Hz "
                             f"{shares} must lie in [0, 1] and not grow with frequency")
        if (self.above_shipped_s > 0) != (self.above_shipped_m_s > 0):
            raise InputError(f"table motion {self.test}: above_shipped_s and "
                             "above_shipped_m_s must be both zero or both above zero")
        if self.above_shipped_s > 0 and self.pga_200hz_g > self.pga_800hz_g:
            raise InputError(f"table motion {self.test}: time above the shipped peak "
                             f"{self.above_shipped_s:g} s, but the 800 Hz peak is below it")

    @property
    def pga_lost(self):
        """Share of the 800 Hz peak the shipped file lacks (negative: its peak is higher)."""
        return 1.0 - self.pga_ratio


COLUMNS = tuple(f.name for f in fields(TableMotionLoss))


def load_table_motion(path=TABLE_MOTION):
    """The table's rows as a tuple of :class:`TableMotionLoss`; one-line InputError for a
    missing or unknown column, a value that is not a number, a row that fails its checks
    or a test given twice."""
    path = Path(path)
    try:
        frame = pd.read_csv(io.StringIO(read_user_text(path, "table-motion table",
                                                       DATA_FILE_BYTES)),
                            dtype={"test": str}, keep_default_na=False)
    except (ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path.name}: not a readable table "
                         f"({str(exc).splitlines()[0][:120]})") from None
    if tuple(frame.columns) != COLUMNS:
        raise InputError(f"{path.name}: columns {', '.join(map(str, frame.columns))}; "
                         f"expected {', '.join(COLUMNS)}")
    if frame.empty:
        raise InputError(f"{path.name}: no tests (a header and no rows)")
    rows = []
    for number, record in enumerate(frame.itertuples(index=False), start=2):
        values = []
        for name, text in zip(COLUMNS[1:], record[1:]):
            try:
                values.append(float(text))
            except ValueError:
                raise InputError(f"{path.name}, row {number}: {name} {show(text)} is not a "
                                 "number") from None
        try:
            rows.append(TableMotionLoss(record[0], *values))
        except InputError as exc:
            raise InputError(f"{path.name}, row {number}: {exc}") from None
    tests = [row.test for row in rows]
    if len(set(tests)) != len(tests):
        twice = next(t for t in tests if tests.count(t) > 1)
        raise InputError(f"{path.name}: test {twice} appears twice")
    return tuple(rows)


@dataclass(frozen=True)
class TableMotionSummary:
    """What the table says over its tests, as the docs quote it: the share of the 800 Hz
    PGA the 200 Hz file lacks (%, median, 95th percentile, largest; on the ``measured``
    tests, whose summary PGA is not nominal, medians below and above ``weak_pga_g`` and
    ``short_pgv_pga_s``), tests whose 200 Hz peak is the higher,
    the 800 Hz energy above 25 and 80 Hz (%), the time (ms) and velocity (mm/s) above the
    shipped peak, the duration (ms) of the pulse holding the 800 Hz peak (median, 5th
    percentile), the change of a run's peak acceleration and velocity (|%|; the tests
    whose peak velocity changes by more than 5 %), and what
    these can do to the rock (over all ``tests``): ``tip_share_pct``, the largest velocity above the shipped
    peak as a share of the angular velocity that tips the rock from rest at its least
    stable seating (p Dv / (2 g sin(alpha/2)), p <= sqrt(g/R)), and the shift (percentage
    points) of the laboratory's overturning probability a PGA or PGV change moves at most
    (slope of its logistic surface over the measured tests / 4).  NaN where no test (or too
    few for the surface) gives the number."""
    tests: int
    measured: int
    lost_median_pct: float
    lost_p95_pct: float
    lost_max_pct: float
    higher_at_200hz: int
    weak_pga_g: float
    lost_weak_pct: float
    lost_strong_pct: float
    short_pgv_pga_s: float
    lost_short_pct: float
    lost_long_pct: float
    energy_25hz_median_pct: float
    energy_80hz_median_pct: float
    energy_80hz_max_pct: float
    above_median_ms: float
    above_max_ms: float
    above_median_mm_s: float
    above_max_mm_s: float
    pulse_median_ms: float
    pulse_p5_ms: float
    run_pga_p95_pct: float
    run_pga_max_pct: float
    run_pgv_median_pct: float
    run_pgv_p95_pct: float
    run_pgv_max_pct: float
    run_pgv_over_5pct: int
    run_pgv_tests: str
    alpha_deg: float
    p_max_per_s: float
    tip_share_pct: float
    lab_b_pga: float
    lab_b_pgv: float
    lost_shift_pp: float
    run_pga_shift_pp: float
    run_pgv_shift_pp: float


def loss_frame(rows, experiments):
    """The table's rows joined with the experiment table (``load_experiments``) by test:
    ``pga_g``, ``pgv_pga_s``, ``observed``, ``pga_nominal`` beside the row's values and
    ``pga_lost``, ``run_pga_change``, ``run_pgv_change`` (fractions)."""
    frame = pd.DataFrame([{**{name: getattr(row, name) for name in COLUMNS},
                           "pga_lost": row.pga_lost} for row in rows])
    keep = ["test", "pga_g", "pgv_pga_s", "observed", "pga_nominal"]
    frame = frame.merge(experiments[[c for c in keep if c in experiments]], on="test")
    if "pga_nominal" not in frame:
        frame["pga_nominal"] = 0                # a table without the column: all measured
    frame["run_pga_change"] = frame["run_pga_ratio"] - 1.0
    frame["run_pgv_change"] = frame["pgv_200hz_m_s"] / frame["pgv_800hz_m_s"] - 1.0
    return frame


def shared_tests(rows, experiments):
    """:func:`loss_frame`, refused in one line when no test of ``rows`` is in
    ``experiments`` (a table beside another experiment table)."""
    frame = loss_frame(rows, experiments)
    if frame.empty:
        raise InputError(f"{TABLE_MOTION.name}: none of its tests is in the experiment table")
    return frame


def pct(values, q):
    """The ``q`` th percentile of ``values`` (fractions) in %; NaN for no value."""
    values = np.asarray(values, float)
    return float(np.percentile(values, q)) * 100 if values.size else math.nan


def table_motion_summary(rows, experiments, specimen, weak_pga_g=0.1, short_pgv_pga_s=0.05):
    """:class:`TableMotionSummary` of ``rows`` (:func:`load_table_motion`) over the tests of
    ``experiments`` (:func:`~pipeline.campaign.shake_table_experiments.load_experiments`),
    for ``specimen`` (a ColumnGeometry description dict) at its least stable calibration
    seating."""
    frame = shared_tests(rows, experiments)
    measured = frame[frame["pga_nominal"].astype(int) == 0]
    lost, run_a, run_v = (frame[c].to_numpy() for c in ("pga_lost", "run_pga_change",
                                                          "run_pgv_change"))
    rock = ColumnGeometry.from_dict({**specimen, "footprint_tolerance_m":
                                     min(CALIBRATION_NEIGHBOURHOOD["footprint_tolerance_m"])})
    alpha = math.radians(rock.critical_angle_along_deg(AXIS_DEG))
    p_max = math.sqrt(MODEL_GRAVITY * math.cos(alpha) / rock.com[2])   # I_O >= m R^2
    above = frame["above_shipped_m_s"].to_numpy()
    lab = logistic_surface(measured["pga_g"] * STANDARD_GRAVITY, measured["pgv_pga_s"],
                           measured["observed"])["coefficients"] or \
        {"b1": math.nan, "b2": math.nan}             # too few tests, or one outcome only
    kept = measured["pga_lost"].to_numpy()
    weak, short = measured["pga_g"] < weak_pga_g, measured["pgv_pga_s"] < short_pgv_pga_s
    return TableMotionSummary(
        tests=len(frame), measured=len(measured), lost_median_pct=pct(lost, 50),
        lost_p95_pct=pct(lost, 95), lost_max_pct=pct(lost, 100),
        higher_at_200hz=int((lost < 0).sum()),
        weak_pga_g=weak_pga_g, lost_weak_pct=pct(kept[weak], 50),
        lost_strong_pct=pct(kept[~weak], 50), short_pgv_pga_s=short_pgv_pga_s,
        lost_short_pct=pct(kept[short], 50), lost_long_pct=pct(kept[~short], 50),
        energy_25hz_median_pct=pct(frame["energy_above_25hz"], 50),
        energy_80hz_median_pct=pct(frame["energy_above_80hz"], 50),
        energy_80hz_max_pct=pct(frame["energy_above_80hz"], 100),
        above_median_ms=pct(frame["above_shipped_s"], 50) * 10,
        above_max_ms=pct(frame["above_shipped_s"], 100) * 10,
        above_median_mm_s=pct(above, 50) * 10, above_max_mm_s=pct(above, 100) * 10,
        pulse_median_ms=pct(frame["peak_pulse_s"], 50) * 10,
        pulse_p5_ms=pct(frame["peak_pulse_s"], 5) * 10,
        run_pga_p95_pct=pct(abs(run_a), 95), run_pga_max_pct=pct(abs(run_a), 100),
        run_pgv_median_pct=pct(abs(run_v), 50), run_pgv_p95_pct=pct(abs(run_v), 95),
        run_pgv_max_pct=pct(abs(run_v), 100), run_pgv_over_5pct=int((abs(run_v) > 0.05).sum()),
        run_pgv_tests=", ".join(frame["test"][abs(run_v) > 0.05]),
        alpha_deg=math.degrees(alpha), p_max_per_s=p_max,
        tip_share_pct=100 * p_max * above.max() / (2 * MODEL_GRAVITY * math.sin(alpha / 2)),
        lab_b_pga=lab["b1"], lab_b_pgv=lab["b2"],
        lost_shift_pp=lab["b1"] * pct(lost, 50) / 4, run_pga_shift_pp=lab["b1"] * pct(
            abs(run_a), 95) / 4, run_pgv_shift_pp=lab["b2"] * pct(abs(run_v), 100) / 4)


def write_table_motion_figure(rows, experiments, path):
    """The figure (:func:`pipeline.figures.table_motion.plot_table_motion`) of ``rows``
    against the tests of ``experiments`` whose PGA is measured; returns the path."""
    from pipeline.figures.table_motion import plot_table_motion  # lazy: matplotlib
    frame = shared_tests(rows, experiments)
    frame = frame[frame["pga_nominal"].astype(int) == 0]
    return plot_table_motion(frame["pga_g"], frame["pgv_pga_s"], frame["observed"],
                             frame["pga_lost"], frame["run_pga_change"],
                             frame["run_pgv_change"], path)
