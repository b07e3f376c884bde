"""The one-cosine pulse of Makris & Roussos (2000, Geotechnique 50(3), their type B):
ground acceleration a_p cos(omega_p t) for 0 <= t <= T_p = 2 pi / omega_p, the toolkit's
:func:`~pipeline.motion.pulses.one_cosine_pulse` with omega_p = 1 / (PGV/PGA).

The smallest amplitude that overturns a block, of the 2D rigid block
(:mod:`pipeline.rocking`, with Housner's restitution of the angular velocity
r = 1 - 1.5 sin^2 alpha from the geometry, as Makris & Roussos take it) and of the YADE
block, against their Fig. 11 (half-width b 0.5 m, half-height h 1.5 m, T_p 1 s: stands at
0.6245 g, overturns at 0.6255 g) and their closed form eq. 43,
a_po / (alpha g) ~ 1 + omega_p / (4 p) (about +-16 %); and the fine amplitude scans that
show where a block stands again above that amplitude (overturning is not monotone in it).
Amplitudes a_p are in g (the model's 9.81 m/s^2), periods in s.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

from pipeline import RESULTS_DIR
from pipeline.rocking.housner import block_constants
from pipeline.rocking.response import rocking_response
from pipeline.rocking.sampled import rocking_response_sampled
from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.scenario import Block, Contact
from pipeline.verification.checks import HOUSNER_DAMPING, classify_rocking, run_block

MR_BLOCK = {"height": 3.0, "width": 1.0, "depth": 1.0}   # b 0.5, h 1.5 m: alpha 18.43 deg
MR_PERIOD_S = 1.0
MR_STANDS_G, MR_OVERTURNS_G = 0.6245, 0.6255             # their Fig. 11
TOLERANCE_2D = 0.005          # relative, the 2D block's threshold against Fig. 11
# YADE against the 2D block (relative): rounded rims (pivot moved ~0.3 % of R), the
# restitution of a critically damped contact (within 0.2 % of Housner's), the finite
# stiffness (the pivot sinks and slides a little: no rigid corner) and the bisection
TOLERANCE_YADE = 0.02
EQ43_SPREAD = 0.16            # the stated accuracy of eq. 43
# eq. 43 describes overturning after one impact; beyond omega_p / p ~ 3.7 that region
# closes for this block (r 0.85) and the smallest amplitude is the no-impact branch
EQ43_OMEGA_RATIOS = (1.0, 3.0)
CURVE_OMEGA_RATIOS = tuple(round(0.5 * i, 1) for i in range(2, 25))     # 1 .. 12
YADE_PERIODS_S = (1.0, 1.5, 2.0, 3.0)    # omega_p / p 2.9 .. 1.0: a_p below mu_s g
YADE_CONTACT = {"damping": HOUSNER_DAMPING}  # critical: Housner's restitution (Verification)
YADE_RUNS = 10
MAX_RUNS = 20
PERIOD_RANGE_S = (0.1, 10.0)
# h / b of the block: Makris & Roussos's theory (and Housner's restitution 1 - 1.5 sin^2
# alpha, 0.25 at h = b, negative beyond b / h = 1.41) is of a block that rocks rather than
# slides or squats, taller than wide; the upper bound is the slenderness the column
# campaigns reach (scenario.parameters.Column.hd), 1.9 deg: an uplift at 0.033 g
SLENDERNESS_RANGE = (1.0, 30.0)
# omega_p / p below this is a nearly quasi-static pulse: the block overturns just above
# tan alpha, after more impacts than the 2D integration follows on a small slender block
# (its threshold in g, which depends on alpha and omega_p / p alone, is then found on a
# 3 m block and missed on a 0.3 m one at 0.3); Fig. 11's curve starts at 1, the
# verification's longest pulse is at 0.97
MIN_OMEGA_RATIO = 0.5
BLOCK_SIZES_M = {f.name: (f.metadata["low"], f.metadata["high"])
                 for f in dataclasses.fields(Block) if f.name in ("height", "width", "depth")}
# SP1's equivalent block: its weak-side critical angle and pivot distance
# (records/shake_table/README.md, Footprint: 14.7 deg, 0.302 m)
SP1_ALPHA_DEG, SP1_R_M = 14.7, 0.302
SP1_BLOCK = {"height": 2 * SP1_R_M * math.cos(math.radians(SP1_ALPHA_DEG)),
             "width": 2 * SP1_R_M * math.sin(math.radians(SP1_ALPHA_DEG))}
SP1_SCAN_PGV_PGA_S = (0.1, 0.2, 0.5)     # in the VSR grid's PGV/PGA (0.1-1.0 s)
SCAN_MAX_G = {"makris-roussos": 5.0, "sp1": 3.0}
SCAN_STEP = 0.005             # relative step of the fine amplitude scans
_T_AFTER_S = 30.0             # bound only: the integration stops once the outcome is certain
_RTOL = 1e-5                  # bisection of a 2D edge, relative


def check_period(period_s):
    """InputError unless the pulse period (s) is in :data:`PERIOD_RANGE_S`."""
    lo, hi = PERIOD_RANGE_S
    if not (isinstance(period_s, (int, float)) and lo <= period_s <= hi):
        raise InputError(f"--period must be in [{lo:g}, {hi:g}] s, got {period_s!r}")


def check_runs(runs):
    """InputError unless the YADE runs of a bisection are a whole number in [3, MAX_RUNS]."""
    if isinstance(runs, bool) or not isinstance(runs, int) or not 3 <= runs <= MAX_RUNS:
        raise InputError(f"--runs must be an integer in [3, {MAX_RUNS}], got {runs!r}")


def check_block_sizes(height, width, depth):
    """InputError unless the block's sizes (m) are within the verification block's ranges
    (:class:`~pipeline.scenario.parameters.Block`), named as the flags of ``verify``."""
    for name, value in (("height", height), ("width", width), ("depth", depth)):
        low, high = BLOCK_SIZES_M[name]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                not (math.isfinite(value) and low <= value <= high):
            raise InputError(f"--{name} must be a finite block size in [{low:g}, {high:g}] m, "
                             f"got {value!r}")


def check_block(height, width, depth):
    """:func:`check_block_sizes`, and the slenderness h / b within
    :data:`SLENDERNESS_RANGE`, the rocking block this check is about."""
    check_block_sizes(height, width, depth)
    low, high = SLENDERNESS_RANGE
    ratio = height / width
    if not low <= ratio <= high:
        what = "wider than tall" if ratio < low else "more slender than the check takes"
        raise InputError(f"--height {height:g} / --width {width:g} = {ratio:.4g}: the block is "
                         f"{what}; the one-cosine check is of a block that rocks (Housner's "
                         f"restitution 1 - 1.5 sin^2 alpha), slenderness h/b in "
                         f"[{low:g}, {high:g}]")


def check_one_cosine(period_s, height, width, depth, runs, **contact):
    """Every setting of the one-cosine check range-checked (one-line InputError), before
    any integration or YADE run: the period, the block, the runs and the contact."""
    check_period(period_s)
    check_block(height, width, depth)
    ratio = omega_ratio(period_s, height, width)
    if ratio < MIN_OMEGA_RATIO:
        raise InputError(f"--period {period_s:g} s on this block is omega_p / p = {ratio:.3g}, "
                         f"a quasi-static pulse: the check needs omega_p / p of at least "
                         f"{MIN_OMEGA_RATIO:g} (--period at most "
                         f"{2 * math.pi / (MIN_OMEGA_RATIO * block_constants(height, width)['p']):.3g}"
                         " s)")
    check_runs(runs)
    Contact(**contact)


def omega_ratio(period_s, height, width):
    """omega_p / p of a pulse of ``period_s`` on the block (h, b full sizes, m)."""
    return 2 * math.pi / period_s / block_constants(height, width)["p"]


def eq43_g(period_s, height, width):
    """Makris & Roussos eq. 43: the smallest overturning amplitude (g),
    alpha (1 + omega_p / (4 p))."""
    c = block_constants(height, width)
    return c["alpha"] * (1 + omega_ratio(period_s, height, width) / 4)


def overturns_2d(a_p_g, period_s, height, width):
    """Whether the 2D rigid block (h, b m; Housner's restitution) overturns under the
    pulse of amplitude ``a_p_g`` (g) and period ``period_s`` (s)."""
    w = 2 * math.pi / period_s
    a = a_p_g * MODEL_GRAVITY

    def acc(t):
        return a * math.cos(w * t) if t <= period_s else 0.0
    out = rocking_response(height, width, acc, period_s + _T_AFTER_S,
                                   still_after=period_s, dt_out=None,
                                   rest_max_step=min(1e-3, period_s / 200))
    return bool(out["overturned"])


def _bisect(overturns, lo, hi, rtol):
    """Shrink [lo, hi] (lo stands, hi overturns) to a relative width rtol."""
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if overturns(mid) else (mid, hi)
    return lo, hi


def _scan(period_s, height, width, amplitudes_g):
    """Overturned (bool array) of the 2D block under each amplitude (g), all at once
    (:func:`pipeline.rocking.sampled.rocking_response_sampled`)."""
    n = 400
    dt = period_s / n
    shape = np.cos(2 * math.pi * np.arange(n + 1) / n)
    acc = shape[:, None] * np.asarray(amplitudes_g)[None, :] * MODEL_GRAVITY
    return rocking_response_sampled(height, width, acc, dt, t_after=_T_AFTER_S,
                                            max_step=min(1e-3, dt))["overturned"]


def overturning_intervals(period_s, height, width, a_max_g, step=SCAN_STEP, first_only=False):
    """The amplitude intervals (g) in which the 2D block overturns, from its uplift
    amplitude (tan alpha) up to ``a_max_g``: a scan every ``step`` (relative) with the
    batch integrator, each edge found again with the exact one near where the scan saw
    it and bisected to 1e-5.  A list of [lo, hi] (hi None: still overturning at
    a_max_g); ``first_only``: the first."""
    a0 = math.tan(block_constants(height, width)["alpha"])
    grid = a0 * (1 + step) ** np.arange(1, int(math.log(a_max_g / a0) / math.log1p(step)) + 1)
    over = np.zeros(0, bool)
    for chunk in np.array_split(grid, max(1, len(grid) // 100)):
        over = np.concatenate([over, _scan(period_s, height, width, chunk)])
        if first_only and over.any():
            found = _refined(grid[:len(over)], over, period_s, height, width, True)
            if found:
                return found
    return _refined(grid, over, period_s, height, width, first_only)


def _refined(grid, scanned, period_s, height, width, first_only):
    """Intervals from the scan's outcomes on ``grid`` (g): the exact integrator's outcome
    on the grid points within 2 of each change the scan saw, each exact change bisected."""
    exact = {}

    def over(i):
        if i not in exact:
            exact[i] = overturns_2d(float(grid[i]), period_s, height, width)
        return exact[i]
    near = sorted({j for i in np.flatnonzero(scanned[1:] != scanned[:-1])
                   for j in range(max(0, i - 2), min(len(grid), i + 4))})
    intervals, start = [], None
    for i, j in zip(near[:-1], near[1:]):
        if j != i + 1 or over(i) == over(j):
            continue
        o = over(i)
        lo, hi = _bisect(lambda x: overturns_2d(x, period_s, height, width) != o,
                         float(grid[i]), float(grid[j]), _RTOL)
        if not o:
            start = hi
        elif start is not None:
            intervals.append([start, lo])
            start = None
        if first_only and intervals:
            return intervals
    if start is not None:
        intervals.append([start, None])
    return intervals


def safe_bands():
    """The fine amplitude scans: the paper's block under its 1 s pulse and SP1's
    equivalent block at :data:`SP1_SCAN_PGV_PGA_S`; a list of {block, period_s,
    pgv_pga_s, overturning_g: intervals, safe_bands_g: where it stands again}."""
    cases = [("makris-roussos", MR_BLOCK, MR_PERIOD_S)] + \
        [("sp1", SP1_BLOCK, 2 * math.pi * r) for r in SP1_SCAN_PGV_PGA_S]
    rows = []
    for name, block, period in cases:
        spans = overturning_intervals(period, block["height"], block["width"],
                                      SCAN_MAX_G[name])
        rows.append({"block": name, "period_s": period, "pgv_pga_s": period / (2 * math.pi),
                     "overturning_g": spans,
                     "safe_bands_g": [[a[1], b[0]] for a, b in zip(spans[:-1], spans[1:])]})
    return rows


def min_overturning_g(period_s, height, width, a_max_g=100.0):
    """The smallest amplitude (g) that overturns the 2D block (None below a_max_g)."""
    found = overturning_intervals(period_s, height, width, a_max_g, first_only=True)
    return found[0][0] if found else None


def curve_2d(height=MR_BLOCK["height"], width=MR_BLOCK["width"],
             omega_ratios=CURVE_OMEGA_RATIOS):
    """The smallest overturning amplitude of the 2D block and eq. 43 over omega_p / p:
    a list of {omega_ratio, period_s, min_overturning_g, over_alpha_g, eq43_over_alpha_g}."""
    c = block_constants(height, width)
    rows = []
    for w in omega_ratios:
        period = 2 * math.pi / (w * c["p"])
        a = min_overturning_g(period, height, width)
        rows.append({"omega_ratio": w, "period_s": period, "min_overturning_g": a,
                     "over_alpha_g": None if a is None else a / c["alpha"],
                     "eq43_over_alpha_g": 1 + w / 4})
    return rows


def overturns_yade(a_p_g, period_s, run_dir, height=MR_BLOCK["height"],
                   width=MR_BLOCK["width"], depth=MR_BLOCK["depth"], **contact):
    """Whether the YADE block overturns under the pulse (East); its mode name too."""
    motion = one_cosine_pulse(a_p_g * MODEL_GRAVITY, period_s / (2 * math.pi), 90.0,
                              dt=0.001, tail_s=4.0)
    t, theta, _ = run_block(run_dir, height, width, depth, motion=motion,
                            duration=motion.duration, **{**YADE_CONTACT, **contact})
    mode = classify_rocking(t, theta, block_constants(height, width)["alpha"])[0]
    return mode != "no_overturn", mode


def yade_threshold(period_s, guess_g, run_dir, runs=YADE_RUNS, **block):
    """The YADE block's smallest overturning amplitude (g) by bisection from a bracket
    of +-2 tolerances around ``guess_g``, ``runs`` YADE runs in all
    (:func:`bracketed_threshold`)."""
    return bracketed_threshold(
        lambda a, k: overturns_yade(a, period_s, Path(run_dir) / f"a{k:02d}", **block),
        guess_g, runs)


def bracketed_threshold(overturns, guess_g, runs=YADE_RUNS):
    """The smallest overturning amplitude (g) by bisection from a bracket of +-2
    tolerances around ``guess_g``, ``runs`` runs of ``overturns(a_g, k)`` -> (bool, mode
    name) in all (k: the run's number).  Returns {stands_g, overturns_g, threshold_g,
    runs: [[a_p_g, mode], ...]}."""
    check_runs(runs)
    done = []

    def over(a):
        out, mode = overturns(a, len(done))
        done.append([a, mode])
        return out
    lo, hi = guess_g * (1 - 2 * TOLERANCE_YADE), guess_g * (1 + 2 * TOLERANCE_YADE)
    moved = False
    while over(lo) and len(done) < runs:          # widen the bracket down
        hi, lo, moved = lo, lo * (1 - 4 * TOLERANCE_YADE), True
    while not moved and len(done) < runs and not over(hi):     # or up
        lo, hi = hi, hi * (1 + 4 * TOLERANCE_YADE)
    while len(done) < runs:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if over(mid) else (mid, hi)
    ok = bool(done) and any(m == "no_overturn" for _, m in done) and \
        any(m != "no_overturn" for _, m in done)
    return {"stands_g": lo, "overturns_g": hi, "threshold_g": 0.5 * (lo + hi) if ok else None,
            "runs": done}


def verify_one_cosine(period_s=MR_PERIOD_S, height=MR_BLOCK["height"], width=MR_BLOCK["width"],
                      depth=MR_BLOCK["depth"], runs=YADE_RUNS, run_dir=None, **contact):
    """The smallest overturning amplitude under a one-cosine pulse of ``period_s``: the 2D
    block's (bisected to 1e-5), the YADE block's (``runs`` runs) and eq. 43; passed when
    YADE is within TOLERANCE_YADE of the 2D block and, for Fig. 11's block and pulse,
    the 2D block within TOLERANCE_2D of Makris & Roussos."""
    check_one_cosine(period_s, height, width, depth, runs, **contact)
    run_dir = Path(run_dir or RESULTS_DIR / "verification" / "runs" / f"one_cosine_{period_s:g}")
    a2d = min_overturning_g(period_s, height, width)
    if a2d is None:
        raise InputError(f"the 2D block does not overturn below 100 g at period {period_s:g} s")
    yade = yade_threshold(period_s, a2d, run_dir, runs, height=height, width=width,
                          depth=depth, **contact)
    c = block_constants(height, width)
    result = {"test": "one-cosine", "period_s": period_s, "height_m": height, "width_m": width,
              "depth_m": depth, "alpha_rad": c["alpha"], "p_per_s": c["p"],
              "omega_ratio": omega_ratio(period_s, height, width),
              "restitution": c["restitution"], "contact": {**YADE_CONTACT, **contact},
              "integration": {"threshold_g": a2d}, "yade": yade,
              "eq43_g": eq43_g(period_s, height, width),
              "tolerance_yade": TOLERANCE_YADE, "tolerance_2d": TOLERANCE_2D}
    result["yade_rel_error"] = (None if yade["threshold_g"] is None
                                else yade["threshold_g"] / a2d - 1)
    passed = result["yade_rel_error"] is not None and \
        abs(result["yade_rel_error"]) <= TOLERANCE_YADE
    if (height, width, period_s) == (MR_BLOCK["height"], MR_BLOCK["width"], MR_PERIOD_S):
        result["makris_roussos_g"] = [MR_STANDS_G, MR_OVERTURNS_G]
        result["rel_error_2d"] = fig11_error(a2d)
        passed = passed and result["rel_error_2d"] <= TOLERANCE_2D
    result["passed"] = bool(passed)
    return result


def fig11_error(a_g):
    """Relative distance (>= 0) of an amplitude (g) from Fig. 11's [stands, overturns]."""
    return max(0.0, MR_STANDS_G - a_g, a_g - MR_OVERTURNS_G) / MR_OVERTURNS_G


def summarise_one_cosine(results):
    """The one-cosine section of the verification's summary from its YADE checks'
    results (a list of CheckResult dicts): Fig. 11 (2D, YADE), the curve of the smallest
    overturning amplitude (2D over CURVE_OMEGA_RATIOS, YADE at its checks' periods) beside
    eq. 43, the safe bands; and its lines for the REPORT."""
    c = block_constants(MR_BLOCK["height"], MR_BLOCK["width"])
    yade = sorted(({"period_s": r["period_s"], "omega_ratio": r["omega_ratio"],
                    "threshold_g": r["yade"]["threshold_g"],
                    "bracket_g": [r["yade"]["stands_g"], r["yade"]["overturns_g"]],
                    "runs": len(r["yade"]["runs"]), "integration_g": r["integration"]["threshold_g"],
                    "rel_error": r["yade_rel_error"], "passed": r["passed"]} for r in results),
                  key=lambda row: row["omega_ratio"])
    a2d = min_overturning_g(MR_PERIOD_S, MR_BLOCK["height"], MR_BLOCK["width"])
    curve = curve_2d()
    inside = [row for row in curve if EQ43_OMEGA_RATIOS[0] <= row["omega_ratio"]
              <= EQ43_OMEGA_RATIOS[1]]
    eq43_error = max(abs(row["over_alpha_g"] / row["eq43_over_alpha_g"] - 1) for row in inside)
    fig11 = {"makris_roussos_g": [MR_STANDS_G, MR_OVERTURNS_G], "integration_g": a2d,
             "integration_rel_error": fig11_error(a2d), "tolerance_2d": TOLERANCE_2D,
             "yade": next((row for row in yade if row["period_s"] == MR_PERIOD_S), None),
             "tolerance_yade": TOLERANCE_YADE, "restitution": c["restitution"]}
    out = {"fig11": fig11, "curve_2d": curve, "curve_yade": yade,
           "eq43": {"omega_ratio_range": list(EQ43_OMEGA_RATIOS), "spread": EQ43_SPREAD,
                    "max_rel_error_2d": eq43_error},
           "safe_bands": safe_bands(), "alpha_rad": c["alpha"], "p_per_s": c["p"]}
    out["lines"] = _lines(out)
    return out


def _lines(out):
    """The REPORT's lines of the one-cosine check."""
    f, y = out["fig11"], out["fig11"]["yade"]
    lines = [f"One-cosine pulse (Makris & Roussos 2000, Fig. 11: b 0.5 m, h 1.5 m, T_p 1 s, "
             f"stands at {MR_STANDS_G} g, overturns at {MR_OVERTURNS_G} g): the 2D block "
             f"overturns from {f['integration_g']:.4f} g ({100 * f['integration_rel_error']:.2f} % "
             f"outside their interval, tolerance {100 * TOLERANCE_2D:g} %, restitution "
             f"{f['restitution']:.2f})" + (
                 f"; the YADE block from {y['threshold_g']:.4f} g ({y['runs']} runs, "
                 f"{100 * y['rel_error']:+.2f} % from the 2D block, tolerance "
                 f"{100 * TOLERANCE_YADE:g} %)" if y and y["threshold_g"] else "")]
    lo, hi = out["eq43"]["omega_ratio_range"]
    lines.append(f"Eq. 43, a_po / (alpha g) = 1 + omega_p / (4 p): within "
                 f"{100 * out['eq43']['max_rel_error_2d']:.1f} % of the 2D block for omega_p / p "
                 f"{lo:g}-{hi:g} (stated +-{100 * EQ43_SPREAD:g} %); beyond ~3.7 the block "
                 "overturns only without an impact, at amplitudes growing as omega_p^2")
    for row in out["safe_bands"]:
        spans = ", ".join(f"{a:.3f}-{'' if b is None else f'{b:.3f}'} g"
                          for a, b in row["overturning_g"])
        lines.append(f"Overturning intervals, {row['block']} block, PGV/PGA "
                     f"{row['pgv_pga_s']:.3f} s (T_p {row['period_s']:.3f} s), up to "
                     f"{SCAN_MAX_G[row['block']]:g} g: {spans or 'none'}")
    return lines
