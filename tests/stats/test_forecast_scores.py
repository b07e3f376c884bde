"""Scores of probability forecasts against closed forms: a threshold model whose
probabilities are known is on the reliability diagram's diagonal, a perfectly calibrated
forecaster's Brier score is UNC - RES with REL = 0, Murphy's identity holds exactly when
the forecasts within a bin are equal and otherwise differs by Stephenson et al.'s
within-bin terms; the log-likelihood's clip by hand."""
import math

import numpy as np
import pytest
from scipy.stats import norm

from pipeline.stats.forecast import (BIN_EDGES, bin_index, brier_decomposition,
                                     classification, forecast_scores, log_likelihood,
                                     reliability_table)


def _threshold_model(tests=20000, seed=3):
    """A rock whose overturning threshold T is lognormal (median 0.4 g, beta 0.5): at a
    test of intensity x, P = Phi(ln(x / 0.4) / 0.5); each test's outcome a fresh draw."""
    rng = np.random.default_rng(seed)
    x = np.exp(rng.uniform(np.log(0.05), np.log(3.0), tests))
    p = norm.cdf(np.log(x / 0.4) / 0.5)
    threshold = 0.4 * np.exp(0.5 * rng.standard_normal(tests))
    return p, (x > threshold).astype(int)


def test_known_probabilities_lie_on_the_diagonal():
    p, observed = _threshold_model()
    rows = reliability_table(observed, p, confidence=0.999)
    assert len(rows) == 10 and sum(r["n"] for r in rows) == len(p)
    for row in rows:
        lo, hi = row["observed_ci95"]
        assert lo <= row["mean_forecast"] <= hi, row
    # a forecaster that is not calibrated (P squared: too low in the middle) leaves them
    rows = reliability_table(observed, p ** 2, confidence=0.999)
    outside = [r for r in rows if not r["observed_ci95"][0] <= r["mean_forecast"]
               <= r["observed_ci95"][1]]
    assert len(outside) >= 5


def test_known_probabilities_have_small_reliability_and_the_brier_of_their_variance():
    p, observed = _threshold_model()
    d = brier_decomposition(observed, p)
    assert d["reliability"] < 2e-4
    # the expected Brier score of calibrated forecasts is mean P (1 - P)
    assert d["brier"] == pytest.approx(np.mean(p * (1 - p)), abs=0.005)


def test_perfectly_calibrated_forecasts_closed_form():
    # three forecasts, each bin's observed rate exactly its forecast
    p = np.repeat([0.2, 0.5, 0.9], [10, 4, 10])
    observed = np.concatenate([[1] * 2 + [0] * 8, [1, 1, 0, 0], [1] * 9 + [0]])
    mean = 13 / 24
    d = brier_decomposition(observed, p)
    assert d["reliability"] == pytest.approx(0.0, abs=1e-15)
    assert d["uncertainty"] == pytest.approx(mean * (1 - mean))
    resolution = (10 * (0.2 - mean) ** 2 + 4 * (0.5 - mean) ** 2 + 10 * (0.9 - mean) ** 2) / 24
    assert d["resolution"] == pytest.approx(resolution)
    assert d["brier"] == pytest.approx((10 * 0.16 + 4 * 0.25 + 10 * 0.09) / 24)
    assert d["brier"] == pytest.approx(d["uncertainty"] - d["resolution"])


def test_murphy_identity_is_exact_for_equal_forecasts_within_bins():
    rng = np.random.default_rng(7)
    p = rng.integers(0, 9, 500) / 8                 # members' P = k/8: one value per bin
    observed = rng.random(500) < p ** 0.7
    d = brier_decomposition(observed, p)
    assert d["brier"] == pytest.approx(d["reliability"] - d["resolution"] + d["uncertainty"],
                                       abs=1e-14)
    assert abs(d["within_bin"]) < 1e-14


def test_within_bin_term_is_stephensons():
    rng = np.random.default_rng(11)
    p = rng.random(400)
    y = (rng.random(400) < p).astype(float)
    d = brier_decomposition(y, p)
    k = np.minimum((p * 10).astype(int), 9)
    wbv = wbc = 0.0
    for b in range(10):
        f, o = p[k == b], y[k == b]
        if f.size:
            wbv += np.sum((f - f.mean()) ** 2)
            wbc += 2 * np.sum((o - o.mean()) * (f - f.mean()))
    assert d["within_bin"] == pytest.approx((wbv - wbc) / 400, abs=1e-14)
    assert abs(d["within_bin"]) > 1e-6


def test_bins_are_width_tenths_with_the_last_closed():
    assert list(bin_index([0.0, 0.0999, 0.1, 0.5, 0.95, 1.0])) == [0, 0, 1, 5, 9, 9]
    assert BIN_EDGES[0] == 0 and BIN_EDGES[-1] == 1 and len(BIN_EDGES) == 11


def test_log_likelihood_clips_by_the_monte_carlo_runs():
    # 0 of 4 members against an overturn: P held at 1/(2*5) = 0.1
    assert log_likelihood([1], [0.0], runs=[4]) == pytest.approx(math.log(0.1))
    assert log_likelihood([0], [0.0], runs=[8]) == pytest.approx(math.log(1 - 1 / 18))
    # an interior P from runs is not moved
    assert log_likelihood([1], [0.25], runs=[4]) == pytest.approx(math.log(0.25))
    # a 0/1 forecast without runs: held at 0.01
    assert log_likelihood([1, 0], [0, 0]) == pytest.approx((math.log(0.01) + math.log(0.99)) / 2)


def test_accuracy_and_balanced_accuracy_by_hand():
    # 6 overturned of which 5 have P > 0.5; 2 standing, 1 called right; P = 0.5 is standing
    observed = [1, 1, 1, 1, 1, 1, 0, 0]
    p = [0.9, 0.8, 0.6, 0.51, 1.0, 0.5, 0.5, 0.7]
    c = classification(observed, p)
    assert c["accuracy"] == pytest.approx(6 / 8)
    assert c["balanced_accuracy"] == pytest.approx((5 / 6 + 1 / 2) / 2)
    assert classification([1, 1], [0.9, 0.1])["balanced_accuracy"] is None


def test_forecast_scores_refuse_what_is_not_a_forecast():
    with pytest.raises(ValueError, match="0 or 1"):
        forecast_scores([2], [0.5])
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        forecast_scores([1], [1.5])
    with pytest.raises(ValueError, match="length"):
        forecast_scores([1, 0], [0.5])
    s = forecast_scores([1, 0], [1.0, 0.0], runs=[4, 8])
    assert s["clip"] == [pytest.approx(1 / 18), pytest.approx(0.1)]
    assert s["accuracy"] == 1.0 and s["brier"] == 0.0
