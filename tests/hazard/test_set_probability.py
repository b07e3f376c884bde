"""P(overturn) averaged over PGV/PGA, for one specimen, a set or many sets at once, against
values written down by hand: pulse grids whose P varies with PGA only (linear in ln PGA
between the cells, held beyond them: the average over PGV/PGA is that line, under any
PGV/PGA model), a lognormal over PGA (Phi), and a fragility lognormal in PGV whose average
over a lognormal PGV/PGA is again a lognormal (Phi(ln(PGA m / v50) / sqrt(beta^2 +
sigma^2))); the stacked evaluation of pulse grids against each grid alone; the sampled
ages' survival as one matrix product against each sample's own sum."""
import math
from dataclasses import dataclass

import numpy as np
import pytest
from scipy import stats

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.constrain import age_chain, log_survival_sampled
from pipeline.hazard.disagg_ratio import bin_shares, ratio_mixture
from pipeline.hazard.disaggregation import load_mag_dist
from pipeline.hazard.fragility import (Fragility, Logistic, Lognormal, PulseGrid, RatioFromGmm,
                                       RatioLognormal)
from pipeline.hazard.fragility.components import OnHazardMeasure
from pipeline.hazard.set_probability import (overturn_probability, ratio_quadrature,
                                             set_probabilities)

PGA = np.geomspace(0.02, 3.0, 37) * G           # below, inside and above the grids
NODES = np.array([0.1, 0.2, 0.4, 0.8]) * G
DISAGG = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / "disaggregation" / \
    "Mag_Dist-0_7.csv"


def _grid(below="ramp"):
    """A 4 x 3 grid (0.1-0.8 g x 0.1-0.6 s), one cell without runs, a surface outside."""
    ratio = (0.1, 0.3, 0.6)
    n = np.full((4, 3), 10)
    n[1, 2] = 0
    overturned = np.array([[0, 0, 1], [1, 2, 0], [4, 6, 8], [8, 9, 10]])
    surface = Logistic((-4 * math.log(0.3 * G) - 1.5 * math.log(0.3), 4.0, 1.5))
    return PulseGrid(tuple(NODES), ratio, n, overturned, np.full((2, 4, 3), np.nan),
                     outside=surface, uplift_m_s2=0.05 * G, below=below)


def _grids(rows):
    """One grid per row of ``rows`` (runs overturned of 10 at each PGA node, the same at
    every PGV/PGA), no surface outside and the edge's P held below: grids that differ in
    their counts only, P the same at any PGV/PGA."""
    return [PulseGrid(tuple(NODES), (0.1, 0.3, 0.6), np.full((4, 3), 10),
                      np.repeat(np.asarray(k)[:, None], 3, axis=1),
                      np.full((1, 4, 3), np.nan), below="edge") for k in rows]


def _by_hand(rows, pga):
    """The grids' P at ``pga``: linear in ln PGA between the nodes, held beyond them."""
    return np.array([np.interp(np.log(pga), np.log(NODES), np.asarray(k) / 10) for k in rows])


@dataclass(frozen=True)
class _PgvLognormal(Fragility):
    """P = Phi(ln(PGV / v50) / beta), PGV = PGA x PGV/PGA."""
    v50_m_s: float
    beta: float
    label = "lognormal in PGV"
    uses_ratio = True

    def probability(self, pga_m_s2, pgv_pga_s=None):
        return stats.norm.cdf(np.log(pga_m_s2 * pgv_pga_s / self.v50_m_s) / self.beta)

    def draws(self, n, rng):
        return None

    def describe(self):
        return {}


def _ratio_models():
    return {"lognormal": RatioLognormal(0.3, 0.5),
            "gmm": RatioFromGmm(6.5, 20.0, correlation=0.654),
            "mixture": ratio_mixture(load_mag_dist(DISAGG), "rlz1")}


@pytest.mark.parametrize("below", ["ramp", "zero", "edge", "logistic"])
def test_stacked_grids_give_each_grid_alone(below):
    grid = _grid(below)
    draws = grid.draws(7, np.random.default_rng(3))
    a, r = np.meshgrid(PGA, np.geomspace(0.03, 2.0, 11), indexing="ij")
    stacked = grid.probability_stack(draws, a, r)
    alone = np.array([d.probability(a, r) for d in draws])
    assert stacked.shape == (7, *a.shape)
    np.testing.assert_allclose(stacked, alone, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("name", ["lognormal", "gmm", "mixture"])
def test_sets_of_grids_against_their_cells_by_hand(name):
    """Nine sets of three (a grid drawn per set, a fixed lognormal, another grid): P(any)
    = 1 - prod(1 - P_j) at each PGA; one specimen's P each, and the largest (fully
    correlated).  Absolute round-off: the weights sum to 1 within a few ulp."""
    model = _ratio_models()[name]
    rng = np.random.default_rng(5)
    rows, others = rng.integers(0, 11, (9, 4)), rng.integers(0, 11, (9, 4))
    first, second = _grids(rows), _grids(others)
    fixed = Lognormal(0.5 * G, 0.4)
    p_fixed = stats.norm.cdf(np.log(PGA / (0.5 * G)) / 0.4)
    want = 1 - (1 - _by_hand(rows, PGA)) * (1 - p_fixed) * (1 - _by_hand(others, PGA))
    batch = [[first[k], fixed, second[k]] for k in range(9)]
    np.testing.assert_allclose(set_probabilities(batch, model, PGA), want, rtol=1e-12,
                               atol=1e-14)
    each = overturn_probability([first[0], fixed], model, PGA)
    np.testing.assert_allclose(each, [_by_hand(rows[:1], PGA)[0], p_fixed], rtol=1e-12,
                               atol=1e-15)
    largest = overturn_probability(batch[0], model, PGA, "any_correlated")
    np.testing.assert_allclose(largest, np.maximum(each.max(axis=0), _by_hand(others[:1],
                                                                              PGA)[0]),
                               rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError):
        set_probabilities(batch, model, PGA, "each")


@pytest.mark.parametrize("name", ["lognormal", "gmm", "mixture"])
def test_a_pgv_fragility_averaged_over_lognormal_pgv_pga(name):
    """ln PGV/PGA ~ N(mu(a), s(a)) (each bin's, weighted by its share, for the mixture):
    E[Phi((ln a + ln r - ln v50) / beta)] = Phi((ln a + mu - ln v50) / sqrt(beta^2 + s^2));
    24 Gauss-Hermite nodes integrate it to 1e-12 for s below beta."""
    model = _ratio_models()[name]
    specimen = _PgvLognormal(0.3, 0.6)
    bins = (model.models, bin_shares(model.anchors, model.shares, PGA).T) \
        if name == "mixture" else ((model,), np.ones((1, PGA.size)))
    want = sum(share * stats.norm.cdf((np.log(PGA) + mu - math.log(0.3)) / np.hypot(0.6, s))
               for m, share in zip(*bins) if m is not None
               for mu, s in [m.ln_mean_sd(PGA)])
    got = overturn_probability([specimen], model, PGA)[0]
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-14)


def test_pga_only_sets_and_a_mixed_column():
    rng = np.random.default_rng(2)
    lognormals = Lognormal(0.4 * G, 0.5, median_ci95=(0.3 * G, 0.5 * G)).draws(5, rng)
    batch = [[f, Lognormal(0.2 * G, 0.3)] for f in lognormals]
    want = [1 - stats.norm.sf(np.log(PGA / f.median_m_s2) / f.beta)
            * stats.norm.sf(np.log(PGA / (0.2 * G)) / 0.3) for f in lognormals]
    np.testing.assert_allclose(set_probabilities(batch, None, PGA), want, rtol=1e-12,
                               atol=1e-15)


def test_quadrature_shares_sum_to_one_at_every_level():
    for model in _ratio_models().values():
        points, shares = ratio_quadrature(model, PGA)
        assert points.shape[:2] == shares.shape and points.shape[0] == PGA.size
        np.testing.assert_allclose(shares.sum(axis=1), 1.0, rtol=1e-12)


def test_grids_on_the_hazards_measure_stack_as_their_grids():
    """P(x) = the grid's P(x / fraction), the wrapped grids evaluated as one stack."""
    fraction = 0.8
    rows = np.random.default_rng(4).integers(0, 11, (6, 4))
    wrapped = [OnHazardMeasure(g, fraction, {"fraction": fraction}) for g in _grids(rows)]
    assert all(wrapped[0].stacks_with(d) for d in wrapped)
    got = set_probabilities([[d] for d in wrapped], RatioLognormal(0.3, 0.5), PGA)
    np.testing.assert_allclose(got, _by_hand(rows, PGA / fraction), rtol=1e-12, atol=1e-14)


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
