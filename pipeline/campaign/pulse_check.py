"""A pulse-grid fragility of SP1 against its shake-table tests (records/shake_table/tests.csv:
PGA, PGV/PGA and SP1's outcome of every test, the 92 without a motion included; only
SP1's outcomes are read).  The tests' motions are table records, not pulses: the scores
say how far the pulse fragility carries over to them.

Scores of the observed outcomes under: the fragility (P between the grid's cells by
their one interpolation, bilinear in ln PGA and ln PGV/PGA, empty cells filled, as
survival reads them; tests outside the grid take the nearest edge, counted in
``outside_grid``), its logistic surface, "overturns when PGA >= g tan alpha" (the 2D
block's critical angle) and a logistic surface fitted to the observations themselves
(the ceiling a smooth surface in these two measures reaches).  Log-likelihood per test
(probabilities clipped to [0.01, 0.99], so that a certain wrong prediction costs
ln 0.01, not -inf) and the Brier score (mean squared error of P; 0.25 for P = 0.5
everywhere)."""
import math

import numpy as np

from pipeline.campaign.shake_table_experiments import (EXPERIMENTS, OUTCOME, PGA_EDGES_G, PGV_PGA_EDGES_S,
                                           load_experiments)
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.pulse_cells import fill_empty, interpolate, lay_cells
from pipeline.stats.ensemble import wilson_interval
from pipeline.stats.fragility import logistic_probability, logistic_surface

SPECIMENS_WITH_TESTS = {"SP1": OUTCOME}
CLIP = 0.01


def scores(observed, probability):
    """{"log_likelihood_per_test", "brier", "n"} of 0/1 ``observed`` under ``probability``."""
    y = np.asarray(observed, float)
    p = np.clip(np.asarray(probability, float), CLIP, 1 - CLIP)
    return {"log_likelihood_per_test": float(np.mean(y * np.log(p) + (1 - y) * np.log(1 - p))),
            "brier": float(np.mean((np.asarray(probability, float) - y) ** 2)),
            "n": int(y.size)}


def grid_probability(section, cells, pga_g, ratio):
    """P of a model's ``cells`` on the axes of ``section`` (its pulse grid) at the tests
    by the pulse grid's one interpolation (:func:`pipeline.hazard.pulse_cells.interpolate`:
    bilinear in ln PGA, ln PGV/PGA, as survival reads it), the nearest edge cell's P
    outside the grid, empty cells filled by survival's rule
    (:func:`pipeline.hazard.pulse_cells.fill_empty`); (P, outside, cells filled), or
    (None, None, 0) when no cell holds a P."""
    _, _, values, _ = lay_cells(section.pga_g, section.pgv_pga_s, cells)
    if np.isnan(values).all():
        return None, None, 0
    values, filled = fill_empty(values)
    return (*interpolate(section.pga_g, section.pgv_pga_s, values, pga_g, ratio), filled)


def experiments_check(section, specimen, experiments=EXPERIMENTS):
    """The ``experiments`` entry of ``pulse_grid`` (``section``, a
    :class:`~pipeline.hazard.fragility.file.PulseGridSection`) for a specimen with shipped
    tests (None for others)."""
    outcome = SPECIMENS_WITH_TESTS.get(specimen)
    if outcome is None:
        return None
    frame = load_experiments(experiments, outcome)
    pga = frame["pga_g"].to_numpy(float)
    ratio = frame["pgv_pga_s"].to_numpy(float)
    y = frame["observed"].to_numpy(bool)
    uplift = section.block2d.uplift_g
    out = {"tests": int(len(frame)), "overturned": int(y.sum()), "outcome": outcome,
           "direction": section.direction,
           "note": "table records, not pulses: how far the pulse fragility carries over",
           "baselines": {f"PGA >= g tan alpha ({uplift:.3f} g)": scores(y, pga >= uplift)}}
    keep = (pga > 0) & (ratio > 0)
    ceiling = logistic_surface(pga[keep] * G, ratio[keep], y[keep])
    if ceiling["coefficients"] is not None:
        out["baselines"]["logistic fit to the observations (ceiling)"] = scores(
            y[keep], logistic_probability(ceiling["coefficients"], pga[keep] * G,
                                          ratio[keep]))
    models = {}
    for model, entry in section.models.items():
        p, outside, filled = grid_probability(section, entry.cells, pga, ratio)
        if p is None:
            continue
        result = {"grid": {**scores(y, p), "outside_grid": int(outside.sum())}}
        if filled:
            result["grid"]["empty_cells_filled"] = filled
        coef = None if entry.logistic is None else entry.logistic.coefficients
        if coef is not None:
            result["logistic"] = scores(y[keep], logistic_probability(
                coef, pga[keep] * G, ratio[keep]))
        result["bins"] = _bins(pga, ratio, y, p)
        models[model] = result
    out["models"] = models
    return out


def _bins(pga, ratio, y, p):
    """Observed rate (Wilson 95 %) and mean predicted P per PGA x PGV/PGA bin of the
    shake-table figure."""
    rows = []
    for i in range(len(PGA_EDGES_G) - 1):
        for j in range(len(PGV_PGA_EDGES_S) - 1):
            inside = ((pga >= PGA_EDGES_G[i]) & (pga < PGA_EDGES_G[i + 1])
                      & (ratio >= PGV_PGA_EDGES_S[j]) & (ratio < PGV_PGA_EDGES_S[j + 1]))
            n = int(inside.sum())
            if not n:
                continue
            k = int(y[inside].sum())
            rows.append({"pga_g": [float(PGA_EDGES_G[i]), float(PGA_EDGES_G[i + 1])],
                         "pgv_pga_s": [float(PGV_PGA_EDGES_S[j]), float(PGV_PGA_EDGES_S[j + 1])],
                         "n": n, "overturned": k, "observed_rate": k / n,
                         "observed_ci95": list(wilson_interval(k, n)),
                         "predicted_mean": float(np.mean(p[inside]))
                         if math.isfinite(np.mean(p[inside])) else None})
    return rows
