"""The pulse grid of the ``fragility`` campaign: P(overturn) of any specimen (a mesh
specimen such as a scanned rock, or a column) over PGA x PGV/PGA of one-cosine
displacement pulses (:func:`pipeline.motion.pulses.one_cosine_pulse`, the Virtual Shake
Robot's grid: Chen et al. 2024, Seismica 3(1)).

The unknowns are ensemble members, not fixed values: ``--members`` parameter sets (a
Latin hypercube over ``--ranges``: contact stiffness kn, log-uniform; damping; static
friction mu_s, with mu_k in the calibration's ratio to it; a mesh specimen's footprint
tolerance), each shaken by every pulse from ``--headings`` directions.  The direction
is a fixed azimuth (``--azimuth``, a table) or, by default, sampled per member over
360 deg relative to the specimen's heading (a field rock: the direction it is shaken
from is unknown), stratified so that each member's directions cover the circle.

Per grid cell and specimen model: n runs, overturned, P with its Wilson 95 % interval
(Monte Carlo error of the pooled estimate), P per parameter set and their spread (the
part of the uncertainty the unknown parameters carry, after the binomial noise of each
set's own estimate is removed).  Contours at the P of ``CONTOUR_LEVELS``, in PGA per PGV/PGA
(linear between cells), with the contours of the Wilson bounds as their Monte Carlo
band; the logistic surface of Purvance et al. (2008) in dimensionless groups; the 2D
rigid block of the same critical angle and pivot distance (the toolkit's Housner
integrator, :func:`pipeline.rocking.rocking_response_sampled`) under the same pulses.
"""
import math

import numpy as np
from scipy.stats import qmc

from pipeline.campaign.column_file import column_kn
from pipeline.campaign.shake_table import GRID_CONTACT, GRID_SPECIMEN, neighbourhood_ranges
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.pulse_cells import CONTOUR_LEVELS
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.rocking import block_constants, rocking_response_sampled
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.parameters import kinetic_friction
from pipeline.stats.ensemble import logistic_surface, wilson_interval

G = STANDARD_GRAVITY               # m/s^2 per g (the grid's PGA is in g)
VSR_PULSES = "pga_g=0.2:1.1:10;pgv_pga_s=0.1:1.0:10"   # Chen et al. (2024)
PULSE_PRESETS = {"vsr": VSR_PULSES}
PULSE_AXES = {"pga_g": (0.01, 5.0), "pgv_pga_s": (0.01, 3.0)}
MAX_AXIS_SIZE = 50
PULSE_DT_S = 0.005                # sample interval of the pulses, at most
PULSE_TAIL_S = 4.0                # at rest after the pulse: the body settles or falls
# member ranges: defaults from the shake-table calibration's neighbourhood
# (shake_table.CALIBRATION_NEIGHBOURHOOD); bounds as the calibration's --grid
RANGE_BOUNDS = {"kn": GRID_CONTACT["kn"], "damping": GRID_CONTACT["damping"],
                "mu_s": GRID_CONTACT["mu_s"], **GRID_SPECIMEN}
DEFAULT_RANGES = neighbourhood_ranges()
LOG_UNIFORM = ("kn",)
# the long-run gate's cost of a run, at most (it stops early once the specimen has fallen
# or settled): SP1 over the vsr grid took 1,600 runs in 166 s on 2 cores (2026-11-27),
# 0.09 s of YADE per simulated second (runs stop early: the bound takes twice that) and
# about 0.1 s per run besides
RUN_CORE_S_PER_MOTION_S = 0.2
RUN_CORE_S_PER_RUN = 0.3


def parse_pulses(text):
    """``pga_g=LO:HI:N;pgv_pga_s=LO:HI:N`` or a preset (``vsr``) -> {"pga_g": array,
    "pgv_pga_s": array} (linear, LO and HI included; N = 1 needs LO = HI)."""
    text = str(text).strip()
    text = PULSE_PRESETS.get(text.lower(), text)
    axes = {}
    for item in text.split(";"):
        if not item.strip():
            continue
        name, _, value = (s.strip() for s in item.partition("="))
        if name not in PULSE_AXES:
            raise InputError(f"--pulses: unknown axis {name!r} (give pga_g=LO:HI:N;"
                             "pgv_pga_s=LO:HI:N, or the preset vsr)")
        if name in axes:
            raise InputError(f"--pulses names {name} twice")
        parts = value.split(":")
        try:
            lo, hi, n = float(parts[0]), float(parts[1]), parts[2]
            if len(parts) != 3 or not n.strip().isdigit():
                raise ValueError
            n = int(n)
        except (ValueError, IndexError):
            raise InputError(f"--pulses {name}={value!r}: expected LO:HI:N (N a whole "
                             "number)") from None
        low, high = PULSE_AXES[name]
        if not (math.isfinite(lo) and math.isfinite(hi) and low <= lo <= hi <= high):
            raise InputError(f"--pulses {name}: need {low:g} <= LO <= HI <= {high:g}, got "
                             f"{value}")
        if not 1 <= n <= MAX_AXIS_SIZE or (n == 1) != (lo == hi):
            raise InputError(f"--pulses {name}: N must be 1-{MAX_AXIS_SIZE}, and 1 exactly "
                             f"when LO = HI, got {value}")
        axes[name] = np.round(np.linspace(lo, hi, n), 9)
    missing = [a for a in PULSE_AXES if a not in axes]
    if missing:
        raise InputError(f"--pulses lacks {missing[0]} (give pga_g=LO:HI:N;pgv_pga_s=LO:HI:N, "
                         "or the preset vsr)")
    return axes


def parse_ranges(text, mesh=True):
    """``name=LO:HI;...`` -> {name: (lo, hi)}: for a mesh specimen over the defaults
    (:data:`DEFAULT_RANGES`, from the shake-table calibration of a rock), for a column
    over none (the paper's values, or a description's matched kn); LO = HI fixes a
    value; footprint_tolerance_m only for a mesh specimen."""
    ranges = {}
    for source in ((DEFAULT_RANGES,) if mesh else ()) + (text or "",):
        given = {}
        for item in source.split(";"):
            if not item.strip():
                continue
            name, _, value = (s.strip() for s in item.partition("="))
            if name not in RANGE_BOUNDS:
                raise InputError(f"--ranges: unknown parameter {name!r} (known: "
                                 f"{', '.join(RANGE_BOUNDS)})")
            if name in given:
                raise InputError(f"--ranges names {name} twice")
            try:
                lo, hi = (float(v) for v in value.split(":"))
            except ValueError:
                raise InputError(f"--ranges {name}={value!r}: expected LO:HI") from None
            low, high = RANGE_BOUNDS[name]
            if not (math.isfinite(lo) and math.isfinite(hi) and low <= lo <= hi <= high):
                raise InputError(f"--ranges {name}: need {low:g} <= LO <= HI <= {high:g}, "
                                 f"got {value}")
            given[name] = (lo, hi)
        if "footprint_tolerance_m" in given and not mesh:
            raise InputError("--ranges footprint_tolerance_m: only a mesh specimen has a "
                             "footprint tolerance")
        ranges.update(given)
    return ranges


def sample_sets(members, seed, ranges):
    """``members`` parameter sets: one Latin hypercube over ``ranges`` (kn log-uniform);
    mu_k from mu_s by the contact's one rule (:func:`~pipeline.scenario.parameters.kinetic_friction`)."""
    names = sorted(ranges)
    if not names:
        return [{} for _ in range(members)]
    u = qmc.LatinHypercube(d=len(names), seed=seed).random(members)
    sets = []
    for row in u:
        point = {}
        for name, q in zip(names, row):
            lo, hi = ranges[name]
            if name in LOG_UNIFORM:
                point[name] = float(math.exp(math.log(lo) + q * (math.log(hi) - math.log(lo))))
            else:
                point[name] = float(lo + q * (hi - lo))
            point[name] = float(f"{point[name]:.6g}")
        if "mu_s" in point:
            point["mu_k"] = kinetic_friction(point["mu_s"])
        sets.append(point)
    return sets


def member_azimuths(members, headings, seed, heading_deg=0.0):
    """(members, headings) shaking azimuths (deg): stratified over 360 deg per member
    (heading j of ``headings`` in [j, j + 1) * 360 / headings, uniform), relative to the
    specimen's heading (turning the specimen turns them with it)."""
    rng = np.random.default_rng([int(seed), 4242])
    u = (np.arange(headings)[None, :] + rng.random((members, headings))) / headings
    return np.round((heading_deg + 360.0 * u) % 360.0, 6)


def pulse_file(cache_dir, pga_m_s2, pgv_pga_s):
    """The pulse of one cell along North (a run turns it by its azimuth), saved once."""
    name = f"cosine_pulse_{pga_m_s2:.6g}ms2_{pgv_pga_s:.6g}s.npz"
    path = cache_dir / name
    if not path.is_file():
        cache_dir.mkdir(parents=True, exist_ok=True)
        one_cosine_pulse(pga_m_s2, pgv_pga_s, 0.0, PULSE_DT_S, PULSE_TAIL_S).save(path)
    return path


def pulse_runs(data, column, pulses, members, headings, azimuth, seed, ranges,
               stiffness="matched", contact=None):
    """(pulse cells, [(pga, ratio, params, tags)]): every cell x parameter set x heading.
    ``data``: the description dict (None: the paper's column); ``contact``: a contact
    file's values, fixed for every run (not drawn; a --ranges of a field it sets is
    refused)."""
    mesh = data is not None and "mesh" in data
    grid = parse_pulses(pulses)
    if contact:
        from pipeline.scenario.contact_file import refuse_set_twice
        given = parse_ranges(ranges, mesh=False)           # those --ranges names
        refuse_set_twice(contact, [f for name in given
                                   for f in ((name, "mu_k") if name == "mu_s" else (name,))],
                         "--ranges")
    ranges = {k: v for k, v in parse_ranges(ranges, mesh).items()
              if not (contact and (k in contact or (k == "mu_s" and "mu_k" in contact)))}

    if not (isinstance(headings, int) and 1 <= headings <= 360):
        raise InputError(f"--headings must be an integer in [1, 360], got {headings!r}")
    if azimuth is not None:
        if not (math.isfinite(azimuth) and 0 <= azimuth < 360):
            raise InputError(f"--azimuth must be in [0, 360) deg, got {azimuth:g}")
        if headings != 1:
            raise InputError("--azimuth fixes the direction: --headings must be 1")
    sets = sample_sets(members, seed, ranges)
    if azimuth is not None and members > 1 and all(lo == hi for lo, hi in ranges.values()):
        raise InputError(f"--members {members} with nothing drawn (no --ranges) and a fixed "
                         "--azimuth would repeat one run: give --ranges or --members 1")
    if azimuth is None:
        heading = float(data.get("heading_deg", 0.0)) if mesh else 0.0
        azimuths = member_azimuths(members, headings, seed, heading)
    else:
        azimuths = np.full((members, 1), float(azimuth))
    runs = []
    for i, ratio in enumerate(grid["pgv_pga_s"]):
        for j, pga_g in enumerate(grid["pga_g"]):
            for m, point in enumerate(sets):
                for h in range(azimuths.shape[1]):
                    params = {"column": "monolithic" if mesh else column, **(contact or {}),
                              **{k: v for k, v in point.items() if k in GRID_CONTACT},
                              "rotate_deg": float(azimuths[m, h])}
                    if data is not None:
                        params["column_file"] = {**data, **{k: v for k, v in point.items()
                                                            if k in GRID_SPECIMEN}}
                    if "kn" not in point and "kn" not in (contact or {}) and data is not None:
                        params["kn"] = column_kn(data, stiffness)
                    runs.append((round(float(pga_g) * G, 6), round(float(ratio), 6), params,
                                 {"cell": [i, j], "pga_g": float(pga_g),
                                  "pgv_pga_s": float(ratio), "member": m, "heading": h,
                                  "azimuth_deg": float(azimuths[m, h]), "point": point}))
    return grid, sets, azimuths, runs


def run_core_s(pgv_pga_s):
    """Core seconds of one run (the long-run gate's estimate): its pulse and tail at
    RUN_CORE_S_PER_MOTION_S."""
    return RUN_CORE_S_PER_RUN + (2 * math.pi * pgv_pga_s + PULSE_TAIL_S) * RUN_CORE_S_PER_MOTION_S


# ---------------------------------------------------------------- 2D block
def block_of(params, azimuth_deg):
    """(height, width) m of the 2D block of the same critical angle and pivot distance
    as the specimen of ``params`` shaken along ``azimuth_deg``: a mesh specimen's
    centre-of-mass height and its smaller lever across that line (critical angle
    :meth:`~pipeline.scenario.mesh.MeshSpecimen.critical_angle_along_deg`), a column's
    overall height and base width."""
    described = params.column.column_file
    if described is not None and "mesh" in described:
        specimen = _specimen(described)
        angle = math.radians(specimen.critical_angle_along_deg(azimuth_deg))
        com_z = float(specimen.com[2])
        return 2 * com_z, 2 * com_z * math.tan(angle)
    return block_size(params)

BLOCK_T_AFTER_S = 30.0          # the 2D block's free rocking after the motion, at most
BLOCK_MAX_STEP_S = 1e-3         # the 2D block's integration step, at most


def block_size(params):
    """(height, width) in m of the 2D block of a run (``params``:
    :class:`~pipeline.scenario.parameters.RunParams`): the paper column's height and
    diameter, or a description's overall height and base width."""
    column = params.column
    if column.column_file is None:
        return column.height, column.height / column.hd
    blocks = column.column_file["blocks"]        # as ColumnGeometry.height and .base_width
    bottom = blocks[0]
    width = (bottom["bottom_diameter"] if bottom["shape"] == "frustum"
             else min(bottom["width"], bottom["depth"]))
    return math.fsum(b["height"] for b in blocks), width


_SPECIMENS = {}


def _specimen(described):
    key = repr(sorted((k, repr(v)) for k, v in described.items()))
    if key not in _SPECIMENS:
        _SPECIMENS[key] = ColumnGeometry.from_dict(described)
    return _SPECIMENS[key]


def block_outcomes(specs, t_after=BLOCK_T_AFTER_S, max_step=BLOCK_MAX_STEP_S):
    """Overturned (bool array, one per spec) of the 2D block of each run under its pulse:
    the pulse along the run's azimuth is the same scalar series for every direction."""
    out = np.zeros(len(specs), bool)
    by_cell = {}
    for k, spec in enumerate(specs):
        by_cell.setdefault((spec.tags["pga_g"], spec.tags["pgv_pga_s"]), []).append(k)
    for (pga_g, ratio), idx in by_cell.items():
        pulse = one_cosine_pulse(pga_g * G, ratio, 0.0, PULSE_DT_S, 0.0)
        sizes = np.array([block_of(specs[k].params, specs[k].tags["azimuth_deg"])
                          for k in idx], float)
        acc = np.repeat(pulse.acc[:, 1:2], len(idx), axis=1)       # (n, cases)
        result = rocking_response_sampled(sizes[:, 0], sizes[:, 1], acc, pulse.dt,
                                          t_after=t_after, max_step=max_step)
        out[idx] = result["overturned"]
    return out


# ---------------------------------------------------------------- summary
def cell_table(table, model):
    """Per cell of one model: n, overturned, P, Wilson ci95, P per parameter set and their
    spread (sd across sets; ``set_spread_sd``: with each set's binomial noise removed)."""
    sub = table[table["model"] == model]
    cells = []
    for (ratio, pga_g), group in sub.groupby(["pgv_pga_s", "pga_g"], sort=True):
        k, n = int(group["toppled"].sum()), len(group)
        lo, hi = wilson_interval(k, n)
        per_set = group.groupby("member")["toppled"].agg(["mean", "count"])
        p_sets = per_set["mean"].to_numpy(float)
        counts = per_set["count"].to_numpy(float)
        between = float(np.var(p_sets, ddof=1)) if len(p_sets) > 1 else 0.0
        within = float(np.mean(p_sets * (1 - p_sets) / np.maximum(counts - 1, 1))) \
            if (counts > 1).all() else float("nan")
        cells.append({"pga_g": float(pga_g), "pgv_pga_s": float(ratio), "n": n,
                      "overturned": k, "P": k / n, "ci95": [lo, hi],
                      "P_per_set": [float(v) for v in p_sets],
                      "sets": [int(m) for m in per_set.index],
                      "set_sd": math.sqrt(between),
                      "set_spread_sd": math.sqrt(max(between - within, 0.0))
                      if math.isfinite(within) else None})
    return cells


def contours(cells, levels=CONTOUR_LEVELS):
    """Per level and PGV/PGA: the PGA (g) where P crosses the level (linear between the
    cells; P made non-decreasing in PGA first), with the PGAs where the Wilson upper and
    lower bounds cross it (the Monte Carlo band: ``pga_g_band``; the bounds made
    monotone as P is: a cell's lower bound holds every cell above it, its upper bound
    every cell below, so a cell of few runs beside a cell of many does not open the band) and where each parameter
    set's own P crosses it (``pga_g_per_set``, for the sets run in every cell of the row:
    the members' spread); None beyond the grid, and ``outside_grid`` says on which side
    (:func:`_outside`)."""
    out = {}
    ratios = sorted({c["pgv_pga_s"] for c in cells})
    for level in levels:
        rows = []
        for ratio in ratios:
            row = sorted((c for c in cells if c["pgv_pga_s"] == ratio), key=lambda c: c["pga_g"])
            pga = np.array([c["pga_g"] for c in row])
            upper = np.array([c["ci95"][1] for c in row])
            upper = np.minimum.accumulate(upper[::-1])[::-1]     # holds every cell below
            crossing = [_crossing(pga, values, level) for values in (
                np.array([c["P"] for c in row]), upper,
                np.array([c["ci95"][0] for c in row]))]
            entry = {"pgv_pga_s": ratio, "pga_g": crossing[0],
                     "pga_g_band": [crossing[1], crossing[2]],
                     "outside_grid": _outside(np.array([c["P"] for c in row]), level)}
            if all("sets" in c for c in row):
                common = set.intersection(*(set(c["sets"]) for c in row))
                entry["pga_g_per_set"] = {
                    str(m): _crossing(pga, np.array([c["P_per_set"][c["sets"].index(m)]
                                                     for c in row]), level)
                    for m in sorted(common)}
            rows.append(entry)
        out[f"{level:g}"] = rows
    return out


def _crossing(x, p, level):
    p = np.maximum.accumulate(p)
    above = np.nonzero(p >= level)[0]
    if not above.size or len(x) < 2:
        return None
    k = int(above[0])
    if k == 0:
        return None if p[0] > level else float(x[0])
    return float(x[k - 1] + (level - p[k - 1]) * (x[k] - x[k - 1]) / (p[k] - p[k - 1]))


def _outside(p, level):
    """Where the ``level`` contour of a row lies when the grid does not hold it: "below"
    (P, made non-decreasing in PGA, is above the level already at the grid's first PGA),
    "above" (P never reaches it) or None (it crosses inside, or one PGA only)."""
    p = np.maximum.accumulate(np.asarray(p, float))
    if len(p) < 2:
        return None
    if p[0] > level:
        return "below"
    return "above" if p[-1] < level else None


def contour_warnings(models, pga_g):
    """One line per model, level and side where a contour leaves the grid (``outside_grid``
    of :func:`contours`), naming the PGV/PGA rows and the grid's edge: the surface there
    is not measured, and whatever integrates over it (survival) extrapolates."""
    out = []
    for model, entry in models.items():
        for level, rows in entry["contours"].items():
            for side, edge in (("below", min(pga_g)), ("above", max(pga_g))):
                ratios = [r["pgv_pga_s"] for r in rows if r.get("outside_grid") == side]
                if ratios:
                    out.append(
                        f"{model}: the P = {level} contour lies {side} the grid's "
                        f"{'lowest' if side == 'below' else 'highest'} PGA ({edge:g} g) for "
                        f"PGV/PGA {', '.join(f'{v:g}' for v in ratios)} s (P is "
                        f"{'above' if side == 'below' else 'below'} {level} at the edge): the "
                        f"grid does not hold it; extend --pulses to "
                        f"{'lower' if side == 'below' else 'higher'} PGA")
    return out


def block_reference(specs):
    """alpha (rad), R (m), p (1/s) of the 2D block: medians over the runs; and
    ``alpha_smallest`` (rad), the smallest critical angle of any run's block."""
    sizes = np.array([block_of(s.params, s.tags["azimuth_deg"]) for s in specs], float)
    c = block_constants(float(np.median(sizes[:, 0])), float(np.median(sizes[:, 1])))
    return {**c, "alpha_smallest": float(np.min(np.arctan2(sizes[:, 1], sizes[:, 0])))}


def summarise_grid(table, specs, grid, sets, azimuths, azimuth, ranges_text):
    """The ``pulse_grid`` section of fragility.json."""
    block = block_reference(specs)
    models = {}
    for model in sorted(set(table["model"])):
        sub = table[table["model"] == model]
        cells = cell_table(table, model)
        y = sub["toppled"].astype(bool).to_numpy()
        models[model] = {
            "cells": cells, "contours": contours(cells),
            "logistic": logistic_surface(sub["pga_g"].to_numpy(float) * G,
                                         sub["pgv_pga_s"].to_numpy(float), y,
                                         alpha=block["alpha"], p=block["p"]),
            "runs": int(len(sub)), "overturned": int(y.sum())}
    return {
        "pulse": "one-cosine displacement d(t) = A - A cos(2 pi F t), F = 1/(2 pi PGV/PGA), "
                 "one cycle, then at rest for the body to settle",
        "pga_g": [float(v) for v in grid["pga_g"]],
        "pgv_pga_s": [float(v) for v in grid["pgv_pga_s"]],
        "tail_s": PULSE_TAIL_S, "g_m_s2": G,
        "direction": ("fixed azimuth {:g} deg (a table)".format(azimuth) if azimuth is not None
                      else "sampled per member over 360 deg relative to the specimen's heading "
                           "(a field rock: the direction is unknown)"),
        "azimuths_deg": azimuths.tolist(),
        "members": len(sets), "headings": int(azimuths.shape[1]),
        "ranges": ranges_text, "parameter_sets": sets,
        "contour_levels": list(CONTOUR_LEVELS),
        "warnings": contour_warnings(models, grid["pga_g"]),
        "uncertainty": "ci95: Wilson 95 % interval of the pooled P (Monte Carlo error); "
                       "P_per_set: P of each parameter set over its headings; set_sd: their "
                       "standard deviation; set_spread_sd: with each set's binomial variance "
                       "removed (the spread the unknown parameters carry)",
        "block2d": {"alpha_rad": block["alpha"], "R_m": block["R"], "p_per_s": block["p"],
                    "uplift_g": math.tan(block["alpha"]),
                    "uplift_g_smallest": math.tan(block["alpha_smallest"]),
                    "definition": "2D rigid block of the specimen's critical angle and pivot "
                                  "distance along each run's azimuth (Housner's equation "
                                  "and restitution, pipeline.rocking.rocking_response_sampled); "
                                  "its constants the runs' medians; uplift_g_smallest: g tan "
                                  "of the smallest critical angle of any run (no run's rigid "
                                  "block leaves rest below it)"},
        "models": models}


# ---------------------------------------------------------------- adaptive sampling
MAX_STAGES = 12
ADAPTIVE_LEVEL = 0.5        # the contour whose side every cell is decided on
# a cell near a change runs this many first: all alike, its Wilson interval excludes
# ADAPTIVE_LEVEL (0 of 4 overturned: upper bound 0.49)
ADAPTIVE_FIRST_RUNS = 4


def cell_key(spec):
    return tuple(spec.tags["cell"])


def run_order(member, heading, headings):
    """Sort key of a cell's runs: its first runs are distinct parameter sets shaken from
    distinct direction sectors (the diagonals of the members x headings square)."""
    return ((heading - member) % headings, member)


def guide_cells(guide_p, margin=1):
    """Cells (i ratio, j PGA) near the guide's threshold: where the guide's P (a dict
    cell -> P, e.g. the 2D block over the same members and directions) is strictly
    between 0 and 1, and ``margin`` cells either side in PGA (the specimen's threshold
    may lie beside the guide's); a step of the guide between two cells counts as
    uncertain on both sides."""
    chosen = set()
    for (i, j), p in guide_p.items():
        step = any(guide_p.get((i, j + d), p) != p for d in (-1, 1))
        if 0.0 < p < 1.0 or step:
            chosen.update((i, j + d) for d in range(-margin, margin + 1)
                          if (i, j + d) in guide_p)
    return chosen


def first_crossings(p_by_cell, level=ADAPTIVE_LEVEL):
    """Per row i (a PGV/PGA): the first cell j (lowest PGA) whose P reaches ``level``,
    where :func:`contours` finds the ``level`` contour (P made non-decreasing in PGA)."""
    crossing = {}
    for (i, j), p in sorted(p_by_cell.items()):
        if i not in crossing and p >= level:
            crossing[i] = j
    return crossing


def first_targets(guide_p, per_cell, first=ADAPTIVE_FIRST_RUNS, margin=1):
    """Runs per cell of the first stage: ``first`` near the guide's threshold
    (:func:`guide_cells`) up to ``margin`` cells above the first cell where the guide's P
    reaches 0.5 (the cells above do not move the 0.5 contour), one probe run elsewhere
    (at most ``per_cell``)."""
    near = guide_cells(guide_p, margin)
    top = first_crossings(guide_p)
    return {(i, j): min(per_cell, first if (i, j) in near and j <= top.get(i, j) + margin
                        else 1)
            for (i, j) in guide_p}


def next_targets(guide_p, outcomes, targets, per_cell, first=ADAPTIVE_FIRST_RUNS,
                 level=ADAPTIVE_LEVEL):
    """Runs per cell of the next stage (never fewer than ``targets``), from the outcomes
    so far (cell -> overturned per finished run, in :func:`run_order`), row by row (a
    PGV/PGA) as :func:`contours` reads them: the ``level`` contour lies below the first
    cell whose P reaches ``level``. That cell and the one below it run all ``per_cell``
    runs, the full grid's count: the contour's position rests on them. The cells above
    them do not move it and stop. A cell below them whose Wilson 95 % interval excludes
    ``level`` is decided and stops; otherwise, with mixed outcomes or ``first`` runs or
    more, it doubles (up to ``per_cell``); with fewer runs all alike (a probe) it goes to
    ``first`` only next to a change: a neighbour in PGA with another outcome, or its
    outcome against the guide's (P >= 0.5); elsewhere it stays a probe."""
    new = dict(targets)
    crossing = first_crossings({cell: np.mean(fell) for cell, fell in outcomes.items() if fell},
                               level)
    for (i, j), fell in outcomes.items():
        m, k = len(fell), int(sum(fell))
        lo, hi = wilson_interval(k, m)
        top = crossing.get(i)
        if top is not None and top > 0 and j in (top - 1, top):
            want = per_cell if m >= first else first
        elif top is not None and j > top or m == 0 or not lo <= level <= hi:
            continue
        elif 0 < k < m or m >= first:
            want = max(first, 2 * m)
        else:
            alike = k == m
            beside = [outcomes.get((i, j + d)) or [] for d in (-1, 1)]
            if not (any(v != alike for row in beside for v in row)
                    or (guide_p[(i, j)] >= 0.5) != alike):
                continue
            want = first
        new[(i, j)] = max(new[(i, j)], min(per_cell, want))
    return new


def adaptive_sampling(guide_p, per_cell, run_stage, max_stages=MAX_STAGES):
    """The stages of the adaptive pulse grid: ``run_stage(stage, targets)`` runs the first
    ``targets[cell]`` runs of every cell (in :func:`run_order`) and returns their outcomes
    (cell -> overturned per finished run); from :func:`first_targets` until
    :func:`next_targets` changes nothing. Returns (targets, settled: False when
    ``max_stages`` ran out first)."""
    targets = first_targets(guide_p, per_cell)
    for stage in range(1, max_stages + 1):
        new = next_targets(guide_p, run_stage(stage, targets), targets, per_cell)
        if new == targets:
            return targets, True
        targets = new
    return targets, False


def contour_difference(reference, other, level="0.5"):
    """How far the P = ``level`` contour of ``other`` lies from that of ``reference`` (two
    :class:`~pipeline.hazard.fragility_file.FragilityFile` of the same pulse grid, e.g.
    the adaptive surface and the full
    grid): per PGV/PGA of the specimen model (not the 2D block) both PGAs (g), their
    difference and the reference's Monte Carlo band (the PGAs where its Wilson bounds
    cross the level); ``max_abs_diff_g`` over the rows where both cross (None if none),
    ``one_sided`` the rows where only one does, ``within_band`` whether every crossing of
    ``other`` lies inside the reference's band (an open side counts as open)."""
    def rows(summary):
        models = summary.pulse_grid.models
        specimen = [m for m in models if m != "block2d"]
        if len(specimen) != 1:
            raise ValueError(f"expected one specimen model beside block2d, got {specimen}")
        return {r["pgv_pga_s"]: r for r in models[specimen[0]].contours[level]}
    ref, oth = rows(reference), rows(other)
    if set(ref) != set(oth):
        raise ValueError("the two fragility.json files are not of the same pulse grid")
    table, diffs, one_sided, within = [], [], 0, True
    for ratio in sorted(ref):
        a, b = ref[ratio]["pga_g"], oth[ratio]["pga_g"]
        lo, hi = ref[ratio]["pga_g_band"]
        diff = None if a is None or b is None else b - a
        if diff is not None:
            diffs.append(abs(diff))
        elif (a is None) != (b is None):
            one_sided += 1
        if b is not None and not ((lo is None or lo <= b) and (hi is None or b <= hi)):
            within = False
        table.append({"pgv_pga_s": ratio, "pga_g_reference": a, "pga_g_other": b,
                      "diff_g": diff, "reference_band_g": [lo, hi]})
    return {"level": float(level), "rows": table,
            "max_abs_diff_g": max(diffs) if diffs else None,
            "one_sided": one_sided, "within_band": within and one_sided == 0}
