"""Many fragility sets at once (constrain's draws and members): the stacked evaluation of
pulse grids and the one quadrature over PGV/PGA give what a loop over the draws gives
with the one-set function (each grid alone, each bin of a disaggregation alone), to
round-off, on a toy grid with an empty cell, points below, inside, beside and above it;
the sampled ages' survival as one matrix product against each sample's own sum."""
import math

import numpy as np
import pytest

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.constrain import age_chain, log_survival_sampled
from pipeline.hazard.disagg_ratio import overturn_probability_over, ratio_mixture
from pipeline.hazard.disaggregation import load_mag_dist
from pipeline.hazard.fragility import Logistic, Lognormal, PulseGrid, RatioFromGmm, RatioLognormal
from pipeline.hazard.fragility.components import OnHazardMeasure
from pipeline.hazard.set_probability import ratio_quadrature, set_probabilities

PGA = np.geomspace(0.02, 3.0, 37) * G           # below, inside and above the grid
DISAGG = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / "disaggregation" / \
    "Mag_Dist-0_7.csv"


def _grid(below="ramp"):
    """A 4 x 3 grid (0.1-0.8 g x 0.1-0.6 s), one cell without runs, a surface outside."""
    pga = tuple(np.array([0.1, 0.2, 0.4, 0.8]) * G)
    ratio = (0.1, 0.3, 0.6)
    n = np.full((4, 3), 10)
    n[1, 2] = 0
    overturned = np.array([[0, 0, 1], [1, 2, 0], [4, 6, 8], [8, 9, 10]])
    surface = Logistic((-4 * math.log(0.3 * G) - 1.5 * math.log(0.3), 4.0, 1.5))
    return PulseGrid(pga, ratio, n, overturned, np.full((2, 4, 3), np.nan), outside=surface,
                     uplift_m_s2=0.05 * G, below=below)


@pytest.mark.parametrize("below", ["ramp", "zero", "edge", "logistic"])
def test_stacked_grids_give_each_grid_alone(below):
    grid = _grid(below)
    draws = grid.draws(7, np.random.default_rng(3))
    a, r = np.meshgrid(PGA, np.geomspace(0.03, 2.0, 11), indexing="ij")
    stacked = grid.probability_stack(draws, a, r)
    alone = np.array([d.probability(a, r) for d in draws])
    assert stacked.shape == (7, *a.shape)
    np.testing.assert_allclose(stacked, alone, rtol=1e-13, atol=1e-15)


def _loop(batch, ratio_model):
    """The one-set function, draw by draw."""
    return np.array([overturn_probability_over(chosen, ratio_model, PGA, "any_common")
                     for chosen in batch])


def _ratio_models():
    return {"lognormal": RatioLognormal(0.3, 0.5),
            "gmm": RatioFromGmm(6.5, 20.0, correlation=0.654),
            "mixture": ratio_mixture(load_mag_dist(DISAGG), "rlz1")}


@pytest.mark.parametrize("name", ["lognormal", "gmm", "mixture"])
def test_sets_of_draws_give_the_loop_over_draws(name):
    ratio_model = _ratio_models()[name]
    rng = np.random.default_rng(5)
    grid, other = _grid(), _grid("edge")
    fixed = Lognormal(0.5 * G, 0.4)
    first, second = grid.draws(9, rng), other.draws(9, rng)
    batch = [[first[k], fixed, second[k]] for k in range(9)]
    got = set_probabilities(batch, ratio_model, PGA)
    # absolute round-off of 1 - sum(...) on a probability: the mixture's shares sum to 1
    # within a few ulp, so P of 1e-15 is round-off either way
    np.testing.assert_allclose(got, _loop(batch, ratio_model), rtol=1e-12, atol=1e-14)
    members = [[m] for m in grid.members() or [grid]]
    np.testing.assert_allclose(set_probabilities(members, ratio_model, PGA),
                               _loop(members, ratio_model), rtol=1e-12, atol=1e-14)


def test_pga_only_sets_and_a_mixed_column():
    rng = np.random.default_rng(2)
    lognormals = Lognormal(0.4 * G, 0.5, median_ci95=(0.3 * G, 0.5 * G)).draws(5, rng)
    batch = [[f, Lognormal(0.2 * G, 0.3)] for f in lognormals]
    np.testing.assert_allclose(set_probabilities(batch, None, PGA), _loop(batch, None),
                               rtol=1e-12, atol=1e-15)


def test_quadrature_weights_sum_to_one_at_every_level():
    for model in _ratio_models().values():
        points, weights = ratio_quadrature(model, PGA)
        assert points.shape == weights.shape and points.shape[0] == PGA.size
        np.testing.assert_allclose(weights.sum(axis=1), 1.0, rtol=1e-12)


def test_grids_on_the_hazards_measure_stack_as_their_grids():
    fraction = 0.8
    wrapped = OnHazardMeasure(_grid(), fraction, {"fraction": fraction})
    draws = wrapped.draws(6, np.random.default_rng(4))
    assert all(draws[0].stacks_with(d) for d in draws)
    batch = [[d] for d in draws]
    ratio_model = RatioLognormal(0.3, 0.5)
    np.testing.assert_allclose(set_probabilities(batch, ratio_model, PGA),
                               _loop(batch, ratio_model), rtol=1e-12, atol=1e-14)


def test_sampled_ages_as_the_sum_over_each_sample():
    """ln P_s over sampled ages against each sample's own sum of dt x rate."""
    rng = np.random.default_rng(8)
    ages = rng.uniform(1e3, 2e4, size=(300, 3))
    rate_of = {}

    def set_rates(members):
        return rate_of.setdefault(members, rng.uniform(1e-6, 1e-4, size=(2, 5)))
    log_p, se = log_survival_sampled(lambda sets: [set_rates(m) for m in sets], ages)
    logs = np.array([-sum(dt * set_rates(m) for m, dt in age_chain(a)) for a in ages])
    want = np.log(np.exp(logs).mean(axis=0))
    np.testing.assert_allclose(log_p, want, rtol=1e-12)
    p = np.exp(logs) / np.exp(want)
    np.testing.assert_allclose(se, p.std(axis=0, ddof=1) / np.sqrt(len(ages)), rtol=1e-9)
