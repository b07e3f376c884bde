"""Survival against the joint hazard of PGA and PGV: plain functions on arrays.

Units: PGA in m/s^2, PGV in m/s, PGV/PGA in s, rates in 1/yr.  ``probability(pga_m_s2,
pgv_pga_s)`` is P(overturn) in one event of that motion, an array of the broadcast shape
(:meth:`pipeline.hazard.fragility.kinds.Fragility.probability`).

The joint hazard gives the annual rate r_ij of events with PGA in cell i and PGV in cell
j (:class:`pipeline.hazard.joint_hazard.JointHazard`).  The rate of overturning is

    lambda_ov = sum_ij r_ij <P>_ij

with <P>_ij the fragility averaged over the cell (Gauss-Legendre, ``nodes`` x ``nodes``
points), the events spread inside it with a density log-linear in ln PGA and in ln PGV,
its slopes from the neighbouring cells' rates (an even spread would weigh a cell's upper
part as much as its lower, where a falling hazard puts more events: 5 % too much rate on
the shipped QA case; with the slopes the integration error falls faster than the cells'
width squared, :mod:`tests.hazard.test_joint_survival`).  Nothing outside the levels is
counted; the shares of lambda_ov in the top PGA row and the top PGV
column are reported (where the grid's end may cut the rate).  Survival over an age is
E[exp(-lambda_ov T)] over the age's distribution (:mod:`pipeline.hazard.ages`).

:func:`scenario_cell_rates` builds the joint hazard of one scenario in closed form: events
at an annual rate, ln PGA and ln PGV bivariate normal with a stated correlation; each
cell's probability from the bivariate normal CDF at its four corners (as OpenQuake's
``compute_mrd`` does for each rupture).
"""
from dataclasses import dataclass

import numpy as np
from scipy import stats

CELL_NODES = 4                 # Gauss-Legendre points per axis inside a cell


@dataclass(frozen=True)
class JointRate:
    """What :func:`joint_overturning_rate` finds: ``rate_per_yr`` (1/yr), the rate of
    events the grid holds (``events_per_yr``), the shares of ``rate_per_yr`` in the top
    PGA row (``share_top_pga``) and the top PGV column (``share_top_pgv``); shares None
    when the rate is 0."""
    rate_per_yr: float
    events_per_yr: float
    share_top_pga: float | None
    share_top_pgv: float | None


def log_slopes(cell_rates, axis):
    """d ln(rate density) / d(cell) along ``axis`` at each cell: the central difference of
    ln rate over its two neighbours, one-sided at an edge or beside an empty cell, 0 where
    neither neighbour holds a rate (or the cell holds none)."""
    r = np.moveaxis(np.asarray(cell_rates, float), axis, 0)
    with np.errstate(divide="ignore"):
        ln_r = np.where(r > 0, np.log(np.where(r > 0, r, 1.0)), np.nan)
    up = np.full(r.shape, np.nan)
    down = np.full(r.shape, np.nan)
    up[:-1] = ln_r[1:] - ln_r[:-1]
    down[1:] = ln_r[1:] - ln_r[:-1]
    both = np.isfinite(up) & np.isfinite(down)
    slope = np.where(both, 0.5 * (np.nan_to_num(up) + np.nan_to_num(down)),
                     np.where(np.isfinite(up), up, np.where(np.isfinite(down), down, 0.0)))
    return np.moveaxis(slope, 0, axis)


def cell_mean_probability(pga_levels_m_s2, pgv_levels_m_s, probability, cell_rates=None,
                          nodes=CELL_NODES):
    """P(overturn) averaged over each cell (PGA cells x PGV cells), the events spread in
    (ln PGA, ln PGV) inside the cell with a density log-linear along each axis, its
    slopes from the neighbouring cells' rates (:func:`log_slopes`; even without
    ``cell_rates``); Gauss-Legendre, ``nodes`` per axis."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    t, w = 0.5 * (x + 1.0), 0.5 * w                  # nodes and weights on [0, 1]
    ln_a, ln_v = np.log(pga_levels_m_s2), np.log(pgv_levels_m_s)
    a = np.exp(ln_a[:-1, None] + np.diff(ln_a)[:, None] * t)          # PGA cells x nodes
    v = np.exp(ln_v[:-1, None] + np.diff(ln_v)[:, None] * t)          # PGV cells x nodes
    pga = a[:, None, :, None]
    ratio = v[None, :, None, :] / pga
    p = probability(pga, ratio)
    p = np.broadcast_to(p, (a.shape[0], v.shape[0], nodes, nodes))
    shape = p.shape[:2]
    s_a = np.zeros(shape) if cell_rates is None else log_slopes(cell_rates, 0)
    s_v = np.zeros(shape) if cell_rates is None else log_slopes(cell_rates, 1)
    weight = (w * np.exp(s_a[..., None] * (t - 0.5)))[..., :, None] * \
        (w * np.exp(s_v[..., None] * (t - 0.5)))[..., None, :]
    return np.einsum("ijkl,ijkl->ij", p, weight) / weight.sum(axis=(2, 3))


def joint_overturning_rate(pga_levels_m_s2, pgv_levels_m_s, cell_rates_per_yr, probability,
                           nodes=CELL_NODES):
    """The annual rate of overturning (1/yr) of one site's joint hazard
    (``cell_rates_per_yr``: PGA cells x PGV cells, 1/yr) as a :class:`JointRate`."""
    rates = np.asarray(cell_rates_per_yr, float)
    part = rates * cell_mean_probability(np.asarray(pga_levels_m_s2, float),
                                         np.asarray(pgv_levels_m_s, float), probability,
                                         rates, nodes)
    total = float(part.sum())
    return JointRate(total, float(rates.sum()),
                     float(part[-1, :].sum()) / total if total > 0 else None,
                     float(part[:, -1].sum()) / total if total > 0 else None)


def scenario_cell_rates(pga_levels_m_s2, pgv_levels_m_s, rate_per_yr, ln_pga_mean,
                        ln_pga_sd, ln_pgv_mean, ln_pgv_sd, correlation):
    """One scenario's joint hazard (PGA cells x PGV cells, 1/yr): events at
    ``rate_per_yr``, (ln PGA, ln PGV) bivariate normal (means of ln(m/s^2) and ln(m/s),
    sds) with ``correlation``; each cell's probability from the CDF at its corners."""
    cov = [[ln_pga_sd ** 2, correlation * ln_pga_sd * ln_pgv_sd],
           [correlation * ln_pga_sd * ln_pgv_sd, ln_pgv_sd ** 2]]
    law = stats.multivariate_normal([ln_pga_mean, ln_pgv_mean], cov)
    ln_a, ln_v = np.log(pga_levels_m_s2), np.log(pgv_levels_m_s)
    corners = np.stack(np.meshgrid(ln_a, ln_v, indexing="ij"), axis=-1)
    cdf = law.cdf(corners)                      # PGA levels x PGV levels
    cells = cdf[1:, 1:] - cdf[:-1, 1:] - cdf[1:, :-1] + cdf[:-1, :-1]
    return rate_per_yr * np.clip(cells, 0.0, None)
