"""P(overturn) at PGA levels averaged over PGV/PGA, for one specimen, a set, or many sets
at once: survival's :func:`overturn_probability` (each specimen, or a set) is
:func:`set_probabilities` (``constrain``'s fragility draws and members) of one set.

The expectation over PGV/PGA is a weighted sum over points (:func:`ratio_quadrature`:
Gauss-Hermite nodes of a lognormal; for a mixture over disaggregation bins every bin's
nodes, the bin's mean weighted by its share, every bin evaluated in the same call), and a
specimen whose D fragilities are pulse grids differing only in their counts (draws,
members; as they are or on the hazard's PGA measure) is evaluated by one interpolation of
the D grids (:meth:`~pipeline.hazard.fragility.grid.PulseGrid.probability_stack`).
Units: PGA in m/s^2, PGV/PGA in s."""
from functools import reduce

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.disagg_ratio import RatioMixture, bin_shares
from pipeline.hazard.fragility.ratio import ratio_nodes

MAX_VALUES = 4_000_000        # sets x PGA levels x PGV/PGA points held at once (32 MB)


def ratio_quadrature(ratio_model, pga_m_s2):
    """(PGV/PGA points (L x B x K, s), the B models' shares (L x B, summing to 1 over B))
    at PGA levels (m/s^2, L): E[f(PGV/PGA)] = sum_b share[l, b] sum_k w_k f(points[l, b,
    k]), w the K Gauss-Hermite weights of :func:`ratio_nodes`.  A lognormal model
    (``ln_mean_sd``) is one (B = 1); a :class:`RatioMixture` its bins with events, each
    weighted by its share at the level."""
    pga = np.asarray(pga_m_s2, float)
    models, shares = [ratio_model], np.ones((pga.size, 1))
    if isinstance(ratio_model, RatioMixture):
        shares = bin_shares(ratio_model.anchors, ratio_model.shares, pga)
        used = [b for b, m in enumerate(ratio_model.models)
                if m is not None and shares[:, b].max() > 0]
        models, shares = [ratio_model.models[b] for b in used], shares[:, used]
    nodes = ratio_nodes()[0]
    return np.stack([np.exp(mean[:, None] + sd[:, None] * nodes[None, :])
                     for mean, sd in (m.ln_mean_sd(pga) for m in models)], axis=1), shares


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
        (ratio, shares), weights = ratio_quadrature(ratio_model, pga), ratio_nodes()[1]
    else:
        ratio, shares, weights = None, np.ones((pga.size, 1)), np.ones(1)
    count = len(batch)
    chunk = max(1, MAX_VALUES // (shares.size * weights.size))
    out = np.empty((count, pga.size))
    for start in range(0, count, chunk):
        part = batch[start:start + chunk]
        columns = [_column([chosen[j] for chosen in part], pga, ratio)
                   for j in range(len(part[0]))]
        out[start:start + len(part)] = (shares * _COMBINED[combine](columns, weights)).sum(-1)
    return out


_COMBINED = {   # the specimens' P at the points ((1 or D) x L x B x K each) to (1 or D) x L x B
    "each": lambda columns, w: columns[0] @ w,
    "any_common": lambda columns, w: 1.0 - reduce(lambda s, p: s * (1.0 - p), columns,
                                                  1.0) @ w,
    "any_correlated": lambda columns, w: reduce(np.maximum, columns) @ w}


def _column(fragilities, pga, ratio):
    """P of one specimen's fragilities (one per set) at the points: (1 or D) x L x B x K."""
    first = fragilities[0]
    a = pga[:, None, None]
    if all(f is first for f in fragilities):
        return (first.probability(a, ratio) if ratio is not None
                else first.probability(a))[None]
    if all(first.stacks_with(f) for f in fragilities):
        return first.probability_stack(fragilities, a, ratio)
    return np.array([f.probability(a, ratio) if ratio is not None else f.probability(a)
                     for f in fragilities])
