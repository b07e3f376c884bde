"""PGV/PGA (s) at a PGA level, and the nodes P(overturn) is averaged over it with.

PGV/PGA at a PGA level is lognormal: :class:`RatioLognormal` (a median and sigma the user
states, the same at every level) or :class:`RatioFromGmm` (the median and sigma of PGV and
PGA from Boore et al. 2014 (pygmm) at a magnitude and distance, for example the mode of
the hazard's disaggregation; ln PGV given ln PGA by their correlation).
:func:`pipeline.hazard.set_probability.overturn_probability` averages fragilities
(:class:`~pipeline.hazard.fragility.kinds.Fragility`) over it.
"""
import functools
import importlib.metadata
import math
from dataclasses import dataclass, field

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.pga_pgv_correlation import BAKER_BRADLEY_2017, correlation_source
from pipeline.hazard.ratio_described import ScenarioRatio, StatedRatio

RATIO_NODES = 24                  # Gauss-Hermite nodes over ln(PGV/PGA)
PGA_PGV_CORRELATION = BAKER_BRADLEY_2017.value   # ln PGA, ln PGV residuals, observed
DEFAULT_VS30_M_S = 760.0          # the model's site: rock (B/C), the USGS hazard curves' Vs30
GMM_MECHANISMS = ("SS", "NS", "RS")
GMM_MODEL = ("Boore, Stewart, Seyhan & Atkinson (2014), pygmm BooreStewartSeyhanAtkinson2014 "
             "(RotD50)")


@dataclass(frozen=True)
class RatioLognormal:
    """PGV/PGA lognormal with ``median_s`` (s) and ``sigma_ln``, the same at every PGA."""
    median_s: float
    sigma_ln: float

    def ln_mean_sd(self, pga_m_s2):
        pga = np.asarray(pga_m_s2, float)
        return np.full(pga.shape, math.log(self.median_s)), np.full(pga.shape, self.sigma_ln)

    def describe(self) -> StatedRatio:
        return StatedRatio(distribution="lognormal, the same at every PGA",
                           median_s=self.median_s, sigma_ln=self.sigma_ln)


@dataclass(frozen=True)
class RatioFromGmm:
    """PGV/PGA at a PGA level from a ground-motion model at a magnitude and distance:
    ln PGV given ln PGA = a is normal with mean mu_v + rho (s_v / s_a)(a - mu_a) and
    sd s_v sqrt(1 - rho^2); PGV/PGA = PGV / a."""
    magnitude: float
    distance_km: float
    vs30_m_s: float = DEFAULT_VS30_M_S
    mechanism: str = "SS"
    correlation: float = PGA_PGV_CORRELATION
    medians: dict = field(default=None, compare=False)

    def __post_init__(self):
        import pygmm  # lazy: pygmm, slow to import and only for a ground-motion model's PGV/PGA
        scenario = pygmm.Scenario(mag=self.magnitude, dist_jb=self.distance_km,
                                  v_s30=self.vs30_m_s, mechanism=self.mechanism)
        model = pygmm.BooreStewartSeyhanAtkinson2014(scenario)
        object.__setattr__(self, "medians", {
            "pga_m_s2": float(model.pga) * STANDARD_GRAVITY, "ln_std_pga": float(model.ln_std_pga),
            "pgv_m_s": float(model.pgv) / 100.0, "ln_std_pgv": float(model.ln_std_pgv)})

    def ln_mean_sd(self, pga_m_s2):
        m, rho = self.medians, self.correlation
        ln_a = np.log(np.asarray(pga_m_s2, float))
        eps_a = (ln_a - math.log(m["pga_m_s2"])) / m["ln_std_pga"]
        mean_v = math.log(m["pgv_m_s"]) + rho * m["ln_std_pgv"] * eps_a
        sd = m["ln_std_pgv"] * math.sqrt(1.0 - rho ** 2)
        return mean_v - ln_a, np.full(ln_a.shape, sd)

    def describe(self) -> ScenarioRatio:
        m = self.medians
        return ScenarioRatio(
            model=GMM_MODEL, magnitude=self.magnitude, distance_jb_km=self.distance_km,
            vs30_m_s=self.vs30_m_s, mechanism=self.mechanism,
            pga_pgv_correlation=self.correlation,
            pga_pgv_correlation_source=correlation_source(self.correlation),
            median_pga_m_s2=m["pga_m_s2"], median_pgv_m_s=m["pgv_m_s"],
            ln_std_pga=m["ln_std_pga"], ln_std_pgv=m["ln_std_pgv"],
            pygmm=importlib.metadata.version("pygmm"),
            distribution="lognormal given PGA: ln PGV | ln PGA by their correlation")


@functools.cache
def ratio_nodes():
    """Gauss-Hermite nodes and weights (summing to 1) over a standard normal, computed once
    (read only)."""
    nodes, weights = np.polynomial.hermite_e.hermegauss(RATIO_NODES)
    nodes.flags.writeable = False
    weights = weights / weights.sum()
    weights.flags.writeable = False
    return nodes, weights

