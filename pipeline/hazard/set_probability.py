"""P(overturn) at PGA levels averaged over PGV/PGA, for one specimen, a set, or many sets
at once: survival's :func:`overturn_probability` (each specimen, or a set) is
:func:`set_probabilities` (``constrain``'s fragility draws and members) of one set.

The expectation over PGV/PGA is a weighted sum over points (:func:`ratio_quadrature`:
Gauss-Hermite nodes of a lognormal; for a mixture over disaggregation bins every bin's
nodes, the bin's mean weighted by its share, every bin evaluated in the same call), and a
specimen whose D fragilities are pulse grids differing only in their counts (draws,
members; as they are or on the hazard's PGA measure) is evaluated by one interpolation of
the D grids (:meth:`~pipeline.hazard.fragility.grid.PulseGrid.probability_stack`).
Several subsets of the specimens (the sets of an age chain: all, then the older ones, ...)
take each specimen's P once (:func:`subset_probabilities`).
Units: PGA in m/s^2, PGV/PGA in s."""
from functools import reduce

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.disagg_ratio import RatioMixture, bin_shares
from pipeline.hazard.fragility.ratio import ratio_nodes

MAX_VALUES = 4_000_000        # subsets x sets x PGA levels x PGV/PGA points at once (32 MB)


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
    if combine == "each" and any(len(chosen) != 1 for chosen in batch):
        raise ValueError(f"combine 'each' for sets of {len(batch[0])} specimens")
    return subset_probabilities(batch, [tuple(range(len(batch[0])))], ratio_model,
                                pga_m_s2, combine)[0]


def subset_probabilities(batch, subsets, ratio_model, pga_m_s2, combine="any_common"):
    """S x D x L: :func:`set_probabilities` of each of the S ``subsets`` (tuples of indices
    into each set of ``batch``) of the specimens, each specimen's P computed once for all
    the subsets holding it (the sets of an age chain, the ages sampled)."""
    pga = np.asarray(pga_m_s2, float)
    if combine not in _COMBINED:
        raise ValueError(f"combine {combine!r}")
    subsets = [tuple(sorted(members)) for members in subsets]
    used = sorted(set().union(*subsets))
    if any(chosen[j].uses_ratio for chosen in batch for j in used):
        if ratio_model is None:
            raise InputError("the fragility depends on PGV/PGA: give its distribution "
                             "(--pgv-pga-median and --pgv-pga-sigma, or --magnitude and "
                             "--distance-km)")
        (ratio, shares), weights = ratio_quadrature(ratio_model, pga), ratio_nodes()[1]
    else:
        ratio, shares, weights = None, np.ones((pga.size, 1)), np.ones(1)
    columns = {j: _column([chosen[j] for chosen in batch]) for j in used}
    count = len(batch)
    step = max(1, MAX_VALUES // ((len(used) + 1) * count * shares.shape[1] * weights.size))
    out = np.empty((len(subsets), count, pga.size))
    for start in range(0, pga.size, step):          # PGA levels in chunks, all sets at once
        rows = slice(start, start + step)
        points = None if ratio is None else ratio[rows]
        p = {j: columns[j](pga[rows, None, None], points) for j in used}
        for s, members in enumerate(subsets):
            combined = _COMBINED[combine]([p[j] for j in members], weights)
            out[s, :, rows] = (shares[rows] * combined).sum(axis=-1)
    return out


_COMBINED = {   # the specimens' P at the points ((1 or D) x L x B x K each) to (1 or D) x L x B
    "each": lambda columns, w: columns[0] @ w,
    "any_common": lambda columns, w: 1.0 - reduce(lambda s, p: s * (1.0 - p), columns,
                                                  1.0) @ w,
    "any_correlated": lambda columns, w: reduce(np.maximum, columns) @ w}


def _column(fragilities):
    """P of one specimen's fragilities (one per set) as a function of the points (PGA, L x
    1 x 1; PGV/PGA, L x B x K or None): (1 or D) x L x B x K."""
    first = fragilities[0]
    if all(f is first for f in fragilities):
        return lambda a, ratio: (first.probability(a, ratio) if ratio is not None
                                 else first.probability(a))[None]
    if all(first.stacks_with(f) for f in fragilities):
        return lambda a, ratio: first.probability_stack(fragilities, a, ratio)
    return lambda a, ratio: np.array([f.probability(a, ratio) if ratio is not None
                                      else f.probability(a) for f in fragilities])
