"""The YADE rocking frame against the rigid one (Makris & Vassiliou 2013,
:class:`~pipeline.rocking.frame.RockingFrame`): identical box columns under one beam
that covers their top faces, shaken in its plane (along the beam, East).

Two checks: the smallest amplitude of a one-cosine pulse that overturns the frame, the
rigid frame's (its one degree of freedom integrated as a block's, :func:`overturns_2d`,
scanned then bisected) against YADE's (bisection, as the single block's one-cosine check,
:func:`pipeline.verification.one_cosine.bracketed_threshold`, within its tolerance); and
uplift at g tan(alpha) whatever the beam weighs.  The beam must not slide on the
capitals (the rigid frame's assumption): the check's friction is high.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

from pipeline import RESULTS_DIR, paper
from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.outcome.columns import column_outcomes
from pipeline.rocking.frame import RockingFrame
from pipeline.rocking.response import body_response
from pipeline.scenario import ColumnGeometry, Contact, Numerics, run_yade, scene_params, \
    write_scenario
from pipeline.scenario.colonnade import Beam, Colonnade, Course, PlacedColumn, Stylobate
from pipeline.scenario.solids import Box, ColumnBlock
from pipeline.verification.checks import HOUSNER_DAMPING
from pipeline.verification.one_cosine import (MR_BLOCK, TOLERANCE_YADE, YADE_RUNS,
                                              bracketed_threshold, check_period, check_runs)

# beam mass over the columns' mass: at gamma 4 the rigid frame under the 1 s pulse no
# longer overturns after an impact, only without one at 4.8 g, beyond any friction (YADE's
# frame, sliding, overturns at 3.2 g): the check keeps to the lighter beams
FRAME_GAMMAS = (0.25, 0.5, 1.0)
FRAME_COLUMNS = (2, 4)
FRAME_PERIOD_S = 1.0                # the verification campaign's pulse (Fig. 11's)
SPACING_M = 2.0                     # axis to axis
BEAM_HEIGHT_M = 0.5
# critical damping: Housner's restitution (as the block's checks); mu 2: no sliding
FRAME_CONTACT = {"damping": HOUSNER_DAMPING, "mu_s": 2.0, "mu_k": 2.0}
SCAN_STEP = 0.002                   # relative step of the rigid frame's amplitude scan
_T_AFTER_S = 30.0
_RTOL = 1e-5


def frame_colonnade(n_columns, gamma, height=MR_BLOCK["height"], width=MR_BLOCK["width"],
                    depth=MR_BLOCK["depth"], density=paper.MARBLE_DENSITY_KG_M3):
    """A :class:`Colonnade` of ``n_columns`` box columns (m) SPACING_M apart along East
    under one beam of BEAM_HEIGHT_M over all their top faces, of mass ``gamma`` times
    the columns'."""
    if isinstance(n_columns, bool) or not isinstance(n_columns, int) or n_columns < 2:
        raise InputError(f"a frame needs 2 columns or more, got {n_columns!r}")
    RockingFrame(height, width, gamma)                    # gamma and sizes checked
    if width >= SPACING_M:
        raise InputError(f"frame columns {width:g} m wide do not fit {SPACING_M:g} m apart")
    column = ColumnGeometry("frame-column", density, (ColumnBlock(Box(height, width, depth)),))
    xs = SPACING_M * np.arange(n_columns)
    columns = tuple(PlacedColumn(f"C{k + 1}", column, float(x), 0.0) for k, x in enumerate(xs))
    length = float(xs[-1]) + width
    mass = gamma * n_columns * column.bodies()[0].mass
    beam = Beam("B", Course.EPISTYLE, tuple(c.name for c in columns), length, depth,
                BEAM_HEIGHT_M, mass / (length * depth * BEAM_HEIGHT_M))
    return Colonnade(f"frame-{n_columns}-{gamma:g}", Stylobate((-width, 0.0),
                                                                (float(xs[-1]) + width, 0.0),
                                                                2 * depth), columns, (beam,))


def overturns_2d(a_p_g, period_s, frame):
    """Whether the rigid frame (:class:`RockingFrame`) overturns under a one-cosine pulse
    a_p cos(2 pi t / T) for 0 <= t <= T (``a_p_g`` g, ``period_s`` T s)."""
    w, a = 2 * math.pi / period_s, a_p_g * MODEL_GRAVITY

    def acc(t):
        return a * math.cos(w * t) if t <= period_s else 0.0
    out = body_response(frame.body(), acc, period_s + _T_AFTER_S, still_after=period_s,
                        dt_out=None, rest_max_step=min(1e-3, period_s / 200))
    return bool(out["overturned"])


def min_overturning_2d(period_s, frame, a_max_g=20.0):
    """The rigid frame's smallest overturning amplitude (g): scanned up from
    tan(alpha) in SCAN_STEP steps, the step that overturns it bisected to _RTOL."""
    lo = math.tan(frame.alpha)
    while lo < a_max_g:
        hi = lo * (1 + SCAN_STEP)
        if overturns_2d(hi, period_s, frame):
            while hi - lo > _RTOL * hi:
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if overturns_2d(mid, period_s, frame) else (mid, hi)
            return 0.5 * (lo + hi)
        lo = hi
    raise InputError(f"the rigid frame does not overturn below {a_max_g:g} g")


def frame_contact(gamma, **contact):
    """The frame's :class:`Contact`: FRAME_CONTACT, and the contact stiffness of a single
    column times 1 + 3 gamma, the frame's rotational inertia over the column's
    (:mod:`pipeline.rocking.frame`), so that the frame rocks on its contact springs at the
    single column's frequency (rigid as the single block's checks are); ``contact``
    overrides."""
    return Contact(**{**FRAME_CONTACT, "kn": Contact().kn * (1.0 + 3.0 * gamma), **contact})


def run_frame(run_dir, colonnade, motion, duration, record_hz=200.0, **contact):
    """Run the frame's scene; its column outcomes (dicts, columns then the beam)."""
    params = scene_params(colonnade=colonnade,
                          contact=frame_contact(colonnade.beam_mass_ratio, **contact),
                          numerics=Numerics(record_hz=record_hz, rest_duration_s=0.3),
                          t_max=duration)
    write_scenario(run_dir, params, motion)
    return column_outcomes(run_yade(run_dir))


def overturns_yade(a_p_g, period_s, run_dir, colonnade, **contact):
    """Whether a column of the YADE frame topples under the pulse (East); "overturned"
    or "no_overturn"."""
    motion = one_cosine_pulse(a_p_g * MODEL_GRAVITY, period_s / (2 * math.pi), 90.0,
                              dt=0.001, tail_s=4.0)
    outcomes = run_frame(run_dir, colonnade, motion, motion.duration, **contact)
    fell = any(o["toppled"] for o in outcomes if o["column"] != "B")
    return fell, "overturned" if fell else "no_overturn"


def verify_frame(n_columns=2, gamma=1.0, period_s=1.0, runs=YADE_RUNS, run_dir=None,
                 **contact):
    """The smallest overturning amplitude (g) of the rigid and the YADE frame under a
    one-cosine pulse of ``period_s``, and the single column's; passed when YADE is
    within the one-cosine check's TOLERANCE_YADE of the rigid frame."""
    check_period(period_s)
    check_runs(runs)
    colonnade = frame_colonnade(n_columns, gamma)
    frame = RockingFrame(MR_BLOCK["height"], MR_BLOCK["width"], gamma)
    run_dir = Path(run_dir or RESULTS_DIR / "verification" / "runs" /
                   f"frame_{n_columns}_{gamma:g}_{period_s:g}")
    a2d = min_overturning_2d(period_s, frame)
    single = min_overturning_2d(period_s, RockingFrame(MR_BLOCK["height"], MR_BLOCK["width"], 0))
    yade = bracketed_threshold(
        lambda a, k: overturns_yade(a, period_s, run_dir / f"a{k:02d}", colonnade, **contact),
        a2d, runs)
    result = {"test": "frame", "n_columns": n_columns, "gamma": gamma, "period_s": period_s,
              "alpha_rad": frame.alpha, "p_frame_per_s": frame.p,
              "restitution": frame.restitution, "size_factor": frame.size_factor,
              "contact": dataclasses.asdict(frame_contact(gamma, **contact)),
              "integration": {"threshold_g": a2d},
              "single_column_threshold_g": single, "yade": yade,
              "tolerance_yade": TOLERANCE_YADE}
    result["yade_rel_error"] = (None if yade["threshold_g"] is None
                                else yade["threshold_g"] / a2d - 1)
    result["passed"] = bool(result["yade_rel_error"] is not None
                            and abs(result["yade_rel_error"]) <= TOLERANCE_YADE)
    return result


def summarise_frames(results):
    """The frame section of the verification's summary from its checks' results
    (CheckResult dicts): per frame the rigid and YADE thresholds (g), their relative
    difference, the single column's threshold and the frame's over it; and a line for
    the REPORT."""
    rows = sorted(({"n_columns": r["n_columns"], "gamma": r["gamma"],
                    "period_s": r["period_s"], "integration_g": r["integration"]["threshold_g"],
                    "yade_g": r["yade"]["threshold_g"], "rel_error": r["yade_rel_error"],
                    "single_column_g": r["single_column_threshold_g"],
                    "over_single": r["integration"]["threshold_g"]
                    / r["single_column_threshold_g"], "passed": r["passed"]}
                   for r in results), key=lambda row: (row["n_columns"], row["gamma"]))
    errors = [abs(row["rel_error"]) for row in rows if row["rel_error"] is not None]
    ratios = [row["over_single"] for row in rows]
    line = (f"Rocking frame (Makris & Vassiliou 2013), one-cosine pulse: YADE within "
            f"{100 * TOLERANCE_YADE:g} % of the rigid frame's smallest overturning amplitude "
            f"in {sum(row['passed'] for row in rows)}/{len(rows)} frames (largest difference "
            f"{100 * max(errors, default=math.nan):.1f} %); the frames overturn at "
            f"{min(ratios):.2f} to {max(ratios):.2f} times the single column's amplitude")
    return {"frames": rows, "tolerance_yade": TOLERANCE_YADE, "lines": [line]}
