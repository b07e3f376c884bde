"""The shell's likelihood marginalised over the decay beyond the last ring: against the
closed form of a uniform slope of log-odds P in ln r, and a sample falling faster beyond
the last ring than the last two rings' slight decay says.

Toy tables of tests/inversion/test_reach.py: every fallen column falls away from the
source; the share that falls is set per ring."""
import math

import numpy as np
import pytest
from scipy.special import expit, logit, softplus

from pipeline.inversion.beyond import SHELL_FACTOR, shell_log_likelihood
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import parse_observations
from pipeline.inversion.posterior import invert
from pipeline.inversion.table import ForwardTable
from tests.inversion.test_reach import RINGS, hidden_source

MEMBERS = 8
P5, P10 = 8.5 / 9, 6.5 / 9           # (k + 1/2) / (n + 1): 8 and 6 of 8 members fall
P_NONE = 0.5 / 9                     # none of 8 falls


def standing_site(standing):
    """One site (the frame's origin) with ``standing`` standing columns."""
    return parse_observations({"sites": [{"name": "A", "east_km": 0.0, "north_km": 0.0,
                                          "columns": [{"column": "drums",
                                                       "state": "standing"}] * standing}]})


def slope_bounds():
    """(the last two rings' log-odds slope in ln r, the slope leaving P_NONE at the shell's
    outer edge), per ln r."""
    return ((logit(P10) - logit(P5)) / math.log(2.0),
            (logit(P_NONE) - logit(P10)) / math.log(SHELL_FACTOR))


@pytest.fixture
def model(make_away_table):
    table = make_away_table(members=MEMBERS, p_fall=[1.0, 1.0, 0.75], distances=RINGS)
    return ForwardModel(table, likelihood="independent")


def test_one_standing_column_beyond_the_reach_stands_with_one_less_the_mean_p(model):
    """Slope s uniform on [s_fast, s_slow]: E[P(r)] = (softplus(l + s_s x) -
    softplus(l + s_f x)) / (x (s_s - s_f)), l = logit P(10 km), x = ln(r / 10 km)."""
    slow, fast = slope_bounds()
    for r in (12.0, 15.0, 19.0):
        x, lo = math.log(r / 10.0), logit(P10)
        mean_p = (softplus(lo + slow * x) - softplus(lo + fast * x)) / (x * (slow - fast))
        ll = shell_log_likelihood(model, standing_site(1), np.zeros(1), np.array([-r]),
                                  np.array([0.0]))
        assert np.exp(ll) == pytest.approx(np.full(ll.shape, 1.0 - mean_p), rel=1e-5)


def test_one_slope_holds_for_every_column_of_a_source(model):
    """Two standing columns: E[(1 - P)^2], not (1 - E[P])^2: the slope is the source's.
    With z = l + s x, the integral of expit(-z)^2 dz is z - softplus(z) - expit(z)."""
    slow, fast = slope_bounds()
    x, lo = math.log(1.5), logit(P10)

    def integral(z):
        return z - softplus(z) - expit(z)
    both = (integral(lo + slow * x) - integral(lo + fast * x)) / (x * (slow - fast))
    one = (softplus(lo + slow * x) - softplus(lo + fast * x)) / (x * (slow - fast))
    ll = shell_log_likelihood(model, standing_site(2), np.zeros(1), np.array([-15.0]),
                              np.array([0.0]))
    assert np.exp(ll) == pytest.approx(np.full(ll.shape, both), rel=1e-5)
    assert both > (1.0 - one) ** 2 * 1.01         # the two differ here


# ------------------------------------------------ a decay steeper than the table's last
SATURATED = {6.0: (1.0, 0.5, 0.25), 7.0: (1.0, 1.0, 0.875)}   # share falling per ring


def saturated_table(members=16, seed=0):
    """Mw 6: a share 2.5 km / r falls; Mw 7: every column falls at 2.5 and 5 km and 7 of 8
    at 10 km, a slight decay between the last two rings (P 0.97 to 0.85).  Directions at
    random: only the counts speak."""
    rng = np.random.default_rng(seed)
    slices = [("strike-slip", 90.0, 180.0, 10.0, mw) for mw in SATURATED]
    azimuths = tuple(np.arange(0.0, 360.0, 30.0))
    falls = [[[[[float(rng.uniform(0.0, 360.0)) if k < round(members * share[i]) else None
                 for k in range(members)] for _ in range(2)] for _ in azimuths]
              for i, _ in enumerate(RINGS)] for share in SATURATED.values()]
    return ForwardTable.toy(slices, RINGS, azimuths, falls)


def test_falls_fewer_than_the_slight_decay_says_leave_the_source_beyond_probable():
    """An Mw 7 beyond the reach whose falls drop from 9 of 12 at 11 km to 1 of 12 at 19 km
    (log-odds slope -7 in ln r, the table's last two rings -2.5): the shell's likelihood
    with the slope unknown takes the source beyond as the likelier (P(beyond) above 1/2),
    where the last two rings' slope alone leaves it below (0.4: the independent product,
    in which every column counts, as the shell's decay matters most)."""
    sites = {"A": (0.0, 11.0), "B": (4.0, 15.0), "C": (0.0, 19.0)}
    observations = hidden_source((0.0, 0.0), sites, share=lambda r: float(
        expit(logit(14.5 / 17) - 7.0 * math.log(r / 10.0))))
    assert [sum(c.fallen for c in s.columns) for s in observations.sites] == [9, 3, 1]
    post = invert(ForwardModel(saturated_table(), likelihood="independent"), observations,
                  CandidateGrid(radius_km=30, step_km=1))
    summary = post.summary()
    assert summary["p_beyond"] > 0.5 and summary["beyond_in_95"]
    assert summary["distance_ci95_unbounded"] and summary["magnitude_ci95_open_above"]
