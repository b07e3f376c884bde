"""PGV/PGA given PGA from a rate density: one scenario's bivariate lognormal PGA and PGV
(in closed form, cells from its CDF) gives back the conditional ln PGV | ln PGA of the
bivariate normal (mean mu_v + rho s_v / s_a (ln a - mu_a), sd s_v sqrt(1 - rho^2))."""
import math

import numpy as np

from pipeline.hazard.joint_hazard import JointHazard
from pipeline.hazard.joint_survival import scenario_cell_rates
from pipeline.hazard.mrd_ratio import ratio_from_mrd

MU_A, S_A, MU_V, S_V, RHO = math.log(1.0), 0.6, math.log(0.08), 0.7, 0.654


def test_a_scenario_gives_the_bivariate_normals_conditional():
    pga = np.exp(np.linspace(MU_A - 6 * S_A, MU_A + 6 * S_A, 241))
    pgv = np.exp(np.linspace(MU_V - 6 * S_V, MU_V + 6 * S_V, 241))
    rates = scenario_cell_rates(pga, pgv, 0.01, MU_A, S_A, MU_V, S_V, RHO)
    joint = JointHazard(pga, pgv, rates[None], 1.0, ((0.0, 0.0),), {"file": "scenario"})
    ratio = ratio_from_mrd(joint, 0)
    at = np.exp(MU_A + S_A * np.array([-2.0, -1.0, 0.0, 1.0, 2.0]))
    mean, sd = ratio.ln_mean_sd(at)
    expected = MU_V + RHO * S_V / S_A * (np.log(at) - MU_A) - np.log(at)
    np.testing.assert_allclose(mean, expected, atol=0.01)
    np.testing.assert_allclose(sd, S_V * math.sqrt(1 - RHO ** 2), rtol=0.02)
    assert ratio.describe().source.startswith("mean rate density")
