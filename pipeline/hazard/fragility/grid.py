"""A pulse grid as a fragility (:class:`PulseGrid`): P(overturn | PGA, PGV/PGA) read from
the cells of ``campaign fragility --pulses`` by their one interpolation
(:mod:`pipeline.hazard.pulse_cells`), carried outside the grid by the logistic surface
fitted to the same runs, and below its first PGA as :data:`BELOW_GRID` says."""
import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.fragility.kinds import Fragility, Logistic
from pipeline.hazard.pulse_cells import fill_empty, interpolate

BELOW_GRID = ("ramp", "zero", "edge", "logistic")   # P below a pulse grid: see PulseGrid


@dataclass(frozen=True)
class PulseGrid(Fragility):
    """P(overturn | PGA, PGV/PGA) from the cells of ``campaign fragility --pulses``:
    ``pga_m_s2`` (m/s^2) x ``pgv_pga_s`` (s) axes, ``n`` runs and ``overturned`` per cell
    (arrays n_pga x n_ratio), ``p_per_set`` (n_sets x n_pga x n_ratio, NaN where a set has
    no run) and ``outside``: the fitted logistic surface (or None).

    Inside the grid P is interpolated bilinearly in (ln PGA, ln PGV/PGA) between the
    cells' fractions (:mod:`pipeline.hazard.pulse_cells`, the one interpolation of a
    pulse grid): no functional form is imposed, and the cells are where the runs are.
    Above the grid's PGA and beside its PGV/PGA P follows the logistic surface fitted to
    the same runs from the nearest edge cell: its log-odds shifted to meet that cell's P
    (continuous at the edge; the surface's trend carries it outwards); without a surface,
    the nearest edge cell's P.  Below the grid's first PGA a_1, ``below`` (:data:`BELOW_GRID`):
    the edge P at a_1 times w(a), continuous at a_1, with ``uplift_m_s2`` = g tan(alpha)
    (a rigid body does not leave its rest below it, Housner 1963):

    - "ramp": w = ln(a / a_u) / ln(a_1 / a_u) between a_u and a_1, 0 below a_u (P rises
      linearly in ln PGA from 0 at the uplift acceleration to the edge P);
    - "zero": w = 0 (nothing below the grid: a lower bound on the rate);
    - "edge": w = 1 above a_u, 0 below (the edge P held: an upper bound, P growing with
      PGA);
    - "logistic": the surface, as above and beside the grid (not continuous at a_1).

    Without an uplift acceleration "ramp" and "edge" take a_u = 0 ("ramp" then is
    "zero", and "edge" holds the edge P down to any PGA), said in ``describe``."""
    pga_m_s2: tuple
    pgv_pga_s: tuple
    n: np.ndarray = field(compare=False)
    overturned: np.ndarray = field(compare=False)
    p_per_set: np.ndarray = field(compare=False)
    outside: Logistic | None = None
    label: str = "pulse grid"
    note: str | None = None
    uplift_m_s2: float | None = None
    below: str = "ramp"
    uses_ratio = True

    @cached_property
    def p(self):
        """The cells' P (n_pga x n_ratio, NaN without runs; read only, computed once)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            p = np.where(self.n > 0, self.overturned / np.maximum(self.n, 1), np.nan)
        p.flags.writeable = False
        return p

    def probability(self, pga_m_s2, pgv_pga_s):
        return self._interpolate(self.p, pga_m_s2, pgv_pga_s)

    def probability_stack(self, grids, pga_m_s2, pgv_pga_s=None):
        """P of each of the grids ``grids`` (the same cells' layout, runs, surface and
        below-grid rule as this one, their counts their own: its :meth:`draws` or
        :meth:`members`) at the points, D x the points' shape: one interpolation for all
        D (the same numbers as each grid's :meth:`probability`, to round-off)."""
        cells = np.stack([g.p for g in grids], axis=-1)          # n_pga x n_ratio x D
        return self._interpolate(cells, pga_m_s2, pgv_pga_s)

    def stacks_with(self, other):
        """True when ``other`` differs from this grid in its counts only (its P per cell),
        so that :meth:`probability_stack` takes both."""
        return isinstance(other, PulseGrid) and other == self and \
            np.array_equal(other.n, self.n)

    def _interpolate(self, cells, pga_m_s2, pgv_pga_s):
        """P at the points from ``cells`` (n_pga x n_ratio, or n_pga x n_ratio x D: then
        D x the points' shape).  Below the grid (but for ``below`` "logistic") P is the
        edge's, read at the first PGA, times w(a)."""
        pga, ratio = np.broadcast_arrays(np.asarray(pga_m_s2, float),
                                         np.asarray(pgv_pga_s, float))
        low = pga < self.pga_m_s2[0]
        if self.below == "logistic" or not low.any():
            return self._surface(cells, pga, ratio)
        weight = np.ones(pga.shape)
        weight[low] = self.below_weight(pga[low])
        p = self._surface(cells, np.where(low, self.pga_m_s2[0], pga), ratio)
        p *= weight                      # 1 at and above the grid's first PGA: exact
        return p

    def below_weight(self, pga_m_s2):
        """w(a) of the class docstring below the grid's first PGA (1 at a_1)."""
        pga = np.asarray(pga_m_s2, float)
        a_1, a_u = self.pga_m_s2[0], self.uplift_m_s2
        if self.below == "zero" or (self.below == "ramp" and (a_u is None or a_u >= a_1)):
            return np.zeros(pga.shape)
        if self.below == "edge":
            return (pga > (a_u or 0.0)).astype(float)
        return np.clip(np.log(pga / a_u) / math.log(a_1 / a_u), 0.0, 1.0)

    def variants(self):
        """The grid with P = 0 below it ("zero", a lower bound on the rate) and with the
        edge P held down to the uplift acceleration ("edge", an upper bound)."""
        return {name: replace(self, below=name) for name in ("zero", "edge")}

    def grid_range(self):
        """(first, last) PGA of the grid, m/s^2."""
        return self.pga_m_s2[0], self.pga_m_s2[-1]

    def _surface(self, cells, pga, ratio):
        """Inside the grid the cells' one interpolation (:mod:`pipeline.hazard.pulse_cells`:
        bilinear in ln PGA, ln PGV/PGA); outside, the logistic surface's trend carried from
        the nearest edge cell (its log-odds shifted to meet that cell's P, so P is
        continuous at the edge and a cell of P 0 or 1 stays so; the raw surface, with its
        steps, for ``below`` "logistic"), or without a surface the edge cell's P."""
        pga, ratio = np.broadcast_arrays(np.asarray(pga, float), np.asarray(ratio, float))
        held, beyond = interpolate(self.pga_m_s2, self.pgv_pga_s, _filled(cells),
                                   pga, ratio)               # the edge cell's P outside
        if self.outside is None or not beyond.any():       # the surface only where needed
            return held
        a, r = pga[beyond], ratio[beyond]
        if self.below == "logistic":
            held[..., beyond] = self.outside.probability(a, r)
            return held
        odds = np.ones(pga.shape)        # of the surface over its odds at the edge
        odds[beyond] = _odds_ratio(
            self.outside.probability(a, r),
            self.outside.probability(np.clip(a, self.pga_m_s2[0], self.pga_m_s2[-1]),
                                     np.clip(r, self.pgv_pga_s[0], self.pgv_pga_s[-1])))
        return _carried(held, odds)

    def draws(self, n, rng):
        """``n`` grids with every cell's count redrawn Binomial(n_cell, P_cell): the Monte
        Carlo error of the cells (parametric bootstrap); the outside surface kept."""
        return [replace(self, overturned=rng.binomial(self.n, np.nan_to_num(self.p)))
                for _ in range(n)]

    def members(self):
        """One grid per parameter set (its own P in every cell; a cell the set did not run
        takes the pooled P): the spread of the unknown contact parameters."""
        out = []
        for p_set in self.p_per_set:
            p = np.where(np.isnan(p_set), self.p, p_set)
            out.append(replace(self, n=np.ones_like(self.n), overturned=p))
        return out

    def describe(self):
        return {"form": "P(overturn | PGA, PGV/PGA) from the pulse grid's cells",
                "label": self.label,
                "inside": "bilinear in (ln PGA, ln PGV/PGA) between the cells' fractions",
                "outside": "the logistic surface fitted to the same runs"
                if self.outside is not None else "the nearest edge cell's P",
                "below_grid": self.describe_below(),
                "above_grid": self.describe_above(),
                "pga_range_g": [self.pga_m_s2[0] / STANDARD_GRAVITY,
                                self.pga_m_s2[-1] / STANDARD_GRAVITY],
                "pgv_pga_range_s": [self.pgv_pga_s[0], self.pgv_pga_s[-1]],
                "cells": int(self.n.size), "runs": int(self.n.sum()),
                "parameter_sets": int(len(self.p_per_set)),
                "outside_surface": None if self.outside is None else self.outside.describe(),
                "note": self.note}

    def describe_above(self):
        """What P is above the grid's last PGA: how it is extended, the top row's P per
        PGV/PGA and (``summary``) one line of it for the warnings."""
        top = fill_empty(self.p)[0][-1]
        a_n = self.pga_m_s2[-1] / STANDARD_GRAVITY
        span = f"{top.min():.3g}" if top.min() == top.max() else \
            f"{top.min():.3g}-{top.max():.3g} over its PGV/PGA"
        if self.outside is None:
            definition = "P = the top edge cell's P (at the nearest PGV/PGA), held at every PGA"
            summary = f"P held at the top cells' P ({span}) at every PGA above"
        elif self.below == "logistic":
            definition = ("P = the logistic surface fitted to the same runs (not continuous "
                          "at the grid's last PGA)")
            summary = "P from the logistic surface fitted to the runs"
        else:
            definition = ("logit P(a, r) = logit P(a_N, r) + logit S(a, r) - logit S(a_N, r): "
                          "the logistic surface S fitted to the same runs carries the top "
                          "edge cell's P upwards (a top cell of P 0 or 1 keeps it at every "
                          "PGA above)")
            summary = f"P carried up from the top cells' P ({span}) by the logistic surface"
        stuck = [r for r, p in zip(self.pgv_pga_s, top) if p == 0]
        note = None
        if stuck and self.below != "logistic":
            note = (f"no run overturned at the grid's last PGA ({a_n:.3g} g) for PGV/PGA "
                    f"{', '.join(f'{r:g}' for r in stuck)} s: P stays 0 at every PGA above it")
            summary += f"; P = 0 at every PGA above for PGV/PGA {', '.join(f'{r:g}' for r in stuck)} s"
        return {"definition": definition, "last_pga_g": a_n,
                "p_at_last_pga": {"pgv_pga_s": list(self.pgv_pga_s),
                                  "P": [float(v) for v in top]},
                "summary": summary, "note": note}

    def describe_below(self):
        """What P is below the grid's first PGA: the choice and its definition."""
        a_u = self.uplift_m_s2
        applied = self.below
        if self.below == "ramp" and (a_u is None or a_u >= self.pga_m_s2[0]):
            applied = "zero"
        definitions = {
            "ramp": "P = P(a_1) ln(a / a_u) / ln(a_1 / a_u) between the uplift acceleration "
                    "a_u = g tan(alpha) and the grid's first PGA a_1, 0 below a_u (a rigid "
                    "body does not leave its rest below a_u)",
            "zero": "P = 0 below the grid's first PGA (a lower bound on the rate)",
            "edge": "P = P(a_1), the edge's P, held down to the uplift acceleration, 0 below "
                    "(an upper bound on the rate, P growing with PGA)",
            "logistic": "the logistic surface fitted to the same runs (not continuous at "
                        "a_1)"}
        note = None
        if applied != self.below:
            note = ("no uplift acceleration in the file: P = 0 below the grid" if a_u is None
                    else "the uplift acceleration is not below the grid's first PGA: P = 0 "
                         "below the grid")
        elif self.below == "edge" and a_u is None:
            note = "no uplift acceleration in the file: the edge's P held down to any PGA"
        return {"choice": self.below, "applied": applied, "definition": definitions[applied],
                "first_pga_g": self.pga_m_s2[0] / STANDARD_GRAVITY,
                "uplift_pga_g": None if a_u is None else a_u / STANDARD_GRAVITY,
                "uplift_source": None if a_u is None else
                "the 2D block in the file: a_u = g tan(alpha), alpha the smallest critical "
                "angle of its runs (block2d uplift_g_smallest) or, in a file without it, "
                "their median",
                "note": note}


def _filled(cells):
    """:func:`~pipeline.hazard.pulse_cells.fill_empty` of cells (n_pga x n_ratio), or of
    each of a stack (n_pga x n_ratio x D)."""
    if cells.ndim == 2:
        return fill_empty(cells)[0]
    if not np.isnan(cells).any():
        return cells
    return np.stack([fill_empty(cells[..., d])[0] for d in range(cells.shape[2])], axis=-1)


def _odds_ratio(surface, surface_at_edge):
    """exp(logit surface - logit surface_at_edge), each clipped to [1e-12, 1 - 1e-12]."""
    tiny = 1e-12
    s, s_edge = np.clip(surface, tiny, 1 - tiny), np.clip(surface_at_edge, tiny, 1 - tiny)
    return (s / (1.0 - s)) / (s_edge / (1.0 - s_edge))


def _carried(p_edge, odds):
    """P outside a grid: logit P = logit p_edge + ln ``odds`` (:func:`_odds_ratio`, one
    value per point), as P = p odds / (1 - p + p odds): no logarithm per grid of a stack
    ``p_edge`` (in [0, 1], changed in place); P 0 and 1 stay so, and where odds is 1
    (inside the grid) P = p exactly ((1 - p) + p rounds to 1 for any p in [0, 1])."""
    spread = 1.0 - p_edge
    p_edge *= odds
    spread += p_edge
    p_edge /= spread
    return p_edge
