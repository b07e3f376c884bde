"""A published multi-branch example: the 27-branch logic tree of Baker, Bradley & Stafford
(2021), Seismic Hazard and Risk Analysis (Cambridge), chapter 9, from the book's public code
(github.com/bakerjw/seismic-hazard-and-risk, MIT; records/hazard/bbs2021_chapter9_epistemic).

What the book's code gives, and what is checked against it:

- its 27 curves and weights (hazardEpistemicData.mat): the shipped plain table is that file,
  and three of its branches are recomputed here from the book's inputs (its simple PSHA of
  chapter6/psha_example_calcs_GR.m: a point source at 10 km, Gutenberg-Richter magnitudes
  5-8, Boore, Joyner & Fumal 1997 at T = 1 s, Vs30 500 m/s, strike-slip);
- its mean hazard curve (recorded in chapter9/risk_target.m): constrain's prior mean;
- its fractiles: the book's code ranks the branches and steps through their cumulative
  weights (the stairs of risk_metrics_epistemic.m: the q fractile is the first ranked
  value whose cumulative weight reaches q).  constrain uses OpenQuake's rule, which
  interpolates linearly in cumulative weight between the ranked values, so its fractile
  lies between the book's value and the ranked value below it, never outside;
- its failure rate (chapter 9, lambda(F) = sum_k P(F | x_k) |lambda(x_k+1) - lambda(x_k)|,
  the fragility at the lower end of each of the 99 intervals, nothing above 2 g): under a
  rising fragility this left sum is a lower bound, the right sum an upper bound, and
  constrain's cell integration (the curve interpolated in (ln x, ln rate), 200 cells per
  interval, P at each cell's midpoint) lies between them (about 5 % above the book's
  left sum on these levels, which are 3.8 % apart); refined 64 times, the book's left and
  right sums close on constrain's value to a few parts in ten thousand.
"""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import io, stats

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.files import InputError
from pipeline.hazard.constrain import branch_rates, cell_matrix, motion_at_rate
from pipeline.hazard.ages import TruncatedNormal
from pipeline.hazard.constrain import FLOOR
from pipeline.hazard.constrain_assess import FRACTILES, constrain_tree
from pipeline.hazard.fragility import Lognormal
from pipeline.hazard.logictree import load_logic_tree

BOOK = RECORDS_DIR / "hazard" / "bbs2021_chapter9_epistemic"
TABLE = BOOK / "logic_tree_sa1.csv"
LEVELS_G = np.logspace(math.log10(0.05), math.log10(2.0), 100)   # risk_metrics_epistemic.m


def _columns(path: Path):
    """The numeric columns of a records CSV (comment lines and the header skipped)."""
    rows = [line.split(",") for line in path.read_text().splitlines()
            if line and not line.startswith("#")][1:]
    return np.array(rows, float).T


@pytest.fixture(scope="module")
def tree():
    return load_logic_tree(TABLE, imt="SA(1.0)")


def _prior(tree):
    summary, _, _ = constrain_tree(tree, [Lognormal(0.4 * G, 0.4)], None,
                                   [TruncatedNormal(1e3)], "bayes", FLOOR, 0, 0)
    return summary.prior


def test_the_table_is_the_books_file(tree):
    """The plain table holds hazardEpistemicData.mat's 27 curves and weights, unchanged."""
    book = io.loadmat(BOOK / "hazardEpistemicData.mat")
    assert tree.imt == "SA(1.0)" and tree.size == 27 and not tree.notes
    np.testing.assert_array_equal(tree.rates_per_yr, book["lambda_x"])
    np.testing.assert_array_equal(tree.weights, book["wt"].ravel())
    np.testing.assert_allclose(tree.levels_m_s2, LEVELS_G * G, rtol=1e-15)


def test_another_imt_only_when_asked_for():
    """The table is SA(1 s): refused as a PGA tree (the fragility's), and an OpenQuake
    export is read for PGA only."""
    with pytest.raises(InputError, match=r"IMT SA\(1.0\): the fragility is over PGA"):
        load_logic_tree(TABLE)
    with pytest.raises(InputError, match="PGA only"):
        load_logic_tree(RECORDS_DIR / "hazard" / "openquake_logictree_case_11", imt="SA(1.0)")


def _bjf97_t1(magnitude, distance_km=10.0, vs30=500.0):
    """Median SA(1 s) (g) and ln sigma of Boore, Joyner & Fumal (1997), strike-slip: the
    T = 1 s coefficients of the book's utils/gmm_bjf97.m."""
    b1, b2, b3, b5, bv, va, h = -1.133, 1.036, -0.032, -0.798, -0.698, 1406.0, 2.9
    m = np.asarray(magnitude, float) - 6.0
    ln_y = (b1 + b2 * m + b3 * m ** 2 + b5 * math.log(math.hypot(distance_km, h))
            + bv * math.log(vs30 / va))
    return np.exp(ln_y), math.hypot(0.474, 0.214)


def test_three_branches_from_the_books_psha(tree):
    """Branch 10 is the book's chapter 6 example (0.05 earthquakes of M > 5 per year,
    magnitudes binned every 0.2 up to 8, BJF97), recomputed as its fn_PSHA_given_M_lambda
    does; branches 1 and 19 are the same source at 0.03 and 0.07 per year (the first
    level of the tree scales the rate).  To ten digits: the book's 1 - normcdf against
    scipy's survival function at the curve's far end."""
    exceed = np.array([0.05, 0.03153, 0.01988, 0.01252, 0.007882, 0.004955, 0.003108,
                       0.001942, 0.001207, 0.0007432, 0.0004505, 0.0002657, 0.0001492,
                       7.57e-05, 2.93e-05])                     # its Table 3.5 column
    magnitudes = np.arange(5.1, 8.0, 0.2)
    occur = np.append(-np.diff(exceed), exceed[-1])
    median, sigma = _bjf97_t1(magnitudes)
    curve = np.array([occur @ stats.norm.sf(np.log(x), np.log(median), sigma)
                      for x in LEVELS_G])
    np.testing.assert_allclose(tree.rates_per_yr[9], curve, rtol=1e-10)
    np.testing.assert_allclose(tree.rates_per_yr[0], 0.6 * curve, rtol=1e-10)
    np.testing.assert_allclose(tree.rates_per_yr[18], 1.4 * curve, rtol=1e-10)


def test_the_base_branch_between_the_books_finer_levels(tree):
    """The book records branch 10 again on 100 levels from 0.001 g (risk_metrics.m): the
    ground motion at each of its rates, read from the table's coarser levels by constrain's
    (ln rate, ln x) interpolation, is its level within 2e-4 (the curve's bend between
    levels 3.8 % apart)."""
    levels_g, rates = _columns(BOOK / "book_base_branch_sa1.csv")
    inside = levels_g >= LEVELS_G[0]
    got = [motion_at_rate(tree.levels_m_s2, tree.rates_per_yr[9], r) for r in rates[inside]]
    np.testing.assert_allclose(np.array(got) / G, levels_g[inside], rtol=2e-4)


def test_constrains_prior_mean_is_the_books_mean(tree):
    """The prior mean is the book's recorded mean curve (risk_target.m's 15-16 digits)."""
    levels_g, mean = _columns(BOOK / "book_mean_hazard_sa1.csv")
    np.testing.assert_allclose(levels_g, LEVELS_G, rtol=1e-15)
    np.testing.assert_allclose(_prior(tree).mean_rates_per_yr, mean, rtol=1e-13)


def _book_fractile(values, weights, q):
    """The book's rule at each level: the branches ranked, the first whose cumulative
    weight reaches q; and the ranked value before it (the same for the first)."""
    order = np.argsort(values, axis=0, kind="stable")
    ranked = np.take_along_axis(values, order, axis=0)
    cumulative = np.cumsum(weights[order], axis=0)
    k = np.argmax(cumulative >= q - 1e-12, axis=0)
    columns = np.arange(values.shape[1])
    return ranked[k, columns], ranked[np.maximum(k - 1, 0), columns]


@pytest.mark.parametrize("q", FRACTILES)
def test_prior_fractiles_against_the_books_stepped_fractiles(tree, q):
    """constrain's q fractile lies between the book's (stepped) fractile and the ranked
    branch below it at every level: the rules differ only in interpolating the step."""
    got = np.array(_prior(tree).fractiles[f"{q:g}"])
    book, below = _book_fractile(tree.rates_per_yr, tree.weights, q)
    assert np.all(below * (1 - 1e-12) <= got) and np.all(got <= book * (1 + 1e-12))
    assert np.any(got < book * (1 - 1e-3))             # the step is interpolated


def _book_failure_rates(levels_g, rates, fragility, right=False):
    """Chapter 9's lambda(F) per branch: P(F | x) at the lower (or upper) end of each
    interval times the rate falling in it; nothing above the last level."""
    p = fragility(levels_g)
    d_rate = -np.diff(rates, axis=1)
    return d_rate @ (p[1:] if right else p[:-1])


def _refined(tree, per_interval):
    """The curves on levels ``per_interval`` times finer, interpolated in (ln x, ln rate)."""
    ln_x = np.log(LEVELS_G)
    fine = np.concatenate([np.linspace(a, b, per_interval, endpoint=False)
                           for a, b in zip(ln_x[:-1], ln_x[1:])] + [ln_x[-1:]])
    rates = np.exp([np.interp(fine, ln_x, np.log(r)) for r in tree.rates_per_yr])
    return np.exp(fine), rates


@pytest.mark.parametrize("median_g", [0.4, 0.6])            # the book's two fragilities
def test_failure_rates_the_integration_difference(tree, median_g):
    """Per branch, constrain's rate within the curve lies between the book's left and
    right sums on its levels, the left sum (the book's number) 3-7 % below it; on levels
    64 times finer both sums close on it (their gap under 3e-3 of it)."""
    def fragility(x_g):
        return stats.norm.cdf(np.log(x_g / median_g) / 0.4)
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    rates = branch_rates(cells, tree.levels_m_s2, tree.rates_per_yr,
                         lambda x: fragility(x / G))
    within = rates - fragility(LEVELS_G[-1]) * tree.rates_per_yr[:, -1]
    left = _book_failure_rates(LEVELS_G, tree.rates_per_yr, fragility)
    right = _book_failure_rates(LEVELS_G, tree.rates_per_yr, fragility, right=True)
    assert np.all(left < within) and np.all(within < right)
    assert np.all((within / left > 1.03) & (within / left < 1.07))
    fine_x, fine_rates = _refined(tree, 64)
    fine_left = _book_failure_rates(fine_x, fine_rates, fragility)
    fine_right = _book_failure_rates(fine_x, fine_rates, fragility, right=True)
    assert np.all(fine_left <= within * (1 + 1e-12)) and np.all(within <= fine_right)
    assert np.all((fine_right - fine_left) / within < 3e-3)


def test_bayes_weights_with_the_books_fragility(tree):
    """The book's fragility (median 0.4 g, beta 0.4) standing for 1000 years: the posterior
    weights w_i exp(-lambda_i t) / sum, lambda_i the failure rate on levels 64 times finer
    (the mean of the left and right sums, plus the exceedances of 2 g counted at it)."""
    def fragility(x_g):
        return stats.norm.cdf(np.log(x_g / 0.4) / 0.4)
    fine_x, fine_rates = _refined(tree, 64)
    lam = 0.5 * (_book_failure_rates(fine_x, fine_rates, fragility)
                 + _book_failure_rates(fine_x, fine_rates, fragility, right=True)) \
        + fragility(LEVELS_G[-1]) * tree.rates_per_yr[:, -1]
    expected = tree.weights * np.exp(-lam * 1000.0)
    summary, rows, _ = constrain_tree(tree, [Lognormal(0.4 * G, 0.4)], None,
                                   [TruncatedNormal(1e3)], "bayes", FLOOR, 0, 0)
    got = np.array([r.posterior_bayes for r in rows])
    np.testing.assert_allclose(got, expected / expected.sum(), rtol=2e-3)
    np.testing.assert_allclose([r.survival_probability for r in rows],
                               np.exp(-lam * 1000.0), rtol=2e-3)
