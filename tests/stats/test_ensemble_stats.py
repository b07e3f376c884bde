"""Ensemble statistics against hand-computed numbers and known distributions."""
import math

import numpy as np
import pytest
from scipy import stats

from pipeline.stats.ensemble import (bootstrap_mean_azimuth_ci, circular_density,
                                     direction_fractions, wilson_interval)
from pipeline.stats.fragility import lognormal_fragility


def test_wilson_interval_by_hand():
    # 7 of 10, 95 %: (p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)
    n, k, z = 10, 7, stats.norm.ppf(0.975)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    assert wilson_interval(k, n) == pytest.approx([centre - half, centre + half], abs=1e-9)
    assert wilson_interval(0, 10)[0] == 0.0 and wilson_interval(10, 10)[1] == 1.0


def test_bootstrap_interval_contains_the_mean_and_wraps_through_north():
    rng = np.random.default_rng(2)
    tight = (rng.normal(0.0, 5.0, 40)) % 360
    lo, hi = bootstrap_mean_azimuth_ci(tight)
    width = (hi - lo) % 360
    assert width < 10                      # 2 x 1.96 x 5 / sqrt(40) = 3.1 deg
    assert (0 - lo) % 360 < width          # North (the mean) lies between lo and hi
    loose = (rng.normal(0.0, 40.0, 40)) % 360
    lo2, hi2 = bootstrap_mean_azimuth_ci(loose)
    assert (hi2 - lo2) % 360 > width
    assert bootstrap_mean_azimuth_ci([12.0]) is None


def test_direction_fractions():
    falls = [175.0, 185.0, 5.0, 90.0]     # back azimuth 180: two toward, one away, one across
    f = direction_fractions(falls, 180.0)
    assert (f["fraction_toward"], f["fraction_away"], f["fraction_transverse"]) == (0.5, 0.25, 0.25)
    assert direction_fractions(falls, None)["fraction_toward"] is None


def test_circular_density_integrates_to_one():
    grid = np.arange(0.0, 360.0, 1.0)
    density = circular_density([350.0, 10.0, 20.0], grid)
    assert density.sum() == pytest.approx(1.0, rel=1e-6)
    assert 0.0 <= grid[density.argmax()] <= 20.0


def test_lognormal_fragility_recovers_a_known_curve():
    rng = np.random.default_rng(5)
    median, beta = 2.5, 0.4
    im = np.exp(rng.uniform(np.log(0.5), np.log(12.0), 4000))
    toppled = rng.random(im.size) < stats.norm.cdf(np.log(im / median) / beta)
    fit = lognormal_fragility(im, toppled)
    assert fit["median"] == pytest.approx(median, rel=0.05)
    assert fit["beta"] == pytest.approx(beta, rel=0.1)
    assert fit["median_ci95"][0] < median < fit["median_ci95"][1]
    assert fit["beta_ci95"][0] < beta < fit["beta_ci95"][1]
