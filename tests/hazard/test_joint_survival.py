"""Survival against a joint hazard of PGA and PGV, checked against independent
computations: one scenario's bivariate lognormal motion integrated directly
(Gauss-Hermite) and through the scalar-curve code (PGA curve and PGV/PGA given PGA), and
the shipped rate density of OpenQuake's QA case against its own PGA curve."""
import math

import numpy as np
import pytest
from scipy import stats

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.curves import load_hazard
from pipeline.hazard.fragility import Logistic, Lognormal, RatioFromGmm
from pipeline.hazard.joint_hazard import load_joint_hazard
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.joint_survival import (cell_mean_probability, joint_overturning_rate,
                                            scenario_cell_rates)
from pipeline.hazard.pga_pgv_correlation import BAKER_BRADLEY_2017
from pipeline.hazard.survival import overturning_rate

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
# a PBR-like surface: P = 0.5 at PGA 3 m/s^2 and PGV/PGA 0.1 s (Purvance et al. 2008 form)
SURFACE = Logistic((-4 * math.log(3.0) - 3 * math.log(0.1), 4.0, 3.0))
EVENTS_PER_YR = 0.01
SPAN = 7.0                     # the grid spans +-7 sd of each ln IM


def _scenario():
    """Boore et al. (2014) at M 6.5, 10 km (pygmm, as the survival command uses it)."""
    gmm = RatioFromGmm(6.5, 10.0, correlation=BAKER_BRADLEY_2017.value)
    m = gmm.medians
    return gmm, (math.log(m["pga_m_s2"]), m["ln_std_pga"], math.log(m["pgv_m_s"]),
                 m["ln_std_pgv"], gmm.correlation)


def _direct_rate(law, nodes=80):
    """EVENTS_PER_YR x E[P(A, V/A)] by Gauss-Hermite over the bivariate normal."""
    mu_a, s_a, mu_v, s_v, rho = law
    z, w = np.polynomial.hermite_e.hermegauss(nodes)
    w = w / w.sum()
    z1, z2 = np.meshgrid(z, z, indexing="ij")
    ln_a = mu_a + s_a * z1
    ln_v = mu_v + s_v * (rho * z1 + math.sqrt(1 - rho ** 2) * z2)
    p = SURFACE.probability(np.exp(ln_a), np.exp(ln_v - ln_a))
    return EVENTS_PER_YR * float(np.einsum("ij,i,j->", p, w, w))


def _grid(law, levels=61):
    mu_a, s_a, mu_v, s_v, _ = law
    return (np.exp(np.linspace(mu_a - SPAN * s_a, mu_a + SPAN * s_a, levels)),
            np.exp(np.linspace(mu_v - SPAN * s_v, mu_v + SPAN * s_v, levels)))


def test_one_scenario_as_a_joint_hazard_gives_the_direct_integral():
    _, law = _scenario()
    pga, pgv = _grid(law)
    cells = scenario_cell_rates(pga, pgv, EVENTS_PER_YR, *law)
    assert cells.sum() == pytest.approx(EVENTS_PER_YR, rel=1e-6)
    rate = joint_overturning_rate(pga, pgv, cells, SURFACE.probability)
    assert rate.rate_per_yr == pytest.approx(_direct_rate(law), rel=1e-4)
    assert rate.share_top_pga < 1e-6 and rate.share_top_pgv < 1e-6


def test_the_cell_integration_converges_at_second_order_at_least():
    """Half the cells' width, at most a quarter of the error."""
    _, law = _scenario()
    direct = _direct_rate(law)
    errors = []
    for levels in (31, 61, 121):
        pga, pgv = _grid(law, levels)
        cells = scenario_cell_rates(pga, pgv, EVENTS_PER_YR, *law)
        rate = joint_overturning_rate(pga, pgv, cells, SURFACE.probability).rate_per_yr
        errors.append(abs(rate / direct - 1))
    assert errors[0] / errors[1] > 4.0 and errors[1] / errors[2] > 4.0


def test_one_scenario_as_a_joint_hazard_gives_what_the_scalar_curve_code_gives():
    """Today's route: the scenario's PGA curve and PGV/PGA given PGA from the same
    model and correlation (:class:`RatioFromGmm`, :func:`overturning_rate`)."""
    gmm, law = _scenario()
    mu_a, s_a = law[:2]
    levels = _grid(law, 121)[0]      # the scalar code's curve on finer levels
    rates = EVENTS_PER_YR * stats.norm.sf((np.log(levels) - mu_a) / s_a)
    def probability(x):
        return overturn_probability([SURFACE], gmm, x)[0]
    scalar = overturning_rate(levels, rates, probability)["rate_per_yr"]
    pga, pgv = _grid(law)
    joint = joint_overturning_rate(pga, pgv, scenario_cell_rates(pga, pgv, EVENTS_PER_YR,
                                                                 *law), SURFACE.probability)
    direct = _direct_rate(law)       # each code within its integration error of it
    assert scalar == pytest.approx(direct, rel=2e-3)
    assert joint.rate_per_yr == pytest.approx(direct, rel=1e-4)


def test_the_correlation_moves_the_rate():
    """Not a test that cannot fail: the rate depends on the correlation (the surface
    rewards PGV/PGA, so its spread given PGA matters)."""
    _, law = _scenario()
    pga, pgv = _grid(law)
    rates = [joint_overturning_rate(pga, pgv, scenario_cell_rates(
        pga, pgv, EVENTS_PER_YR, *law[:4], rho), SURFACE.probability).rate_per_yr
        for rho in (0.654, 0.733)]
    assert abs(rates[0] / rates[1] - 1) > 0.005


def test_a_pga_only_fragility_on_the_shipped_mrd_gives_the_pga_curves_rate():
    """The cells and the curve's intervals agree to 0.1 % (test_joint_hazard); what
    remains is the two integrations' error on the engine's levels (0.27 apart in ln
    PGA): within 2 %."""
    joint = load_joint_hazard(CASE / "mrd_pga_pgv.hdf5").site(0)
    curve = load_hazard(CASE / "hazard_curve-mean-PGA_6.csv")
    fragility = Lognormal(0.02 * STANDARD_GRAVITY, 0.5)   # the site's hazard is low
    joint_rate = joint_overturning_rate(joint.pga_levels_m_s2, joint.pgv_levels_m_s,
                                        joint.cell_rates_per_yr[0], fragility.probability)
    scalar = overturning_rate(curve.levels_m_s2, curve.rates_per_yr,
                              lambda x: fragility.probability(x))["rate_per_yr"]
    assert joint_rate.rate_per_yr == pytest.approx(scalar, rel=0.02)


def test_cell_average_of_a_probability_linear_in_log_pga_is_exact():
    pga = np.array([1.0, 2.0, 8.0])
    pgv = np.array([0.1, 0.3])
    mean = cell_mean_probability(pga, pgv, lambda a, r: np.log(a) + 0 * r)   # even
    np.testing.assert_allclose(mean[:, 0], [0.5 * math.log(2.0), 0.5 * math.log(16.0)])
