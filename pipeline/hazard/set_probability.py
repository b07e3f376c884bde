"""P that any specimen of a set overturns in one event, for many fragility sets at once
(``constrain``'s fragility draws and members): :func:`set_probabilities`.

The same quantity as :func:`~pipeline.hazard.disagg_ratio.overturn_probability_over` with
"any_common" (1 - E[prod_j (1 - P_j)] over PGV/PGA), each set's specimens independent given
the shaking they share, computed for D sets in one pass: the expectation over PGV/PGA is a
weighted sum over points (:func:`ratio_quadrature`: Gauss-Hermite nodes of a lognormal,
and for a mixture over disaggregation bins every bin's nodes times its share, so every
bin's grid is evaluated in the same call), and a specimen whose D fragilities are pulse
grids differing only in their counts (draws, members; as they are or on the hazard's
PGA measure) is evaluated by one interpolation of the D grids
(:meth:`~pipeline.hazard.fragility.grid.PulseGrid.probability_stack`).  Several subsets
of the specimens (the sets of an age chain: all, then the older ones, ...) take each
specimen's P once (:func:`subset_probabilities`).
Units: PGA in m/s^2, PGV/PGA in s."""
import numpy as np

from pipeline.files import InputError
from pipeline.hazard.disagg_ratio import RatioMixture, bin_shares
from pipeline.hazard.fragility.ratio import ratio_nodes

MAX_VALUES = 4_000_000        # subsets x sets x PGA levels x PGV/PGA points at once (32 MB)


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


def set_probabilities(batch, ratio_model, pga_m_s2):
    """D x L: for each of the D sets in ``batch`` (lists of fragilities, one per specimen,
    the same specimens in each), P(any of the set overturns) at PGA levels (m/s^2, L),
    averaged over PGV/PGA from ``ratio_model`` (see the module)."""
    return subset_probabilities(batch, [tuple(range(len(batch[0])))], ratio_model,
                                pga_m_s2)[0]


def subset_probabilities(batch, subsets, ratio_model, pga_m_s2):
    """S x D x L: :func:`set_probabilities` of each of the S ``subsets`` (tuples of indices
    into each set of ``batch``) of the specimens, each specimen's P computed once for all
    the subsets holding it (the sets of an age chain, the ages sampled)."""
    pga = np.asarray(pga_m_s2, float)
    subsets = [tuple(sorted(members)) for members in subsets]
    used = sorted(set().union(*subsets))
    if any(chosen[j].uses_ratio for chosen in batch for j in used):
        if ratio_model is None:
            raise InputError("the fragility depends on PGV/PGA: give its distribution "
                             "(--pgv-pga-median and --pgv-pga-sigma, or --magnitude and "
                             "--distance-km)")
        ratio, weights = ratio_quadrature(ratio_model, pga)
    else:
        ratio, weights = None, np.ones((pga.size, 1))
    columns = {j: _column([chosen[j] for chosen in batch]) for j in used}
    count = len(batch)
    step = max(1, MAX_VALUES // ((len(subsets) + 1) * count * weights.shape[1]))
    out = np.empty((len(subsets), count, pga.size))
    for start in range(0, pga.size, step):          # PGA levels in chunks, all sets at once
        rows = slice(start, start + step)
        survive = np.empty((len(subsets), count, *weights[rows].shape))
        for j in used:
            _spare(survive, subsets, j, columns[j](pga[rows, None],
                                                   None if ratio is None else ratio[rows]))
        survive *= weights[rows]
        out[:, :, rows] = 1.0 - survive.sum(axis=-1)
    return out


def _spare(survive, subsets, j, column):
    """Multiply P(specimen ``j`` stands), 1 - ``column``, into the survival of each subset
    holding it (S x D x L x K, the subsets' specimens in index order: a subset's first one
    sets it)."""
    first = [s for s, members in enumerate(subsets) if members[0] == j]
    spared = survive[first[0]] if first else np.empty(np.broadcast_shapes(
        survive.shape[1:], column.shape))
    np.subtract(1.0, column, out=spared)
    for s in first[1:]:
        survive[s] = spared
    for s, members in enumerate(subsets):
        if j in members[1:]:
            survive[s] *= spared


def _column(fragilities):
    """P of one specimen's fragilities (one per set) as a function of the points (PGA, L x
    1; PGV/PGA, L x K or None): (1 or D) x L x K."""
    first = fragilities[0]
    if all(f is first for f in fragilities):
        return lambda a, ratio: (first.probability(a, ratio) if ratio is not None
                                 else first.probability(a))[None]
    if all(first.stacks_with(f) for f in fragilities):
        return lambda a, ratio: first.probability_stack(fragilities, a, ratio)
    return lambda a, ratio: np.array([f.probability(a, ratio) if ratio is not None
                                      else f.probability(a) for f in fragilities])
