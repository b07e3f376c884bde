"""A set of specimens of different ages at one site, shaken by the same earthquakes: the
age chain of ``constrain`` (:func:`pipeline.hazard.constrain.log_survival_fixed`)
against a Monte Carlo of Poisson event histories."""
import math

import numpy as np
import pytest

from pipeline.hazard.constrain import log_survival_fixed

EVENTS_PER_YR = 2e-4                    # every event the same motion at the site
P_EACH = np.array([0.3, 0.5, 0.2])      # P(overturn) of each specimen in one event
AGES_YR = np.array([12_000.0, 5_000.0, 20_000.0])


def _any_rate(indices):
    return EVENTS_PER_YR * (1.0 - np.prod(1.0 - P_EACH[list(indices)]))


def site_set_survival(ages, any_rate):
    return math.exp(log_survival_fixed(lambda sets: [any_rate(m) for m in sets], ages))


def test_specimens_of_different_ages_against_simulated_histories():
    rng = np.random.default_rng(61)
    n = 200_000
    t_max = AGES_YR.max()
    events = rng.poisson(EVENTS_PER_YR * t_max, n)
    survived = np.ones(n, bool)
    for k in range(events.max()):
        has = events > k
        ago = rng.uniform(0.0, t_max, n)                 # when the event came, years ago
        met = AGES_YR[None, :] > ago[:, None]            # the specimens standing then
        fell = met & (rng.random((n, P_EACH.size)) < P_EACH[None, :])
        survived &= ~(has & fell.any(axis=1))
    estimate = survived.mean()
    error = math.sqrt(estimate * (1 - estimate) / n)
    assert site_set_survival(AGES_YR, _any_rate) == pytest.approx(estimate, abs=4 * error)


def test_equal_ages_are_one_rate_of_any_overturning():
    ages = np.full(3, 8_000.0)
    assert site_set_survival(ages, _any_rate) == pytest.approx(
        math.exp(-8_000.0 * _any_rate((0, 1, 2))), rel=1e-14)
    one = site_set_survival([8_000.0], lambda idx: EVENTS_PER_YR * P_EACH[0])
    assert one == pytest.approx(math.exp(-8_000.0 * EVENTS_PER_YR * 0.3), rel=1e-14)
