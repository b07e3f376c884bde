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
(:meth:`~pipeline.hazard.fragility.grid.PulseGrid.probability_stack`).
Units: PGA in m/s^2, PGV/PGA in s."""
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


def set_probabilities(batch, ratio_model, pga_m_s2):
    """D x L: for each of the D sets in ``batch`` (lists of fragilities, one per specimen,
    the same specimens in each), P(any of the set overturns) at PGA levels (m/s^2, L),
    averaged over PGV/PGA from ``ratio_model`` (see the module)."""
    pga = np.asarray(pga_m_s2, float)
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
        survive = np.ones((len(part), *weights.shape))
        for j in range(len(part[0])):
            survive = survive * (1.0 - _column([chosen[j] for chosen in part], pga, ratio))
        out[start:start + len(part)] = 1.0 - (survive * weights).sum(axis=-1)
    return out


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
