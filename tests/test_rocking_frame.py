"""The rigid rocking frame (columns under a beam, Makris & Vassiliou 2013) against its own
kinematics written out body by body, a Newton-Euler impulse balance of columns and beam,
the single block (gamma 0, and the enlarged block of the same p), conservation and symmetry."""
import math

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.rocking.frame import (RockingFrame, makris_vassiliou_p,
                                    makris_vassiliou_restitution)
from pipeline.rocking.housner import RockingBody, block_constants, cylinder_constants
from pipeline.rocking.pulse import body_sine_pulse_response, sine_pulse
from pipeline.rocking.response import body_response, free_rocking

G = 9.81
H, B = 3.113, 0.795                  # Hinzen (2009) Fig. 5 block: alpha 0.25, p 2.14
GAMMAS = (0.0, 0.3, 1.0, 4.0)


def _rotate_cw(point, pivot, theta):
    """``point`` (x East, z up) turned clockwise (leaning East) by theta about ``pivot``."""
    dx, dz = point[0] - pivot[0], point[1] - pivot[1]
    c, s = math.cos(theta), math.sin(theta)
    return np.array([pivot[0] + dx * c + dz * s, pivot[1] - dx * s + dz * c])


def _frame_positions(theta, n, h, b):
    """Centres of mass of n columns (2b wide, 2h high, base centres 3 widths apart, each
    leaning East about its East corner) and the height and x of the beam, which rides on
    the highest top corner of the columns."""
    cols, tops = [], []
    for i in range(n):
        x0 = 6 * b * i
        pivot = (x0 + b, 0.0)
        cols.append(_rotate_cw((x0, h), pivot, theta))
        corners = [_rotate_cw((x0 + sx, 2 * h), pivot, theta) for sx in (-b, b)]
        tops.append(max(corners, key=lambda c: c[1]))
    tops = np.array(tops)
    assert np.ptp(tops[:, 1]) < 1e-12            # the beam stays level
    return np.array(cols), tops[0]


def _lagrange_acc(theta, a_g, gamma, n=3, h=H / 2, b=B / 2, d=1e-6):
    """theta'' of the frame (rad/s^2) from its positions: M theta'' = -dV/dtheta + Q, per
    unit total column mass, by central differences (M is constant in theta)."""
    m, m_b = 1.0 / n, gamma                   # columns of total mass 1, beam gamma
    i_g = m * (h ** 2 + b ** 2) / 3.0         # (2b x 2h rectangle) about its centre
    c0, t0 = _frame_positions(theta - d, n, h, b)
    c1, t1 = _frame_positions(theta + d, n, h, b)
    dc, dt_ = (c1 - c0) / (2 * d), (t1 - t0) / (2 * d)
    mass_matrix = m * (dc ** 2).sum() + n * i_g + m_b * (dt_ ** 2).sum()
    dv = G * (m * dc[:, 1].sum() + m_b * dt_[1])
    q = -a_g * (m * dc[:, 0].sum() + m_b * dt_[0])
    return (q - dv) / mass_matrix


@pytest.mark.parametrize("gamma", GAMMAS)
def test_equation_of_motion_from_the_frames_kinematics(gamma):
    frame = RockingFrame(H, B, gamma)
    body = frame.body()
    for theta in (0.02, 0.1, 0.2, 0.3):
        for a_g in (0.0, 1.3, -2.0):
            housner = -body.p ** 2 * (math.sin(body.alpha - theta)
                                      + a_g / G * math.cos(body.alpha - theta))
            assert _lagrange_acc(theta, a_g, gamma) == pytest.approx(housner, rel=1e-6,
                                                                      abs=1e-9)


def test_closed_forms_are_the_papers_for_blocks_and_the_single_column_at_gamma_zero():
    c = block_constants(H, B)
    for gamma in GAMMAS:
        frame = RockingFrame(H, B, gamma)
        assert frame.p == pytest.approx(makris_vassiliou_p(c["p"], gamma), rel=1e-12)
        assert frame.p ** 2 == pytest.approx(3 * G / (4 * c["R"]) * (1 + 2 * gamma)
                                             / (1 + 3 * gamma), rel=1e-12)
        assert frame.restitution == pytest.approx(
            makris_vassiliou_restitution(c["alpha"], gamma), rel=1e-12)
        assert frame.size_factor == pytest.approx((1 + 3 * gamma) / (1 + 2 * gamma))
        assert frame.uplift_acc == pytest.approx(G * B / H)
    for shape, constants in (("block", block_constants), ("cylinder", cylinder_constants)):
        single = constants(H, B)
        body = RockingFrame(H, B, 0.0, shape).body()
        assert (body.alpha, body.p, body.restitution) == pytest.approx(
            (single["alpha"], single["p"], single["restitution"]), rel=1e-14)
    # a heavy beam: p -> p sqrt(2/3), eta -> cos 2 alpha
    heavy = RockingFrame(H, B, 1e3)
    assert heavy.p == pytest.approx(c["p"] * math.sqrt(2 / 3), rel=1e-3)
    assert heavy.restitution == pytest.approx(math.cos(2 * c["alpha"]), abs=1e-3)
    assert RockingFrame.of_masses(H, B, 4, 1000.0, 2000.0).gamma == 0.5


def _impact(n, gamma, h=H / 2, b=B / 2, omega=1.0):
    """Velocities after the impact of a frame of n columns, from Newton-Euler with
    impulses at the new pivots (West base corners) and the new beam contacts (East top
    corners); before it every column turns at ``omega`` (counter-clockwise) about its East
    base corner and the beam rides on the West top corners.  Returns the columns' and the
    beam's angular velocities after the impact."""
    m, m_b = 1.0 / n, gamma
    i_g, i_b = m * (h ** 2 + b ** 2) / 3.0, m_b * (6 * b * n) ** 2 / 12.0
    gb = np.array([6 * b * (n - 1) / 2, 2 * h + 0.3])
    nv, ni = 3 * n + 3, 4 * n                     # velocities (u, w, Omega) and impulses
    a, rhs, row = np.zeros((nv + ni, nv + ni)), np.zeros(nv + ni), 0

    def cross_row(r):                             # Omega x r in the plane: (-r_z, r_x)
        return np.array([-r[1], r[0]])

    beam_v = omega * cross_row(np.array([-2 * b, 2 * h]))     # West top corner about A
    for i in range(n):
        g = np.array([6 * b * i, h])
        new_pivot, contact = np.array([6 * b * i - b, 0.0]), np.array([6 * b * i + b, 2 * h])
        v_before = omega * cross_row(g - np.array([6 * b * i + b, 0.0]))
        col, p_idx, q_idx = 3 * i, nv + 4 * i, nv + 4 * i + 2
        for k in range(2):                        # m (v - v-) = P - Q
            a[row, col + k] = m
            a[row, p_idx + k], a[row, q_idx + k] = -1.0, 1.0
            rhs[row] = m * v_before[k]
            row += 1
        a[row, col + 2] = i_g                     # I_G (Omega - omega) = r_P x P - r_Q x Q
        rp, rq = new_pivot - g, contact - g
        a[row, p_idx:p_idx + 2] = [rp[1], -rp[0]]
        a[row, q_idx:q_idx + 2] = [-rq[1], rq[0]]
        rhs[row] = i_g * omega
        row += 1
        for k in range(2):                        # the new pivot does not move
            a[row, col + k] = 1.0
            a[row, col + 2] = cross_row(rp)[k]
            row += 1
        rb = contact - gb
        for k in range(2):                        # beam and column move together there
            a[row, 3 * n + k], a[row, 3 * n + 2] = 1.0, cross_row(rb)[k]
            a[row, col + k], a[row, col + 2] = -1.0, -cross_row(rq)[k]
            row += 1
    for k in range(2):                            # m_b (V - V-) = sum Q
        a[row, 3 * n + k] = m_b
        for i in range(n):
            a[row, nv + 4 * i + 2 + k] = -1.0
        rhs[row] = m_b * beam_v[k]
        row += 1
    a[row, 3 * n + 2] = i_b                       # I_b Omega_b = sum r x Q
    for i in range(n):
        rb = np.array([6 * b * i + b, 2 * h]) - gb
        a[row, nv + 4 * i + 2:nv + 4 * i + 4] = [-rb[1], rb[0]]
    row += 1
    assert row == nv + ni
    z = np.linalg.lstsq(a, rhs, rcond=None)[0]
    np.testing.assert_allclose(a @ z, rhs, atol=1e-10)        # consistent
    return z[2:3 * n:3], z[3 * n + 2]


@pytest.mark.parametrize("n", (2, 3, 4))
def test_restitution_from_a_newton_euler_impulse_balance(n):
    for gamma in GAMMAS[1:]:
        omegas, beam_omega = _impact(n, gamma)
        eta = RockingFrame(H, B, gamma).restitution
        np.testing.assert_allclose(omegas, eta, rtol=1e-9)
        assert beam_omega == pytest.approx(0.0, abs=1e-9)


def test_energy_conserved_between_impacts_and_reduced_by_eta_squared():
    frame = RockingFrame(H, B, 1.5)
    out = free_rocking(frame.body(), 0.6 * frame.alpha, n_impacts=4, dt_out=0.002)
    e = frame.energy_per_column_mass(out["theta"], out["omega"])
    bounds = np.concatenate([[0.0], out["impact_times"], [np.inf]])
    scale = G * frame.column["R"]
    for k in range(len(bounds) - 1):
        inside = (out["t"] > bounds[k]) & (out["t"] < bounds[k + 1])
        assert inside.sum() > 50
        assert np.ptp(e[inside]) < 1e-7 * scale
    ratio = (out["impact_omega_after"] / out["impact_omega_before"]) ** 2
    np.testing.assert_allclose(ratio, frame.restitution ** 2, rtol=1e-12)


@pytest.mark.parametrize("gamma", GAMMAS)
def test_uplift_at_g_tan_alpha_whatever_the_beam(gamma):
    frame = RockingFrame(H, B, gamma)
    # the static threshold from the kinematics: the ground acceleration (West, < 0) at
    # which theta'' just off theta = 0 (leaning East) vanishes
    still, pushed = _lagrange_acc(1e-5, 0.0, gamma), _lagrange_acc(1e-5, 1.0, gamma)
    assert -still / (pushed - still) == pytest.approx(-G * B / H, rel=1e-4)
    body = frame.body()
    for factor, lifts in ((0.99, False), (1.01, True)):
        out = body_response(body, lambda t, f=factor: f * G * B / H * min(1.0, t), 2.0,
                            dt_out=None)
        assert (out["uplift_times"].size > 0) == lifts


def test_reversed_pulse_mirrors_the_frame():
    body = RockingFrame(H, B, 2.0).body()

    def acc(t):
        return 2.5 * body.uplift_acc * math.sin(2 * math.pi * 0.8 * t) * math.exp(-0.4 * t)

    out = body_response(body, acc, 8.0)
    mirror = body_response(body, lambda t: -acc(t), 8.0)
    assert out["n_impacts"] > 0
    np.testing.assert_array_equal(out["t"], mirror["t"])
    np.testing.assert_allclose(mirror["theta"], -out["theta"], atol=1e-12)
    assert mirror["first_side"] == -out["first_side"]


def test_frame_is_the_single_column_enlarged_to_its_p():
    """Under one physical pulse the frame rocks as the single column of the same alpha
    enlarged by (1 + 3 gamma) / (1 + 2 gamma), given the frame's restitution."""
    frame = RockingFrame(H, B, 1.0)
    k = frame.size_factor
    enlarged = RockingBody.of_shape(k * H, k * B, restitution=frame.restitution)
    assert enlarged.p == pytest.approx(frame.p, rel=1e-12)
    acc, t_pulse = sine_pulse(2.0 * G * B / H, 2 * math.pi / 0.8, 0.3)
    a = body_response(frame.body(), acc, t_pulse + 6.0, dt_out=0.01)
    b = body_response(enlarged, acc, t_pulse + 6.0, dt_out=0.01)
    assert a["n_impacts"] > 1 and a["n_impacts"] == b["n_impacts"]
    np.testing.assert_allclose(a["theta"], b["theta"], atol=1e-7 * frame.alpha)


def _min_overturning_ratio(body, omega, lo=1.0, hi=12.0, tol=1e-3):
    """Smallest A / (alpha g) of a one-sine pulse of ``omega`` (rad/s) that overturns
    ``body``: a scan by 2 %, then bisection of the first change."""
    def over(ratio):
        return body_sine_pulse_response(body, ratio, omega / body.p, dt_out=None)["overturned"]
    grid = lo * 1.02 ** np.arange(int(math.log(hi / lo) / math.log(1.02)) + 1)
    first = next(i for i, r in enumerate(grid) if over(r))
    a, b = grid[first - 1], grid[first]
    while b - a > tol * b:
        mid = 0.5 * (a + b)
        a, b = (a, mid) if over(mid) else (mid, b)
    return b


def test_heavier_beam_more_stable_by_the_predicted_scaling():
    omega = 2 * math.pi / 1.0                     # a 1 s pulse, omega / p = 2.9 alone
    column = RockingBody.of_shape(H, B)
    alone = _min_overturning_ratio(column, omega)
    previous = alone
    for gamma in (0.5, 2.0):
        frame = RockingFrame(H, B, gamma)
        framed = _min_overturning_ratio(frame.body(), omega)
        assert framed > previous * 1.02
        previous = framed
        # the enlarged single column with the frame's restitution overturns at the same
        # amplitude (in units of alpha g: the same alpha)
        k = frame.size_factor
        enlarged = RockingBody.of_shape(k * H, k * B, restitution=frame.restitution)
        assert _min_overturning_ratio(enlarged, omega) == pytest.approx(framed, rel=2e-3)


def test_bad_frames_raise_one_line():
    for kwargs in (dict(gamma=-0.1), dict(gamma=float("nan")), dict(gamma=True),
                   dict(gamma=1.0, shape="sphere")):
        with pytest.raises(InputError):
            RockingFrame(H, B, **kwargs)
    with pytest.raises(InputError):
        RockingFrame(-1.0, B, 1.0)
    with pytest.raises(InputError):
        RockingFrame.of_masses(H, B, 0, 1.0, 1.0)
    with pytest.raises(InputError):
        RockingBody(0.2, 2.0, 1.2)
