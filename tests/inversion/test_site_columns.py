"""The predictive likelihood's site columns: a site whose columns are one column repeated
(fully correlated by construction) says what one column says, and its 95 % regions then
hold the truth about 95 % of the time, where the independent product's do not."""
import math

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import ColumnObservation, Observations, Site
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.posterior import invert
from pipeline.inversion.table import ForwardTable

RINGS = (2.5, 5.0, 10.0)
P_RING = (0.95, 0.5, 0.05)            # fall probability per ring (drums and monoliths)
MEMBERS = 200
GRID = CandidateGrid(radius_km=10.0, step_km=1.0, strike_step_deg=90.0)
ONE = 1e-9                            # site columns: the site's columns count as one


def flat_table():
    """Falls whose directions cover the circle evenly (the direction says nothing), the
    share of members falling P_RING per ring: only fallen/standing locates the source."""
    azimuths = tuple(np.arange(0.0, 360.0, 90.0))
    rings = []
    for p in P_RING:
        k = int(round(p * MEMBERS))
        column = [360.0 * i / k for i in range(k)] + [None] * (MEMBERS - k)
        rings.append([[column, column] for _ in azimuths])
    return ForwardTable.toy([("strike-slip", 90.0, 180.0, 10.0, 6.5)], RINGS, azimuths,
                            [rings])


def p_fall(r_km):
    """The table's (k + 1/2) / (n + 1), linear in log distance between rings (clamped)."""
    nodes = [(round(p * MEMBERS) + 0.5) / (MEMBERS + 1) for p in P_RING]
    return float(np.interp(math.log(r_km), np.log(RINGS), nodes))


def repeated(fallen, azimuth_deg, copies):
    obs = ColumnObservation("drums", "fallen", azimuth_deg, 10.0) if fallen else \
        ColumnObservation("drums", "standing")
    return Observations((Site("A", 0.0, 0.0, (obs,) * copies),), "synthetic")


def test_one_column_repeated_says_what_one_column_says():
    table = flat_table()
    for fallen in (True, False):
        single = invert(ForwardModel(table, likelihood="independent"), repeated(fallen, 40.0, 1), GRID)
        many = invert(ForwardModel(table, likelihood="predictive", site_columns=ONE),
                      repeated(fallen, 40.0, 30), GRID)
        assert np.allclose(many.epicentre, single.epicentre, atol=1e-9)
        sure = invert(ForwardModel(table, likelihood="independent"), repeated(fallen, 40.0, 30), GRID)
        assert not np.allclose(sure.epicentre, single.epicentre, atol=1e-3)


def coverage(model, trials, copies, seed):
    """Share of truths (drawn from the prior: a candidate cell at random) whose cell lies
    in the 95 % epicentre region, the site's one column drawn from the fall probability at
    the truth's distance and repeated ``copies`` times."""
    rng = np.random.default_rng(seed)
    east, north = GRID.lattice(repeated(False, 0.0, 1), RINGS[-1])
    hits = 0
    for _ in range(trials):
        k = int(rng.integers(east.size))
        fell = rng.uniform() < p_fall(math.hypot(east[k], north[k]))
        post = invert(model, repeated(fell, float(rng.uniform(0, 360)), copies), GRID)
        hits += post.contains(east[k], north[k], 0.95)
    return hits / trials


def test_correlated_columns_cover_with_site_columns_not_with_the_product():
    table = flat_table()
    calibrated = coverage(ForwardModel(table, likelihood="predictive", site_columns=ONE),
                          300, 30, 1)
    product = coverage(ForwardModel(table, likelihood="independent"), 300, 30, 1)
    assert 0.91 <= calibrated <= 0.99          # Bayes: E[mass of the 95 % region] ~ 0.95
    assert product < 0.85                      # 30 copies taken for 30 columns


def test_site_columns_must_be_positive():
    with pytest.raises(InputError, match="site columns"):
        ForwardModel(flat_table(), likelihood="predictive", site_columns=0.0)
