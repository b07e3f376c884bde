"""Constraining a logic tree by what still stands: plain functions on arrays.

Units: PGA in m/s^2, rates in 1/yr, ages in years.  ``rates`` is B x L (one hazard curve
per branch on common levels), ``weights`` B (sum 1).

The survival of a specimen set under branch i is P_s,i = exp(-sum_k dt_k lambda_i(S_k)):
the ages sorted t_(1) <= ... <= t_(n), S_k the specimens at least t_(k) old (standing
through the interval dt_k = t_(k) - t_(k-1), t_(0) = 0) and lambda_i(S) the annual rate of
events in which any of S overturns under branch i's curve (the specimens independent given
the shaking they share, :func:`pipeline.hazard.set_probability.overturn_probability` "any_common").
Exact for earthquakes as a Poisson process: the intervals do not overlap, so their
survivals multiply.  lambda_i is the cell integration of :mod:`pipeline.hazard.survival`
(the same cells, the exceedances of the last level counted at it), done for all branches
at once: the cells' PGA does not depend on the branch, their rates do (:func:`cell_matrix`);
a fragility's draws too, their probabilities at the cells times the cells' rates being one
matrix product (:func:`branch_rates`).

Rules: Bayes (w_i' proportional to w_i P_s,i: the survival is the likelihood of each
branch; every branch keeps a weight in proportion to how well it explains the standing
specimens, and no threshold is chosen) and elimination (branches with P_s,i < floor
dropped, the rest renormalised).  Statistics over branches: the weighted mean of the
annual rates and OpenQuake's weighted quantile (``openquake.hazardlib.stats.
quantile_curve``: at each level the values sorted, their cumulative weights C_k, the
quantile q interpolated linearly in (C_k, value), the smallest value below C_1).
"""
import numpy as np
from scipy.special import logsumexp

from pipeline.hazard.survival import CELLS_PER_INTERVAL, hazard_cells

FLOOR = 0.05                               # elimination: survival below this drops a branch
FRACTILES = (0.05, 0.16, 0.5, 0.84, 0.95)
TARGET_RATES = (1e-3, 4e-4, 1e-4)          # annual rates of the ground motion reported (1/yr)
MAX_CELL_VALUES = 20_000_000               # branches x cells held at once (160 MB)
MIN_CELLS = 20


def cell_matrix(levels_m_s2, rates_per_yr, cells=CELLS_PER_INTERVAL):
    """(x_mid (C,), d_rate (B x C), cells per interval): the cells of
    :func:`pipeline.hazard.survival.hazard_cells` for every branch; fewer cells per interval
    when B x C would pass MAX_CELL_VALUES (at least MIN_CELLS)."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.atleast_2d(np.asarray(rates_per_yr, float))
    intervals = len(levels) - 1
    cells = int(min(cells, max(MIN_CELLS, MAX_CELL_VALUES // (rates.shape[0] * intervals))))
    x_mid = hazard_cells(levels, rates[0], cells)[0]
    d_rate = np.stack([hazard_cells(levels, r, cells)[1] for r in rates])
    return x_mid, d_rate, cells


def branch_rates(cells, levels_m_s2, rates_per_yr, probability):
    """Annual rate (1/yr) of the events in which ``probability`` (a function of PGA, m/s^2)
    happens, under each branch: sum over cells of P(x_mid) d_rate plus P(x_N) at the last
    level x_N times its rate (:func:`pipeline.hazard.survival.overturning_rate`).
    ``probability`` gives one value per PGA (result B) or a row per fragility draw (D x
    len(x): result D x B, one matrix product for all draws; S x D x len(x) for S sets of
    specimens: S x D x B)."""
    x_mid, d_rate, _ = cells
    rates = np.atleast_2d(np.asarray(rates_per_yr, float))
    p_mid = np.asarray(probability(x_mid), float)
    top = np.asarray(probability(np.asarray(levels_m_s2, float)[-1:]), float)[..., 0]
    if p_mid.ndim == 1:
        return d_rate @ p_mid + top * rates[:, -1]
    return p_mid @ d_rate.T + top[..., None] * rates[:, -1]


def draw_chunk(cells):
    """How many fragility draws :func:`branch_rates` takes at once: their D x C cell
    probabilities held within MAX_CELL_VALUES (at least 1)."""
    return max(1, MAX_CELL_VALUES // cells[0].size)


def age_chain(ages_yr):
    """[(indices of the specimens standing through the interval, its duration yr)], from
    the present back: all specimens over the youngest age, then those older, ..."""
    ages = np.asarray(ages_yr, float)
    order = np.argsort(ages, kind="stable")
    chain, previous = [], 0.0
    for k, j in enumerate(order):
        if ages[j] > previous:
            chain.append((tuple(sorted(int(i) for i in order[k:])), float(ages[j] - previous)))
            previous = float(ages[j])
    return chain


def log_survival_fixed(rates_of, ages_yr):
    """ln P_s per branch for known ages: -sum_k dt_k lambda(S_k); ``rates_of(sets)`` gives
    lambda (1/yr, B, or D x B for D fragility draws) of each of a list of sets (tuples of
    specimen indices), all at once."""
    chain = age_chain(ages_yr)
    rates = rates_of([members for members, _ in chain])
    return -sum(dt * rate for (_, dt), rate in zip(chain, rates))


def log_survival_sampled(rates_of, age_samples):
    """(ln P_s per branch, its standard error relative to P_s per branch): the mean of
    exp(-sum dt lambda) over sampled ages (Monte Carlo over uncertain, differing ages).
    Each set's lambda is computed once, all sets at once (``rates_of`` as for
    :func:`log_survival_fixed`); a sample's sum is its durations (samples x sets) times
    the sets' rates, one matrix product for all samples."""
    chains = [age_chain(a) for a in age_samples]
    sets = list(dict.fromkeys(m for chain in chains for m, _ in chain))
    index = {m: k for k, m in enumerate(sets)}
    durations = np.zeros((len(chains), len(sets)))
    for s, chain in enumerate(chains):
        for members, dt in chain:
            durations[s, index[members]] += dt
    rates = np.stack([np.asarray(rate, float) for rate in rates_of(sets)])
    logs = -np.tensordot(durations, rates, axes=1)
    log_p = logsumexp(logs, axis=0) - np.log(len(logs))
    with np.errstate(invalid="ignore", over="ignore"):
        ratio = np.exp(logs - log_p)                     # samples of P / mean P
        se = ratio.std(axis=0, ddof=1) / np.sqrt(len(logs))
    return log_p, se


def bayes(weights, log_survival):
    """w_i P_s,i / sum: posterior weights (B), or None when every branch has P_s = 0."""
    w = np.asarray(weights, float)
    with np.errstate(divide="ignore"):
        log_w = np.log(w) + np.asarray(log_survival, float)
    if not np.isfinite(log_w).any():
        return None
    return np.exp(log_w - logsumexp(log_w[np.isfinite(log_w)]))


def eliminate(weights, survival, floor=FLOOR):
    """Weights with the branches of P_s < ``floor`` set to 0, renormalised; None when no
    branch of positive weight is left."""
    w = np.where(np.asarray(survival, float) >= floor, np.asarray(weights, float), 0.0)
    total = w.sum()
    return None if not total > 0 else w / total


def weighted_mean(values, weights):
    """The weighted mean over branches (axis 0) of ``values`` (B x L)."""
    return np.asarray(weights, float) @ np.asarray(values, float)


def weighted_quantile(values, weights, q):
    """OpenQuake's weighted quantile (see the module) of ``values`` (B x L) over branches,
    at each level (L); branches of weight 0 left out."""
    values = np.atleast_2d(np.asarray(values, float))
    w = np.asarray(weights, float)
    keep = w > 0
    v, w = values[keep], w[keep] / w[keep].sum()
    order = np.argsort(v, axis=0, kind="stable")
    sorted_v = np.take_along_axis(v, order, axis=0)
    cumulative = np.cumsum(w[order], axis=0)
    return np.array([np.interp(q, cumulative[:, k], sorted_v[:, k])
                     for k in range(v.shape[1])])


def motion_at_rate(levels_m_s2, rates_per_yr, rate):
    """The PGA (m/s^2) at which the curve's annual rate is ``rate``: interpolated linearly
    in (ln rate, ln PGA); None outside the curve's rates (no extrapolation)."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.asarray(rates_per_yr, float)
    if not rates[-1] <= rate <= rates[0]:
        return None
    return float(np.exp(np.interp(np.log(rate), np.log(rates[::-1]), np.log(levels[::-1]))))


def change_percent(before, after):
    """100 (after / before - 1), or None when either is None."""
    if before is None or after is None or before == 0:
        return None
    return 100.0 * (after / before - 1.0)
