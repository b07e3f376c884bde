"""Rigid-block rocking reference against analytic results, symmetry and hand values."""
import math

import numpy as np
import pytest

from pipeline.rocking.decay import restitution_from_peaks
from pipeline.rocking.housner import (augusti_sinopoli_mu_min, block_constants, cylinder_constants,
                                      housner_closed_form, impact_friction_demand)
from pipeline.rocking.pulse import (MODE_NAMES, MODE_NO_OVERTURN, MODE_OVERTURN_WITHOUT_IMPACT,
                                    overturning_map, sine_pulse_response)
from pipeline.rocking.response import housner_free_rocking, rocking_response
from pipeline.files import InputError

G = 9.81
PAPER_H, PAPER_B = 3.113, 0.795          # Hinzen (2009) Fig. 5 block: alpha 0.25, p 2.14


def housner_half_periods(height, width, theta0_ratio, n, r=None, g=G):
    """Paper eq 7 (linearised block): duration (s) of half-cycles k = 0..n.

    T_k / 2 = (2 / p) artanh( sqrt(r^k (1 - (1 - theta0/alpha)^2)) ), the time
    the block needs to swing from theta = 0 out to amplitude theta_k and back.
    Released from rest at theta0, the first impact comes after T_0 / 4; impact
    k + 1 follows impact k after T_k / 2.  r defaults to Housner's eta^2.
    """
    c = block_constants(height, width, g)
    r = c["energy_ratio"] if r is None else r
    k = np.arange(n + 1)
    return 2.0 / c["p"] * np.arctanh(np.sqrt(r ** k * (1.0 - (1.0 - theta0_ratio) ** 2)))


def mode_edges(height, width, omega_ratio, amplitude_ratios, restitution=None, g=G,
               tol=1e-3):
    """Amplitude ratios (A / (alpha g)) where the one-sine-pulse mode changes.

    Scans ``amplitude_ratios`` (increasing) and bisects every change of mode to
    ``tol``.  Returns a list of dicts: lower (ratio just below the edge),
    upper (just above), mode_below, mode_above (names).
    """
    def mode_at(a):
        return sine_pulse_response(height, width, a, omega_ratio, restitution=restitution,
                                   g=g, dt_out=None)["mode"]

    amps = np.asarray(amplitude_ratios, float)
    modes = [mode_at(a) for a in amps]
    edges = []
    for k in range(len(amps) - 1):
        lo, hi, m_lo, m_hi = amps[k], amps[k + 1], modes[k], modes[k + 1]
        if m_lo == m_hi:
            continue
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            if mode_at(mid) == m_lo:
                lo = mid
            else:
                hi = mid
        edges.append(dict(lower=float(lo), upper=float(hi), mode_below=MODE_NAMES[m_lo],
                          mode_above=MODE_NAMES[mode_at(hi)]))
    return edges


def energy_per_mass(c, theta, omega):
    """(1/2) I0 omega^2 / m + g R cos(alpha - |theta|) (J/kg), rigid block about a corner."""
    return 0.5 * c["I0_per_mass"] * omega ** 2 + G * c["R"] * np.cos(c["alpha"] - np.abs(theta))


def test_paper_block_constants():
    c = block_constants(PAPER_H, PAPER_B)
    assert c["alpha"] == pytest.approx(0.25, abs=1e-3)
    assert c["p"] == pytest.approx(2.14, abs=2e-3)
    assert c["uplift_acc"] == pytest.approx(G * PAPER_B / PAPER_H)
    # Housner: eta = 1 - 1.5 sin^2(alpha) = 1 - 1.5 b^2 / (b^2 + h^2)
    assert c["restitution"] == pytest.approx(1 - 1.5 * PAPER_B ** 2 / (PAPER_B ** 2 + PAPER_H ** 2))
    assert c["energy_ratio"] == pytest.approx(c["restitution"] ** 2)


def test_energy_conserved_between_impacts_and_reduced_by_eta_squared():
    c = block_constants(PAPER_H, PAPER_B)
    eta = 0.8
    out = housner_free_rocking(PAPER_H, PAPER_B, 0.7 * c["alpha"], n_impacts=4,
                                  restitution=eta, dt_out=0.002)
    t, e = out["t"], energy_per_mass(c, out["theta"], out["omega"])
    bounds = np.concatenate([[0.0], out["impact_times"], [np.inf]])
    for k in range(len(bounds) - 1):
        inside = (t > bounds[k]) & (t < bounds[k + 1])
        assert inside.sum() > 50
        assert np.ptp(e[inside]) < 1e-7 * G * c["R"]
    potential_upright = G * c["R"] * math.cos(c["alpha"])
    kinetic_before = 0.5 * c["I0_per_mass"] * out["impact_omega_before"] ** 2
    kinetic_after = 0.5 * c["I0_per_mass"] * out["impact_omega_after"] ** 2
    np.testing.assert_allclose(kinetic_after / kinetic_before, eta ** 2, rtol=1e-12)
    # kinetic energy at impact = potential drop from the previous peak (exact rigid block)
    peaks = np.abs(out["peak_theta"][:-1])
    drop = G * c["R"] * np.cos(c["alpha"] - peaks) - potential_upright
    np.testing.assert_allclose(kinetic_before, drop, rtol=1e-7)


def test_elastic_rocking_keeps_its_amplitude():
    c = block_constants(PAPER_H, PAPER_B)
    out = housner_free_rocking(PAPER_H, PAPER_B, -0.4 * c["alpha"], n_impacts=6,
                                  restitution=1.0)
    np.testing.assert_allclose(np.abs(out["peak_theta"]), 0.4 * c["alpha"], rtol=1e-7)
    assert np.all(np.sign(out["peak_theta"]) == (-1) ** (np.arange(7) + 1))
    half_cycles = np.diff(out["impact_times"])
    np.testing.assert_allclose(half_cycles, 2 * out["impact_times"][0], rtol=1e-7)


def test_linearised_quarter_period_is_cosh_solution():
    c = block_constants(PAPER_H, PAPER_B)
    alpha, p, theta0 = c["alpha"], c["p"], 0.3 * c["alpha"]
    out = housner_free_rocking(PAPER_H, PAPER_B, theta0, n_impacts=1, linearised=True)
    t1 = math.acosh(alpha / (alpha - theta0)) / p
    assert out["impact_times"][0] == pytest.approx(t1, rel=1e-9)
    before = out["t"] < t1
    np.testing.assert_allclose(out["theta"][before],
                               alpha - (alpha - theta0) * np.cosh(p * out["t"][before]),
                               atol=1e-9)
    np.testing.assert_allclose(out["omega"][before],
                               -(alpha - theta0) * p * np.sinh(p * out["t"][before]), atol=1e-8)


def test_slender_block_small_tilt_follows_linearised_solution():
    height, width = 10.0, 0.5                 # alpha ~ 0.05 rad: sin(x) ~ x within 0.1 %
    c = block_constants(height, width)
    p, theta0 = c["p"], 0.5 * c["alpha"]
    out = housner_free_rocking(height, width, theta0, n_impacts=1)
    assert out["impact_times"][0] == pytest.approx(math.acosh(2.0) / p, rel=2e-3)


def test_closed_form_eq6_eq7_match_linearised_integration():
    c = block_constants(PAPER_H, PAPER_B)
    for ratio in (0.2, 0.5, 0.9):
        out = housner_free_rocking(PAPER_H, PAPER_B, ratio * c["alpha"], n_impacts=8,
                                      linearised=True)
        amplitudes = housner_closed_form(ratio, c["energy_ratio"], 8)
        np.testing.assert_allclose(out["peak_ratio"], amplitudes, rtol=1e-7)
        half = housner_half_periods(PAPER_H, PAPER_B, ratio, 8)
        expected_impacts = half[0] / 2 + np.concatenate([[0.0], np.cumsum(half[1:8])])
        np.testing.assert_allclose(out["impact_times"], expected_impacts, rtol=1e-7)


def test_closed_form_limits():
    # no loss: amplitude kept; released at the top (theta0 = alpha): stays there
    np.testing.assert_allclose(housner_closed_form(0.4, 1.0, 5), 0.4)
    np.testing.assert_allclose(housner_closed_form(1.0, 0.8, 3), [1, 1 - math.sqrt(0.2),
                                                                     1 - math.sqrt(0.36),
                                                                     1 - math.sqrt(1 - 0.512)])


def test_nonlinear_paper_block_impact_times_match_shared_notes():
    c = block_constants(PAPER_H, PAPER_B)
    out = housner_free_rocking(PAPER_H, PAPER_B, 0.5 * c["alpha"], n_impacts=4)
    np.testing.assert_allclose(out["impact_times"], [0.6165, 1.6123, 2.4528, 3.1785], atol=1e-3)


def test_nonlinear_peaks_follow_exact_energy_recurrence_and_give_back_eta():
    c = block_constants(PAPER_H, PAPER_B)
    out = housner_free_rocking(PAPER_H, PAPER_B, 0.8 * c["alpha"], n_impacts=5)
    peaks = np.abs(out["peak_theta"])
    # cos(alpha - theta_{k+1}) - cos(alpha) = eta^2 (cos(alpha - theta_k) - cos(alpha))
    lhs = np.cos(c["alpha"] - peaks[1:]) - math.cos(c["alpha"])
    rhs = c["energy_ratio"] * (np.cos(c["alpha"] - peaks[:-1]) - math.cos(c["alpha"]))
    np.testing.assert_allclose(lhs, rhs, rtol=1e-7)
    est = restitution_from_peaks(peaks, c["alpha"])
    assert est["eta"] == pytest.approx(c["restitution"], rel=1e-7)
    np.testing.assert_allclose(est["eta_per_impact"], c["restitution"], rtol=1e-7)


def test_free_release_beyond_alpha_overturns_that_way():
    c = block_constants(PAPER_H, PAPER_B)
    out = housner_free_rocking(PAPER_H, PAPER_B, -1.01 * c["alpha"], n_impacts=3)
    assert out["overturned"] and out["impact_times"].size == 0


def test_no_uplift_below_g_tan_alpha_and_uplift_above():
    c = block_constants(PAPER_H, PAPER_B)
    below = rocking_response(PAPER_H, PAPER_B,
                                lambda t: 0.99 * c["uplift_acc"] * math.sin(7.0 * t), 3.0)
    assert below["uplift_times"].size == 0
    assert np.all(below["theta"] == 0) and below["max_abs_theta"] == 0
    above = rocking_response(PAPER_H, PAPER_B,
                                lambda t: 1.05 * c["uplift_acc"] * math.sin(7.0 * t), 3.0)
    # first uplift when sin(7 t) = 1 / 1.05, onto the West corner (East push)
    assert above["uplift_times"][0] == pytest.approx(math.asin(1 / 1.05) / 7.0, abs=1e-6)
    assert above["first_side"] == -1 and above["max_abs_theta"] > 0


def test_east_push_rocks_block_onto_west_corner():
    c = block_constants(PAPER_H, PAPER_B)
    out = rocking_response(PAPER_H, PAPER_B, lambda t: 2.0 * c["uplift_acc"] * (t < 0.2),
                              1.0, still_after=0.2)
    first_moves = out["theta"][out["theta"] != 0][:10]
    assert np.all(first_moves < 0)


def test_mirror_symmetry():
    c = block_constants(PAPER_H, PAPER_B)

    def acc(t):
        return 1.6 * c["uplift_acc"] * math.sin(2 * math.pi * 0.9 * t) * math.exp(-0.3 * t)

    out = rocking_response(PAPER_H, PAPER_B, acc, 6.0)
    mirror = rocking_response(PAPER_H, PAPER_B, lambda t: -acc(t), 6.0)
    assert out["uplift_times"].size and out["n_impacts"] > 0
    np.testing.assert_array_equal(out["t"], mirror["t"])
    np.testing.assert_allclose(mirror["theta"], -out["theta"], atol=1e-12)
    np.testing.assert_allclose(mirror["impact_times"], out["impact_times"])
    assert mirror["overturn_direction"] == -out["overturn_direction"]
    assert mirror["first_side"] == -out["first_side"]


def test_sine_pulse_three_modes_in_paper_order():
    # Hinzen (2009) Fig. 5 / Zhang & Makris (2000): omega = 5 p, eta = 0.9.  Rising
    # amplitude: overturning after one impact (towards +x, away from the first
    # push), a safe band, overturning without impact (towards -x, the first push).
    modes = {}
    for ratio in (6.0, 7.0, 8.0):
        modes[ratio] = sine_pulse_response(PAPER_H, PAPER_B, ratio, 5.0, restitution=0.9)
    assert modes[6.0]["mode_name"] == "overturn_after_impact"
    assert modes[6.0]["n_impacts"] == 1 and modes[6.0]["overturn_direction"] == 1
    assert modes[6.0]["relative_direction"] == -1
    assert modes[7.0]["mode_name"] == "no_overturn" and not modes[7.0]["overturned"]
    assert modes[8.0]["mode_name"] == "overturn_without_impact"
    assert modes[8.0]["overturn_direction"] == -1 and modes[8.0]["relative_direction"] == 1


def test_sine_pulse_mode_edges_near_shared_notes():
    edges = mode_edges(PAPER_H, PAPER_B, 5.0, [6.0, 7.0, 8.0], restitution=0.9, tol=0.01)
    assert [(e["mode_below"], e["mode_above"]) for e in edges] == [
        ("overturn_after_impact", "no_overturn"), ("no_overturn", "overturn_without_impact")]
    # shared notes (independent rigid integration, confirmed by YADE): ~6.76 and ~7.5
    assert edges[0]["lower"] == pytest.approx(6.76, abs=0.05)
    assert edges[1]["lower"] == pytest.approx(7.5, abs=0.05)


def test_sine_pulse_below_uplift_does_nothing():
    c = block_constants(PAPER_H, PAPER_B)
    ratio = 0.95 * math.tan(c["alpha"]) / c["alpha"]
    out = sine_pulse_response(PAPER_H, PAPER_B, ratio, 5.0)
    assert out["mode_name"] == "no_overturn" and out["uplift_times"].size == 0


def test_overturning_map_matches_single_runs():
    amps, omegas = [1.05, 6.0, 8.0], [3.0, 5.0]
    grid = overturning_map(PAPER_H, PAPER_B, amps, omegas, restitution=0.9)
    assert grid["mode"].shape == (2, 3)
    for i, w in enumerate(omegas):
        for j, a in enumerate(amps):
            single = sine_pulse_response(PAPER_H, PAPER_B, a, w, restitution=0.9)
            assert grid["mode"][i, j] == single["mode"]
    # a pulse barely above uplift (tan(alpha) / alpha = 1.02) cannot topple the block
    assert grid["mode"][0, 0] == MODE_NO_OVERTURN
    assert grid["mode"][1, 2] == MODE_OVERTURN_WITHOUT_IMPACT


def test_augusti_sinopoli_criterion_hand_value():
    # h/b = 5 (the paper's marble block): 3 * 0.2 / (4 + 0.04) = 0.148515
    assert augusti_sinopoli_mu_min(0.08, 0.40) == pytest.approx(0.6 / 4.04, rel=1e-12)
    assert augusti_sinopoli_mu_min(0.08, 0.40) == pytest.approx(0.148515, abs=1e-6)


def test_housner_impact_impulse_ratio_equals_eq8():
    for height, width in ((0.40, 0.08), (PAPER_H, PAPER_B), (2.0, 1.0)):
        assert impact_friction_demand(width, height) == pytest.approx(
            augusti_sinopoli_mu_min(width, height), rel=1e-12)
    # a lossier impact needs more friction
    assert impact_friction_demand(0.08, 0.40, 0.88) > 0.3


def test_bad_input_raises():
    with pytest.raises(InputError):
        block_constants(-1.0, 0.5)
    with pytest.raises(InputError):
        housner_free_rocking(PAPER_H, PAPER_B, 0.0)
    with pytest.raises(InputError):
        housner_free_rocking(PAPER_H, PAPER_B, 0.1, restitution=1.5)
    with pytest.raises(InputError):
        restitution_from_peaks([0.3, 0.2], alpha=0.25)


def test_cylinder_constants_from_its_mass_properties_and_an_impact_balance():
    """The cylinder's I0 from the solid's own closed forms (parallel axes), and its
    restitution from angular momentum about the new pivot written out as vectors."""
    from pipeline.scenario.solids import Frustum
    h, d = 3.5, 3.5 / 6
    c = cylinder_constants(h, d)
    m, zc, (ixx, _, _) = Frustum(h, d, d).mass_properties(1.0)
    R = math.hypot(zc, d / 2)
    assert c["R"] == pytest.approx(R) and c["alpha"] == pytest.approx(math.atan(d / h))
    assert c["I0_per_mass"] == pytest.approx((ixx + m * R ** 2) / m)
    assert c["p"] == pytest.approx(math.sqrt(G * R * m / (ixx + m * R ** 2)))
    # at theta = 0 rocking about A = (+r, 0) with omega about North (y): the centre of mass
    # G = (0, zc) moves with v = omega x (G - A); after the impact about B = (-r, 0),
    # H_B = I_G omega + m (G - B) x v is kept
    omega = 1.0
    g_minus_a = np.array([-d / 2, 0.0, zc])
    v = np.cross([0.0, omega, 0.0], g_minus_a)
    h_b = ixx * omega + m * np.cross(np.array([d / 2, 0.0, zc]), v)[1]
    assert c["restitution"] == pytest.approx(h_b / (ixx + m * R ** 2))
    # the block's constants through the same balance (its I_G = m (b^2 + h^2) / 12)
    b = block_constants(h, d)
    i_block = (d ** 2 + h ** 2) / 12
    h_block = i_block + np.cross([d / 2, 0.0, h / 2], np.cross([0, 1.0, 0],
                                                                [-d / 2, 0, h / 2]))[1]
    assert b["restitution"] == pytest.approx(h_block / b["I0_per_mass"])


def test_cylinder_free_rocking_keeps_its_energy_between_impacts():
    h, d = 3.5, 3.5 / 6
    c = cylinder_constants(h, d)
    out = housner_free_rocking(h, d, 0.5 * c["alpha"], n_impacts=3, shape="cylinder")
    before = out["t"] < out["impact_times"][0]
    energy = energy_per_mass(c, out["theta"][before], out["omega"][before])
    assert np.ptp(energy) < 1e-8 * G * c["R"]
    assert out["impact_omega_after"][0] == pytest.approx(
        c["restitution"] * out["impact_omega_before"][0])
    with pytest.raises(InputError, match="shape"):
        housner_free_rocking(h, d, 0.1, shape="sphere")
