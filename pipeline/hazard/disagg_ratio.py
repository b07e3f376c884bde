"""PGV/PGA at each PGA level from a magnitude-distance disaggregation: the indirect route
to the joint hazard of PGA and PGV (Kohrangi, Bazzurro & Vamvatsikos): the scalar PGA
curve, and at each PGA level a mixture over the disaggregation's bins of PGV given PGA
from the ground-motion model at each bin's magnitude and distance
(:class:`~pipeline.hazard.fragility.ratio.RatioFromGmm`).  One bin is today's one
scenario.

The bins' shares at a PGA level a (:func:`bin_shares`) are those of the events with PGA
near a: between two disaggregated levels l_k <= a < l_k+1, each bin's rate of exceeding
l_k less its rate of exceeding l_k+1 (the events whose PGA falls between them: their
mean over the interval), normalised; from the top level up, the bins' rates of exceeding
it; below the first level, the shares between the first two (with one level only, the
shares of exceeding it everywhere).
:func:`pipeline.hazard.set_probability.overturn_probability` averages P(overturn | PGA,
PGV/PGA) over the mixture.  Units: PGA in m/s^2, distances in km, magnitudes Mw.
"""
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.fragility.ratio import DEFAULT_VS30_M_S, RatioFromGmm
from pipeline.hazard.pga_pgv_correlation import BAKER_BRADLEY_2017
from pipeline.hazard.ratio_described import MixtureRatio


def level_shares(disaggregation, column):
    """(anchors (m/s^2, the disaggregated levels, increasing), shares (anchors x bins)):
    the bins' shares of the events from each anchor to the next (see the module), bins
    flattened magnitude-major."""
    if column not in disaggregation.columns:
        raise InputError(f"{disaggregation.source.get('file')}: no column {column!r} (has "
                         f"{', '.join(disaggregation.columns)})")
    rates = disaggregation.bin_rates_per_yr[disaggregation.columns.index(column)]
    rates = rates.reshape(rates.shape[0], -1)             # levels x bins
    levels = disaggregation.levels_m_s2
    if levels.size == 1:
        return levels, _normalised(rates, levels)
    between = np.clip(rates[:-1] - rates[1:], 0.0, None)
    return levels, _normalised(np.vstack([between, rates[-1:]]), levels)


def _normalised(rates, anchors):
    total = rates.sum(axis=1, keepdims=True)
    if np.any(total <= 0):
        k = int(np.flatnonzero(total[:, 0] <= 0)[0])
        raise InputError(f"no events in any bin near PGA {anchors[k]:.4g} m/s^2")
    return rates / total


def bin_shares(anchors, shares, pga_m_s2):
    """The bins' shares (PGA levels x bins) at PGA levels (m/s^2): those of the anchor
    at or below (the first anchor's below it)."""
    k = np.searchsorted(anchors, np.asarray(pga_m_s2, float), side="right") - 1
    return shares[np.clip(k, 0, len(anchors) - 1)]


@dataclass(frozen=True)
class RatioMixture:
    """PGV/PGA at each PGA level as a mixture over disaggregation bins: ``anchors``
    (m/s^2) and ``shares`` (anchors x bins) from :func:`level_shares`; ``models`` one
    :class:`RatioFromGmm` per bin (None for a bin without events)."""
    anchors: np.ndarray
    shares: np.ndarray
    models: tuple

    def describe(self) -> MixtureRatio:
        """The mixture as results describe it: its bins with events and their model (the
        same at every bin but the magnitude and distance)."""
        used = [m for m in self.models if m is not None]
        model = used[0].describe()
        return MixtureRatio(
            bins_used=len(used), bins=[[m.magnitude, m.distance_km] for m in used],
            anchors_m_s2=self.anchors.tolist(),
            shares="between disaggregated levels: the events falling between them",
            model=model.model, vs30_m_s=model.vs30_m_s, mechanism=model.mechanism,
            pga_pgv_correlation=model.pga_pgv_correlation,
            pga_pgv_correlation_source=model.pga_pgv_correlation_source)


def ratio_mixture(disaggregation, column="mean", vs30_m_s=DEFAULT_VS30_M_S, mechanism="SS",
                  correlation=BAKER_BRADLEY_2017.value):
    """The :class:`RatioMixture` of ``disaggregation``'s ``column``: each bin with events
    gets the ground-motion model at its centre (the bin's rupture distance taken as the
    model's Joyner-Boore distance)."""
    anchors, shares = level_shares(disaggregation, column)
    mags = 0.5 * (disaggregation.mag_edges[:-1] + disaggregation.mag_edges[1:])
    dists = 0.5 * (disaggregation.dist_edges_km[:-1] + disaggregation.dist_edges_km[1:])
    models = []
    for b, (m, r) in enumerate((m, r) for m in mags for r in dists):
        models.append(RatioFromGmm(float(m), float(r), vs30_m_s, mechanism, correlation)
                      if shares[:, b].max() > 0 else None)
    return RatioMixture(anchors, shares, tuple(models))

