"""PGV/PGA given PGA from a site's mean rate density of PGA and PGV (OpenQuake's ``mrd``,
:class:`~pipeline.hazard.joint_hazard.JointHazard`), for ``constrain``: at each PGA cell
the events' ln(PGV/PGA) (cells at their geometric centres), taken as a lognormal of their
rate-weighted mean and standard deviation; between cells interpolated in ln PGA, held
beyond the first and last cell with events.  The engine writes the mean's rate density
only: every branch then gets the mean's distribution (its PGA curve its own); a file with
the rate density per realisation gives each its own
(:func:`~pipeline.hazard.branch_ratio.mrd_ratios`)."""
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.ratio_described import DensityRatio
from pipeline.hazard.record import ABSENT


@dataclass(frozen=True)
class RatioFromMrd:
    """ln(PGV/PGA) (PGV m/s, PGA m/s^2: ln s) given PGA at ``pga_m_s2`` (the PGA cells
    with events): ``ln_mean`` and ``ln_sd``; ``source``: the file and site;
    ``realisation``: the realisation whose rate density it is (None: the mean's)."""
    pga_m_s2: np.ndarray
    ln_mean: np.ndarray
    ln_sd: np.ndarray
    source: dict
    realisation: int | None = None

    def __post_init__(self):
        if self.pga_m_s2.size < 1 or not (self.pga_m_s2.shape == self.ln_mean.shape ==
                                         self.ln_sd.shape):
            raise InputError(f"{self.source.get('file', 'mrd')}: no PGA cell with events")
        if np.any(np.diff(self.pga_m_s2) <= 0) or np.any(self.ln_sd < 0):
            raise InputError(f"{self.source.get('file', 'mrd')}: cells out of order")

    def ln_mean_sd(self, pga_m_s2):
        """(mean, sd) of ln(PGV/PGA) at PGA levels (m/s^2)."""
        ln_a = np.log(np.asarray(pga_m_s2, float))
        x = np.log(self.pga_m_s2)
        return np.interp(ln_a, x, self.ln_mean), np.interp(ln_a, x, self.ln_sd)

    def describe(self) -> DensityRatio:
        """The rate density as results describe it (its file and site where it was read
        from a file)."""
        return DensityRatio(
            source="mean rate density of PGA and PGV (mrd)" if self.realisation is None
            else f"rate density of PGA and PGV (mrd) of realisation rlz-{self.realisation}",
            file=self.source.get("file", ABSENT),
            site_index=self.source.get("site_index", ABSENT),
            pga_cells_with_events=int(self.pga_m_s2.size),
            distribution="lognormal given PGA: the rate-weighted mean and sd of the events' "
                         "ln(PGV/PGA) in each PGA cell (geometric centres)")


def ratio_from_mrd(joint, site, realisation=None):
    """The :class:`RatioFromMrd` of ``joint`` (a JointHazard) at ``site`` (0-based): of its
    mean, or of ``realisation`` r (an index of its ``realisation_rates_per_yr``)."""
    one = joint.site(site)
    rates = one.cell_rates_per_yr[0] if realisation is None else \
        one.realisation_rates_per_yr[realisation, 0]
    pga = np.sqrt(one.pga_levels_m_s2[:-1] * one.pga_levels_m_s2[1:])
    pgv = np.sqrt(one.pgv_levels_m_s[:-1] * one.pgv_levels_m_s[1:])
    total = rates.sum(axis=1)
    keep = total > 0
    ln_ratio = np.log(pgv)[None, :] - np.log(pga)[keep][:, None]
    w = rates[keep] / total[keep][:, None]
    mean = (w * ln_ratio).sum(axis=1)
    sd = np.sqrt(np.maximum((w * (ln_ratio - mean[:, None]) ** 2).sum(axis=1), 0.0))
    return RatioFromMrd(pga[keep], mean, sd, dict(one.source), realisation)
