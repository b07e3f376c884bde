"""The likelihood against numbers computed by hand on a tiny forward table."""
import math

import numpy as np
import pytest
from scipy import optimize, special

from pipeline.inversion.table import ForwardTable
from pipeline.inversion.likelihood import ForwardModel
from pipeline.stats.circular import concentration
from pipeline.inversion.observations import ColumnObservation, Site

KERNEL, SIGMA, FLOOR = 20.0, 10.0, 0.05


def kappa_by_hand(sigma_deg):
    """Von Mises kappa with I1/I0 = exp(-sigma^2/2) (scipy.special.iv, brentq)."""
    target = math.exp(-math.radians(sigma_deg) ** 2 / 2)
    return optimize.brentq(lambda k: special.iv(1, k) / special.iv(0, k) - target, 1e-6, 500)


def vm(x_deg, kappa):
    return math.exp(kappa * math.cos(math.radians(x_deg))) / (2 * math.pi * special.iv(0, kappa))


@pytest.fixture
def tiny():
    """1 slice; rings 5 and 10 km; node azimuths 0, 90, 180, 270; 4 members.
    (5 km, 0):   drums fall toward 10 and 20 (strike frame), monolith stands (4x).
    (5 km, 270): drums: one falls toward 285, monolith stands.
    (10 km, *):  drums stand, monolith falls (4x) toward 0."""
    n = 4
    stand = [None] * n
    falls = [[[None] * 4 for _ in range(2)]]
    falls[0][0][0] = [[10.0, 20.0, None, None], stand]
    falls[0][0][1] = [stand, stand]
    falls[0][0][2] = [stand, stand]
    falls[0][0][3] = [[285.0, None, None, None], stand]
    for j in range(4):
        falls[0][1][j] = [stand, [0.0] * n]
    return ForwardTable.toy([("strike-slip", 90.0, 180.0, 10.0, 6.5)], (5.0, 10.0),
                            (0.0, 90.0, 180.0, 270.0), falls)


def site(*columns):
    return Site("A", 0.0, 0.0, tuple(columns))


DRUMS_15 = ColumnObservation("drums", "fallen", 15.0, SIGMA)
MONO_STANDS = ColumnObservation("monolithic", "standing")


def density_node0(psi):
    kappa = kappa_by_hand(math.hypot(KERNEL, SIGMA))
    return (1 - FLOOR) * 0.5 * (vm(psi - 10, kappa) + vm(psi - 20, kappa)) \
        + FLOOR / (2 * math.pi)


def test_concentration_matches_bessel_ratio():
    for sigma in (5.0, 10.0, 22.36, 60.0):
        assert concentration(sigma) == pytest.approx(kappa_by_hand(sigma), rel=1e-6)


def test_at_a_node(tiny):
    """Epicentre 5 km south of the site, strike 0: the site sits on node (5 km, 0)."""
    model = ForwardModel(tiny, KERNEL, FLOOR)
    ll = model.site_log_likelihood(site(DRUMS_15, MONO_STANDS), [0.0], [-5.0], [0.0])
    p_drums = (2 + 0.5) / (4 + 1)               # 0.5
    p_mono = (0 + 0.5) / (4 + 1)                # 0.1
    expected = math.log(p_drums * density_node0(15.0)) + math.log(1 - p_mono)
    assert ll.shape == (1, 1, 1)
    assert ll[0, 0, 0] == pytest.approx(expected, rel=1e-9)


def test_turned_strike_turns_the_observation_frame(tiny):
    """Strike 90 with the epicentre 5 km west: the site is at azimuth 90 = strike + 0, the
    same node; the observed fall turned by 90 deg gives the same likelihood."""
    model = ForwardModel(tiny, KERNEL, FLOOR)
    turned = ColumnObservation("drums", "fallen", 105.0, SIGMA)
    a = model.site_log_likelihood(site(DRUMS_15, MONO_STANDS), [0.0], [-5.0], [0.0])
    b = model.site_log_likelihood(site(turned, MONO_STANDS), [-5.0], [0.0], [90.0])
    assert b[0, 0, 0] == pytest.approx(a[0, 0, 0], rel=1e-12)


def test_between_rings_log_linear(tiny):
    """r = sqrt(5 x 10): half of each ring; ring 10 km: drums P = 0.1 with a uniform
    density, monolith P = 0.9."""
    model = ForwardModel(tiny, KERNEL, FLOOR)
    r = math.sqrt(50.0)
    ll = model.site_log_likelihood(site(DRUMS_15, MONO_STANDS), [0.0], [-r], [0.0])
    fallen = 0.5 * 0.5 * density_node0(15.0) + 0.5 * 0.1 / (2 * math.pi)
    standing = 0.5 * (1 - 0.1) + 0.5 * (1 - 0.9)
    assert ll[0, 0, 0] == pytest.approx(math.log(fallen) + math.log(standing), rel=1e-9)


def test_between_node_azimuths_spread_between_the_two_frames(tiny):
    """Strike 45, site due north of the epicentre: node azimuth 315, half way between the
    nodes 270 and 0 (45 deg from each).  Each node's fall density is read over the
    rotations between its site-frame reading and its strike-frame reading: the mean of
    d(psi + t delta), t in [0, 1], with delta = +45 deg for node 270 (its one fall, 285,
    lies 15 deg clockwise of its site direction) and -45 deg for node 0; P halfway."""
    from scipy import integrate
    model = ForwardModel(tiny, KERNEL, FLOOR)
    ll = model.site_log_likelihood(site(DRUMS_15), [0.0], [-5.0], [45.0])
    kappa = kappa_by_hand(math.hypot(KERNEL, SIGMA))

    def d270(psi):
        return (1 - FLOOR) * vm(psi - 15.0, kappa) + FLOOR / (2 * math.pi)

    spread0 = integrate.quad(lambda t: density_node0(15.0 - 45.0 * t), 0, 1)[0]
    spread270 = integrate.quad(lambda t: d270(15.0 + 45.0 * t), 0, 1)[0]
    value = 0.5 * 0.5 * spread0 + 0.5 * (1.5 / 5) * spread270
    assert ll[0, 0, 0] == pytest.approx(math.log(value), rel=1e-4)
    # at the node itself nothing is spread (test_at_a_node); the spread widens the reading
    assert spread270 < d270(15.0)


def test_floor_keeps_an_odd_fall_finite(tiny):
    """A fall opposite to every ensemble fall costs a bounded amount, never -inf."""
    model = ForwardModel(tiny, KERNEL, FLOOR)
    odd = ColumnObservation("drums", "fallen", 195.0, SIGMA)
    ll = model.site_log_likelihood(site(odd), [0.0], [-5.0], [0.0])
    assert np.isfinite(ll).all()
    assert ll[0, 0, 0] >= math.log(0.5 * FLOOR / (2 * math.pi)) - 1e-12


def test_distances_beyond_the_table_are_clamped(tiny):
    model = ForwardModel(tiny, KERNEL, FLOOR)
    near = model.site_log_likelihood(site(MONO_STANDS), [0.0], [-1.0], [0.0])
    at5 = model.site_log_likelihood(site(MONO_STANDS), [0.0], [-5.0], [0.0])
    far = model.site_log_likelihood(site(MONO_STANDS), [0.0], [-40.0], [0.0])
    at10 = model.site_log_likelihood(site(MONO_STANDS), [0.0], [-10.0], [0.0])
    assert near[0, 0, 0] == pytest.approx(at5[0, 0, 0])
    assert far[0, 0, 0] == pytest.approx(at10[0, 0, 0])


def test_unmodelled_column_is_one_line(tiny):
    from pipeline.files import InputError
    model = ForwardModel(tiny)
    with pytest.raises(InputError, match="models drums, monolithic only"):
        model.site_log_likelihood(site(ColumnObservation("ionic.json", "standing")),
                                  [0.0], [-5.0], [0.0])


def test_predictive_polya_urn_by_hand(tiny):
    """Two drums fell (15, then 25 deg) and one stands, at node (5 km, 0): n = 4 members,
    and 3 site columns: 1 / A = 1 / 5 + 1 / 3, A = 15 / 8.  First fall: as the independent
    product; second: the weight A plus a kernel about the first fall, over A + 1; the
    standing one: A (1 - P) over A + 2."""
    model = ForwardModel(tiny, KERNEL, FLOOR, likelihood="predictive", site_columns=3.0)
    second = ColumnObservation("drums", "fallen", 25.0, SIGMA)
    stands = ColumnObservation("drums", "standing")
    ll = model.site_log_likelihood(site(DRUMS_15, second, stands), [0.0], [-5.0], [0.0])
    a, p = 15.0 / 8.0, 0.5
    pair = (1 - FLOOR) * vm(10.0, kappa_by_hand(math.sqrt(KERNEL ** 2 + 2 * SIGMA ** 2))) \
        + FLOOR / (2 * math.pi)
    terms = [p * density_node0(15.0),
             (a * p * density_node0(25.0) + pair) / (a + 1),
             a * (1 - p) / (a + 2)]
    assert ll[0, 0, 0] == pytest.approx(sum(math.log(t) for t in terms), rel=1e-9)
    # the site's first fall makes a second one nearby more probable than the ensemble
    # alone says (P = 0.5 of a fall): the urn learns from the site's own columns
    falls = site(DRUMS_15, second)
    urn = model.site_log_likelihood(falls, [0.0], [-5.0], [0.0])
    independent = ForwardModel(tiny, KERNEL, FLOOR, "independent").site_log_likelihood(
        falls, [0.0], [-5.0], [0.0])
    assert urn[0, 0, 0] > independent[0, 0, 0]


def test_predictive_equals_independent_for_one_column_per_type(tiny):
    obs = site(DRUMS_15, MONO_STANDS)
    east, north, strikes = np.array([0.0, 3.0, -2.0]), np.array([-5.0, -1.0, 4.0]), [0, 45]
    a = ForwardModel(tiny, likelihood="predictive").site_log_likelihood(obs, east, north,
                                                                         strikes)
    b = ForwardModel(tiny, likelihood="independent").site_log_likelihood(obs, east, north,
                                                                          strikes)
    np.testing.assert_allclose(a, b, rtol=1e-12)
