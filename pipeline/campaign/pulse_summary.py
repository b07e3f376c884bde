"""The summary of the pulse grid (:mod:`pipeline.campaign.pulse_grid`), the ``pulse_grid``
section of fragility.json.  Per grid cell and specimen model: n runs, overturned, P with
its Wilson 95 % interval (Monte Carlo error of the pooled estimate), P per parameter set
and their spread (the part of the uncertainty the unknown parameters carry, after the
binomial noise of each set's own estimate is removed).  Contours at the P of
``CONTOUR_LEVELS``, in PGA (g) per PGV/PGA (s) (linear between cells), with the contours
of the Wilson bounds as their Monte Carlo band; the logistic surface of Purvance et al.
(2008) in dimensionless groups; the 2D rigid block of the same critical angle and pivot
distance (:mod:`pipeline.campaign.pulse_block`) under the same pulses.
"""
import math

import numpy as np

from pipeline.campaign.pulse_block import block_reference
from pipeline.campaign.pulse_grid import G, PULSE_TAIL_S
from pipeline.hazard.pulse_cells import CONTOUR_LEVELS
from pipeline.stats.ensemble import wilson_interval
from pipeline.stats.fragility import logistic_surface


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
                           "(a field rock: the direction is unknown)")
                     + (", less each member's yaw_deg" if any(p.get("yaw_deg") for p in sets)
                        else ""),
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
                                  "and restitution, "
                                  "pipeline.rocking.sampled.rocking_response_sampled); "
                                  "its constants the runs' medians; uplift_g_smallest: g tan "
                                  "of the smallest critical angle of any run (no run's rigid "
                                  "block leaves rest below it)"},
        "models": models}


def contour_difference(reference, other, level=0.5):
    """How far the P = ``level`` contour of ``other`` lies from that of ``reference`` (two
    :class:`~pipeline.hazard.fragility.file.FragilityFile` of the same pulse grid, e.g.
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
        return {r.pgv_pga_s: r for r in models[specimen[0]].contour(level)}
    ref, oth = rows(reference), rows(other)
    if set(ref) != set(oth):
        raise ValueError("the two fragility.json files are not of the same pulse grid")
    table, diffs, one_sided, within = [], [], 0, True
    for ratio in sorted(ref):
        a, b = ref[ratio].pga_g, oth[ratio].pga_g
        lo, hi = ref[ratio].pga_g_band
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
