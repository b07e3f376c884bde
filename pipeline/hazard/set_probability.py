"""P(overturn) at PGA levels averaged over PGV/PGA, for one specimen, a set, or many sets
at once: survival's :func:`overturn_probability` (each specimen, or a set) is
:func:`set_probabilities` (``constrain``'s fragility draws and members) of one set.

The expectation over PGV/PGA is a weighted sum over points (:func:`ratio_quadrature`:
Gauss-Hermite nodes of a lognormal, and for a mixture over disaggregation bins every bin's
nodes times its share, so every bin's grid is evaluated in the same call), and a specimen
whose D fragilities are pulse grids differing only in their counts (draws, members; as
they are or on the hazard's PGA measure) is evaluated by one interpolation of the D grids
(:meth:`~pipeline.hazard.fragility.grid.PulseGrid.probability_stack`).
Units: PGA in m/s^2, PGV/PGA in s."""
from functools import reduce

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.disagg_ratio import RatioMixture, bin_shares
from pipeline.hazard.fragility.ratio import ratio_nodes

MAX_VALUES = 4_000_000        # sets x PGA levels x PGV/PGA points held at once (32 MB)


def ratio_quadrature(ratio_model, pga_m_s2):
    """(PGV/PGA points (L x K, s), their weights (L x K, summing to 1 over K)) at PGA
    levels (m/s^2, L): E[f(PGV/PGA)] = sum_k w[l, k] f(points[l, k]).  A lognormal model
    (``ln_mean_sd``) its Gauss-Hermite nodes; a :class:`RatioMixture` the nodes of each of
    its bins with events, weighted by the bin's share at the level."""
    pga = np.asarray(pga_m_s2, float)
    nodes, weights = ratio_nodes()
    if not isinstance(ratio_model, RatioMixture):
        mean, sd = ratio_model.ln_mean_sd(pga)
        return (np.exp(mean[:, None] + sd[:, None] * nodes[None, :]),
                np.broadcast_to(weights, (pga.size, nodes.size)))
    shares = bin_shares(ratio_model.anchors, ratio_model.shares, pga)
    points, w = [], []
    for b, model in enumerate(ratio_model.models):
        if model is not None and shares[:, b].max() > 0:
            mean, sd = model.ln_mean_sd(pga)
            points.append(np.exp(mean[:, None] + sd[:, None] * nodes[None, :]))
            w.append(shares[:, b][:, None] * weights[None, :])
    return np.concatenate(points, axis=1), np.concatenate(w, axis=1)


def overturn_probability(fragilities, ratio_model, pga_m_s2, combine="each"):
    """P(overturn) at PGA levels (m/s^2) averaged over PGV/PGA from ``ratio_model`` (None
    when no fragility depends on it).  ``combine``: "each" (array n_specimens x n_levels),
    "any_common" (P that any overturns in one event, the specimens independent given the
    motion they share: 1 - E[prod(1 - P_i)]) or "any_correlated" (the specimens'
    capacities fully correlated: E[max P_i]), arrays n_levels."""
    if combine == "each":
        return set_probabilities([[f] for f in fragilities], ratio_model, pga_m_s2, combine)
    return set_probabilities([fragilities], ratio_model, pga_m_s2, combine)[0]


def set_probabilities(batch, ratio_model, pga_m_s2, combine="any_common"):
    """D x L: for each of the D sets in ``batch`` (lists of fragilities, one per specimen,
    the same specimens in each) at PGA levels (m/s^2, L), averaged over PGV/PGA from
    ``ratio_model``: P(any of the set overturns), ``combine`` as in
    :func:`overturn_probability` ("each": sets of one specimen, its P)."""
    pga = np.asarray(pga_m_s2, float)
    if combine not in _COMBINED or (combine == "each" and any(len(c) != 1 for c in batch)):
        raise ValueError(f"combine {combine!r} for sets of {len(batch[0])} specimens")
    if any(f.uses_ratio for chosen in batch for f in chosen):
        if ratio_model is None:
            raise InputError("the fragility depends on PGV/PGA: give its distribution "
                             "(--pgv-pga-median and --pgv-pga-sigma, or --magnitude and "
                             "--distance-km)")
        ratio, weights = ratio_quadrature(ratio_model, pga)
    else:
        ratio, weights = None, np.ones((pga.size, 1))
    count = len(batch)
    chunk = max(1, MAX_VALUES // weights.size)
    out = np.empty((count, pga.size))
    for start in range(0, count, chunk):
        part = batch[start:start + chunk]
        columns = [_column([chosen[j] for chosen in part], pga, ratio)
                   for j in range(len(part[0]))]
        out[start:start + len(part)] = _COMBINED[combine](columns, weights)
    return out


_COMBINED = {   # the specimens' P at the points ((1 or D) x L x K each) to D x L
    "each": lambda columns, w: (columns[0] * w).sum(axis=-1),
    "any_common": lambda columns, w: 1.0 - (reduce(lambda s, p: s * (1.0 - p), columns,
                                                   1.0) * w).sum(axis=-1),
    "any_correlated": lambda columns, w: (reduce(np.maximum, columns) * w).sum(axis=-1)}


def _column(fragilities, pga, ratio):
    """P of one specimen's fragilities (one per set) at the points: (1 or D) x L x K."""
    first = fragilities[0]
    a = pga[:, None]
    if all(f is first for f in fragilities):
        return (first.probability(a, ratio) if ratio is not None
                else first.probability(a))[None]
    if all(first.stacks_with(f) for f in fragilities):
        return first.probability_stack(fragilities, a, ratio)
    return np.array([f.probability(a, ratio) if ratio is not None else f.probability(a)
                     for f in fragilities])
