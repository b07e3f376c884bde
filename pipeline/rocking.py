"""Rigid rectangular block rocking in a plane: the reference the YADE model is verified against.

Theory after Housner (1963), Zhang & Makris (2000) and Augusti & Sinopoli (1992),
as summarised in Hinzen (2009), eqs 1-8.  Pure numpy/scipy; the equations of
motion are integrated with ``scipy.integrate.solve_ivp`` and its events
(impacts, peaks, overturning, uplift).

Block: width b (m, in the rocking plane), height h (m), homogeneous.
alpha = atan(b/h) (rad), R = half-diagonal (m), p = sqrt(3 g / (4 R)) (1/s),
I0 = (4/3) m R^2 about a base corner.

Sign convention (x = East): theta (rad) > 0 is rotation about the East (+x) base
corner, the block leaning East; theta < 0 about the West corner.  With the
horizontal ground acceleration a_g (m/s^2, positive East) the equation is

    I0 theta'' = -m R [ g sin(alpha sgn(theta) - theta) + a_g cos(alpha sgn(theta) - theta) ]

so a positive (East) a_g, whose inertial force points West, rocks the block onto
its West corner (theta < 0).  The block uplifts from rest when |a_g| > g tan(alpha),
towards the side -sign(a_g).  At each impact (theta crossing 0) the angular
velocity is multiplied by the coefficient of restitution eta; the block is put
back to rest when the angular velocity after an impact drops below a tiny
threshold (the impact sequence of a settling block is infinite but converges).
It has overturned when |theta| reaches pi/2 (its side strikes the ground).

Coefficient of restitution: Housner's exact rectangular-block value
eta = 1 - 1.5 sin^2(alpha) (angular momentum conserved about the new corner),
with the kinetic-energy ratio r = eta^2 (paper eq 4).  The paper's eq 5 is the
slender-block form eta ~ 1 - 1.5 (b/h)^2 ~ 1 - 1.5 alpha^2; we use the exact
sin^2(alpha) form everywhere (for alpha = 0.25: 0.9082 vs 0.9063).

Time series returned by the integrators are sampled every ``dt_out`` seconds,
plus the states at every event; at an impact the time appears twice, with the
angular velocity before and after the impact.
"""
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.stats import norm, theilslopes

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError

MODE_NO_OVERTURN = 0
MODE_OVERTURN_AFTER_IMPACT = 1
MODE_OVERTURN_WITHOUT_IMPACT = 2
MODE_NAMES = {MODE_NO_OVERTURN: "no_overturn",
              MODE_OVERTURN_AFTER_IMPACT: "overturn_after_impact",
              MODE_OVERTURN_WITHOUT_IMPACT: "overturn_without_impact"}

_RTOL = 1e-10
_ATOL = 1e-12
_REST_OMEGA_FRACTION = 1e-7   # rest when |omega| after impact < this * p * alpha
_MAX_EVENTS = 5000
_FREE_ROCKING_T_MAX = 1e4     # s, bound only: free rocking stops at its last peak
NOISE_SWINGS = 10.0           # a recorded swing counts above this many noise sd
MAX_AMPLITUDE_OF_ALPHA = 0.99  # free rocking from a frequency: amplitudes below this x alpha


def block_constants(height, width, g=MODEL_GRAVITY):
    """Geometry and Housner constants of a rectangular block (h, b in m).

    Returns dict: alpha (rad), R (m, half-diagonal), p (1/s), I0_per_mass
    (m^2, (4/3) R^2), restitution (Housner eta = 1 - 1.5 sin^2 alpha, for the
    angular velocity), energy_ratio (r = eta^2), uplift_acc (m/s^2, g tan alpha).
    """
    if not (height > 0 and width > 0 and g > 0):
        raise InputError(f"block height {height}, width {width} and g {g} must be positive")
    alpha = math.atan(width / height)
    R = 0.5 * math.hypot(height, width)
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    return dict(alpha=alpha, R=R, p=math.sqrt(3.0 * g / (4.0 * R)),
                I0_per_mass=4.0 / 3.0 * R ** 2, restitution=eta,
                energy_ratio=eta ** 2, uplift_acc=g * math.tan(alpha))


def cylinder_constants(height, diameter, g=MODEL_GRAVITY):
    """Housner's constants of a homogeneous solid cylinder (h, d in m) rocking in a plane
    about a point of its base rim: the block's equation with alpha = atan(d / h), R the
    distance from that point to the centre of mass, I0 = m (d^2 / 16 + h^2 / 12) + m R^2
    about it, p = sqrt(g R / (I0 / m)) (1/s) and the restitution of a perfectly inelastic
    impact on the opposite rim point, eta = 1 - 2 R^2 sin^2(alpha) / (I0 / m) (angular
    momentum conserved about it).  Same keys as :func:`block_constants`."""
    if not (height > 0 and diameter > 0 and g > 0):
        raise InputError(f"cylinder height {height}, diameter {diameter} and g {g} must be "
                         "positive")
    alpha = math.atan(diameter / height)
    R = 0.5 * math.hypot(height, diameter)
    i0 = diameter ** 2 / 16.0 + height ** 2 / 12.0 + R ** 2
    eta = 1.0 - 2.0 * R ** 2 * math.sin(alpha) ** 2 / i0
    return dict(alpha=alpha, R=R, p=math.sqrt(g * R / i0), I0_per_mass=i0, restitution=eta,
                energy_ratio=eta ** 2, uplift_acc=g * math.tan(alpha))


SHAPES = {"block": block_constants, "cylinder": cylinder_constants}


def housner_closed_form(theta0_ratio, r, n):
    """Paper eq 6 (Housner 1963, linearised block): amplitudes theta_k / alpha.

    theta_k / alpha = 1 - sqrt(1 - r^k (1 - (1 - theta0/alpha)^2)) for
    k = 0..n, k = number of impacts so far; r = kinetic-energy ratio per impact.
    """
    k = np.arange(n + 1)
    return 1.0 - np.sqrt(1.0 - r ** k * (1.0 - (1.0 - theta0_ratio) ** 2))


def housner_half_periods(height, width, theta0_ratio, n, r=None, g=MODEL_GRAVITY):
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


def housner_free_rocking(height, width, theta0, n_impacts=10, restitution=None, g=MODEL_GRAVITY,
                         linearised=False, dt_out=0.001, shape="block"):
    """Free rocking released from rest at theta0 (rad, != 0), Housner's equation; of a
    block, or with ``shape`` "cylinder" of a cylinder of diameter ``width``
    (:func:`cylinder_constants`).

    ``linearised`` uses theta'' = p^2 (theta - alpha sgn theta) instead of the
    full nonlinear equation.  Integrates up to the peak after impact n_impacts.

    Returns dict: t (s), theta (rad), omega (rad/s) samples; impact_times (s),
    impact_omega_before, impact_omega_after (rad/s); peak_times (s), peak_theta
    (rad, signed; index k = amplitude after k impacts, index 0 = theta0),
    peak_ratio (|peak| / alpha); alpha, p, restitution, overturned (bool).
    """
    if shape not in SHAPES:
        raise InputError(f"rocking shape must be one of {', '.join(SHAPES)}, got {shape!r}")
    c = SHAPES[shape](height, width, g)
    if theta0 == 0:
        raise InputError("free rocking needs a non-zero initial tilt theta0")
    out = _integrate(c, None, _FREE_ROCKING_T_MAX, theta0, 0.0, _restitution(c, restitution), g,
                     max_impacts=n_impacts, still_after=None, linearised=linearised,
                     dt_out=dt_out)
    peak_t = np.concatenate([[0.0], out["peak_times"]])
    peak_theta = np.concatenate([[float(theta0)], out["peak_theta"]])
    return dict(t=out["t"], theta=out["theta"], omega=out["omega"],
                impact_times=out["impact_times"],
                impact_omega_before=out["impact_omega_before"],
                impact_omega_after=out["impact_omega_after"],
                peak_times=peak_t, peak_theta=peak_theta,
                peak_ratio=np.abs(peak_theta) / c["alpha"], alpha=c["alpha"], p=c["p"],
                restitution=out["restitution"], overturned=out["overturned"])


def rocking_response(height, width, acc_func, t_end, restitution=None, g=MODEL_GRAVITY, theta0=0.0,
                     omega0=0.0, still_after=None, dt_out=0.005, rest_max_step=1e-3):
    """Rocking of the rigid block under a horizontal ground acceleration.

    acc_func(t) -> a_g (m/s^2, positive East), called with scalar t (s).
    Integrates from t = 0 to t_end (s) or until the block overturns.  If
    ``still_after`` (s) is given, a_g is taken as 0 from then on and the run
    stops early once the outcome is certain (a swing peaks below alpha, or the
    block rests).  While resting, the uplift condition |a_g| > g tan(alpha) is
    watched with steps of at most rest_max_step (s).

    Returns dict: t (s), theta (rad), omega (rad/s) samples; impact_times (s);
    uplift_times (s); peak_times (s), peak_theta (rad); overturned (bool);
    overturn_direction (+1 East, -1 West, 0 none); overturn_time (s, None if not);
    n_impacts (before overturning, or in total); first_side (+1/-1 side of the
    first uplift, 0 if none); max_abs_theta (rad); stop_reason (str);
    alpha, p, restitution.
    """
    c = block_constants(height, width, g)
    if not t_end > 0:
        raise InputError(f"t_end must be positive, got {t_end}")
    return _integrate(c, acc_func, t_end, theta0, omega0, _restitution(c, restitution), g,
                      max_impacts=None, still_after=still_after, linearised=False,
                      dt_out=dt_out, rest_max_step=rest_max_step)


def sine_pulse(amplitude, omega, psi):
    """One-sine ground acceleration (m/s^2): a(t) = A sin(omega t + psi) for
    0 <= t <= (2 pi - psi) / omega, i.e. the sine cycle from phase psi up to
    phase 2 pi, zero afterwards.  Returns (acc_func, pulse_end_s)."""
    t_pulse = (2.0 * math.pi - psi) / omega

    def acc(t):
        return amplitude * math.sin(omega * t + psi) if 0.0 <= t <= t_pulse else 0.0
    return acc, t_pulse


def sine_pulse_response(height, width, amplitude_ratio, omega_ratio, psi=None,
                        restitution=None, g=MODEL_GRAVITY, t_after=30.0, dt_out=0.005):
    """Block under a one-sine pulse a_g = A sin(omega t + psi) (Zhang & Makris 2000).

    A = amplitude_ratio * alpha * g (m/s^2, > 0: the first half-cycle pushes the
    block West, theta < 0), omega = omega_ratio * p (rad/s).  psi (rad) defaults
    to asin(g tan(alpha) / A), the phase at which uplift starts, placed at t = 0;
    the pulse runs to phase 2 pi (the part before uplift moves nothing).  If
    A <= g tan(alpha) the block never uplifts (psi = 0).

    Returns the rocking_response dict plus: mode (int, MODE_*), mode_name,
    relative_direction (+1 overturned towards the side of the first push,
    -1 away from it, 0 not overturned), psi (rad), pulse_end (s),
    amplitude (m/s^2), omega (rad/s).
    """
    c = block_constants(height, width, g)
    amplitude = amplitude_ratio * c["alpha"] * g
    omega = omega_ratio * c["p"]
    if not (amplitude > 0 and omega > 0):
        raise InputError("sine pulse amplitude and frequency ratios must be positive")
    if psi is None:
        psi = math.asin(c["uplift_acc"] / amplitude) if amplitude > c["uplift_acc"] else 0.0
    acc, t_pulse = sine_pulse(amplitude, omega, psi)
    out = _integrate(c, acc, t_pulse + t_after, 0.0, 0.0, _restitution(c, restitution), g,
                     max_impacts=None, still_after=t_pulse, linearised=False, dt_out=dt_out,
                     rest_max_step=min(1e-3, t_pulse / 200.0))
    if not out["overturned"]:
        mode = MODE_NO_OVERTURN
    elif out["n_impacts"] > 0:
        mode = MODE_OVERTURN_AFTER_IMPACT
    else:
        mode = MODE_OVERTURN_WITHOUT_IMPACT
    out.update(mode=mode, mode_name=MODE_NAMES[mode],
               relative_direction=out["overturn_direction"] * out["first_side"],
               psi=psi, pulse_end=t_pulse, amplitude=amplitude, omega=omega)
    return out


def overturning_map(height, width, amplitude_ratios, omega_ratios, restitution=None, g=MODEL_GRAVITY):
    """Outcome of one-sine pulses over a grid (like Zhang & Makris 2000, Fig. 6).

    Returns dict: mode (int array, shape (len(omega_ratios), len(amplitude_ratios)),
    MODE_* codes), n_impacts (int array, impacts before overturning or in total),
    relative_direction (int array), amplitude_ratios, omega_ratios (1-D arrays),
    mode_names (dict code -> name).
    """
    amps = np.asarray(amplitude_ratios, float)
    omegas = np.asarray(omega_ratios, float)
    shape = (omegas.size, amps.size)
    mode = np.zeros(shape, int)
    impacts = np.zeros(shape, int)
    direction = np.zeros(shape, int)
    for i, w in enumerate(omegas):
        for j, a in enumerate(amps):
            out = sine_pulse_response(height, width, a, w, restitution=restitution, g=g,
                                      dt_out=None)
            mode[i, j] = out["mode"]
            impacts[i, j] = out["n_impacts"]
            direction[i, j] = out["relative_direction"]
    return dict(mode=mode, n_impacts=impacts, relative_direction=direction,
                amplitude_ratios=amps, omega_ratios=omegas, mode_names=dict(MODE_NAMES))


def mode_edges(height, width, omega_ratio, amplitude_ratios, restitution=None, g=MODEL_GRAVITY,
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


def augusti_sinopoli_mu_min(width, height):
    """Paper eq 8 (Augusti & Sinopoli 1992): static friction needed for pure rocking.

    mu_s > 3 (b/h) / (4 + (b/h)^2) = 3 sin(alpha) cos(alpha) / (4 - 3 sin^2 alpha).
    This is, for a rigid block rocking about a corner at theta = 0, both the
    ratio of base friction to normal force when rocking starts from rest
    (omega = 0; demand falls as the release angle grows) and the ratio of
    horizontal to vertical base impulse of a Housner impact (see
    impact_friction_demand).  Dimensionless.
    """
    ratio = width / height
    return 3.0 * ratio / (4.0 + ratio ** 2)


def impact_friction_demand(width, height, restitution=None):
    """Horizontal / vertical base impulse of a rigid-block impact (dimensionless).

    Linear momentum of the centre of mass before and after an impact with
    angular velocity ratio eta gives |P_x| / P_z = (1 - eta) / ((1 + eta) tan alpha).
    With Housner's eta = 1 - 1.5 sin^2 alpha this equals eq 8; a lossier impact
    (smaller eta) demands more friction: the friction needed to avoid sliding
    at impact in a model whose impacts dissipate more than Housner's.
    """
    c = block_constants(height, width)
    eta = c["restitution"] if restitution is None else restitution
    return (1.0 - eta) / ((1.0 + eta) * math.tan(c["alpha"]))


def restitution_from_peaks(peaks, alpha):
    """Effective restitution from successive peak amplitudes (rad) of free rocking.

    peaks[k] = |theta| at the peak after k impacts.  Energy at impact
    k+1 is proportional to cos(alpha - theta_k) - cos(alpha) (exact rigid block),
    so the per-impact angular-velocity ratio is
    eta_k = sqrt(E_{k+1} / E_k).  Returns dict: eta_per_impact, r_per_impact
    (arrays), eta, r (overall geometric means over all impacts).
    """
    peaks = np.abs(np.asarray(peaks, float))
    if peaks.size < 2 or np.any(peaks >= alpha) or np.any(peaks <= 0):
        raise InputError("need >= 2 peak amplitudes, all between 0 and alpha")
    energy = np.cos(alpha - peaks) - math.cos(alpha)
    r_k = energy[1:] / energy[:-1]
    r = (energy[-1] / energy[0]) ** (1.0 / (peaks.size - 1))
    return dict(eta_per_impact=np.sqrt(r_k), r_per_impact=r_k, eta=math.sqrt(r), r=r)


def _restitution(c, restitution):
    eta = c["restitution"] if restitution is None else float(restitution)
    if not 0.0 <= eta <= 1.0:
        raise InputError(f"coefficient of restitution must lie in [0, 1], got {eta}")
    return eta


def _event(func, direction, terminal):
    func.direction = direction
    func.terminal = terminal
    return func


def _integrate(c, acc_func, t_end, theta0, omega0, eta, g, max_impacts, still_after,
               linearised, dt_out, rest_max_step=1e-3):
    """Hybrid integration: rest / rocking segments joined at impacts and uplifts."""
    alpha, p2 = c["alpha"], c["p"] ** 2
    omega_rest = _REST_OMEGA_FRACTION * c["p"] * alpha

    def acc(t):
        if acc_func is None or (still_after is not None and t >= still_after):
            return 0.0
        return float(acc_func(t))

    samples = _Samples(dt_out)
    events = {key: [] for key in ("impact_times", "impact_omega_before", "impact_omega_after",
                                  "uplift_times", "peak_times", "peak_theta")}
    t = 0.0
    theta, omega = float(theta0), float(omega0)
    side = int(np.sign(theta) or np.sign(omega))
    resting = side == 0
    overturned, overturn_time, stop_reason = False, None, "t_end"
    max_abs = abs(theta)

    for _ in range(_MAX_EVENTS):
        if t >= t_end:
            break
        if resting:
            if still_after is not None and t >= still_after \
                    and abs(acc(t)) < c["uplift_acc"] * (1.0 - 1e-12):
                stop_reason = "rest"
                break
            t, side = _rest(t, t_end, still_after, acc, c["uplift_acc"], rest_max_step, samples)
            if side:
                resting = False
                events["uplift_times"].append(t)
            continue

        free = still_after is not None and t >= still_after
        t_stop = t_end if (still_after is None or free) else min(t_end, still_after)
        last_swing = max_impacts is not None and len(events["impact_times"]) >= max_impacts
        s = side
        t_start = t
        # a segment starting at rest would trigger its own peak event at once
        sol = _swing(t, t_stop, theta, omega, s, alpha, p2, g, acc, linearised,
                     (free or last_swing) and omega != 0)
        samples.add_segment(t_start, sol.t[-1], sol.sol)
        max_abs = max(max_abs, float(np.max(np.abs(sol.y[0]))),
                      *_record_peaks(sol, t_start, events))
        t, (theta, omega) = float(sol.t[-1]), sol.y[:, -1]
        if sol.status != 1:  # reached t_stop: end of run or start of the still phase
            continue
        if sol.t_events[1].size:
            overturned, overturn_time, stop_reason = True, float(sol.t_events[1][0]), "overturned"
            max_abs = 0.5 * math.pi
            break
        if sol.t_events[2].size and sol.t_events[2][-1] > t_start and (free or last_swing):
            stop_reason = "safe" if free else "max_impacts"
            t, (theta, omega) = float(sol.t_events[2][-1]), sol.y_events[2][-1]
            samples.add_state(t, theta, omega)
            break
        # impact: theta = 0, angular velocity reduced, pivot changes side
        t, omega, resting = _impact_at(sol, eta, omega_rest, events, samples)
        theta, side = 0.0, -s
    else:
        raise RuntimeError(f"rocking integration exceeded {_MAX_EVENTS} events")

    ts, ys = samples.arrays()
    return dict(t=ts, theta=ys[0], omega=ys[1],
                **{key: np.array(values) for key, values in events.items()},
                overturned=overturned,
                overturn_direction=int(np.sign(theta)) if overturned else 0,
                overturn_time=overturn_time, n_impacts=len(events["impact_times"]),
                first_side=_first_side(events["uplift_times"], theta0, omega0, acc),
                max_abs_theta=max_abs, stop_reason=stop_reason, alpha=alpha, p=c["p"],
                restitution=eta)


def _record_peaks(sol, t_start, events):
    """The swing's peaks after t_start (s) appended to ``events``; their |theta| (rad)."""
    for tp, yp in zip(sol.t_events[2], sol.y_events[2]):
        if tp > t_start:
            events["peak_times"].append(float(tp))
            events["peak_theta"].append(float(yp[0]))
            yield abs(float(yp[0]))


def _impact_at(sol, eta, omega_rest, events, samples):
    """The swing's impact (theta 0): omega times eta, at rest below ``omega_rest`` (rad/s);
    recorded in ``events`` and ``samples``.  Returns its time (s), omega after it (rad/s)
    and whether the block rests."""
    t, omega_in = float(sol.t_events[0][0]), float(sol.y_events[0][0][1])
    omega_out = eta * omega_in
    events["impact_times"].append(t)
    events["impact_omega_before"].append(omega_in)
    events["impact_omega_after"].append(omega_out)
    samples.add_state(t, 0.0, omega_in)
    resting = abs(omega_out) < omega_rest
    omega = 0.0 if resting else omega_out
    samples.add_state(t, 0.0, omega)
    return t, omega, resting


class _Samples:
    """The states (theta rad, omega rad/s) an integration returns: every ``dt_out`` s of
    each segment (None: none) and the states at events, in time order."""

    def __init__(self, dt_out):
        self.dt_out, self.t, self.y = dt_out, [], []

    def add_segment(self, t_a, t_b, states):
        """The grid times in [t_a, t_b] (s), their states from ``states(times)`` (2, n)."""
        if self.dt_out is None:
            return
        k0 = math.ceil(t_a / self.dt_out - 1e-9)
        k1 = math.floor(t_b / self.dt_out + 1e-9)
        if k1 >= k0:
            grid = np.arange(k0, k1 + 1) * self.dt_out
            self.t.append(grid)
            self.y.append(states(grid))

    def add_state(self, t, theta, omega):
        if self.dt_out is not None:
            self.t.append(np.array([t]))
            self.y.append(np.array([[theta], [omega]]))

    def arrays(self):
        """Times (n,) s and states (2, n)."""
        if not self.t:
            return np.empty(0), np.empty((2, 0))
        return np.concatenate(self.t), np.concatenate(self.y, axis=1)


def _swing(t, t_stop, theta, omega, s, alpha, p2, g, acc, linearised, peak_armed):
    """One rocking segment about the pivot on side ``s`` from (t, theta, omega) to t_stop
    or its first terminal event: impact (theta 0), overturn (|theta| pi/2) or, when
    ``peak_armed``, the next peak; solve_ivp's solution (DOP853, dense)."""
    if linearised:
        def rhs(tt, y):
            return [y[1], -p2 * (s * alpha - y[0] + acc(tt) / g)]
    else:
        def rhs(tt, y):
            phi = s * alpha - y[0]
            return [y[1], -p2 * (math.sin(phi) + acc(tt) / g * math.cos(phi))]

    impact = _event(lambda tt, y: y[0], -s, True)
    fallen = _event(lambda tt, y: s * y[0] - 0.5 * math.pi, 1, True)
    peak = _event(lambda tt, y: y[1], -s, peak_armed)
    return solve_ivp(rhs, (t, t_stop), [theta, omega], method="DOP853", rtol=_RTOL,
                     atol=_ATOL, events=(impact, fallen, peak), dense_output=True)


def _rest(t, t_end, still_after, acc, uplift_acc, max_step, samples):
    """A block at rest from t (s) until the ground acceleration reaches ``uplift_acc``
    (m/s^2) or the segment ends (t_end, or the still phase from ``still_after``); the rest
    samples appended.  Returns the time reached and the pivot side of the uplift (0: none)."""
    if abs(acc(t)) >= uplift_acc * (1.0 - 1e-12):
        return t, -int(np.sign(acc(t)))
    t_stop = t_end if still_after is None else min(t_end, still_after)
    uplift = _event(lambda tt, y: abs(acc(tt)) - uplift_acc, 1, True)
    sol = solve_ivp(lambda tt, y: [0.0, 0.0], (t, t_stop), [0.0, 0.0],
                    events=uplift, max_step=max_step)
    samples.add_segment(t, sol.t[-1], lambda grid: np.zeros((2, grid.size)))
    if sol.status == 1:
        t = float(sol.t_events[0][0])
        return t, -int(np.sign(acc(t)))
    return t_stop, 0


def _first_side(uplifts, theta0, omega0, acc):
    if theta0 or omega0:
        return int(np.sign(theta0) or np.sign(omega0))
    return -int(np.sign(acc(uplifts[0]))) if uplifts else 0


# ---------------------------------------------------------------- many blocks at once
_BATCH_REST_OMEGA_FRACTION = 1e-5   # rest when |omega| after an impact < this * p * alpha


def rocking_response_sampled(height, width, acc, dt, t_after=30.0, restitution=None, g=MODEL_GRAVITY,
                             max_step=1e-3):
    """Rocking of N rigid blocks under sampled ground accelerations, all at once.

    The fast path of :func:`rocking_response` for records (no scalar callback, no
    event location by root finding): fixed-step classical Runge-Kutta on the same
    nonlinear equation, vectorised over the N cases, the ground acceleration
    linear between its samples.  An impact (theta crossing 0 within a step) is
    placed by linear interpolation inside the step, the angular velocity there
    multiplied by eta and the rest of the step continued to first order; uplift
    from rest is checked at every step (timing error <= one step).  After the
    motion the ground is still; a block inside its barrier (|theta| < alpha) whose
    energy about its pivot, (1/2) I0 omega^2 / m + g R cos(alpha - |theta|), is
    below g R (the top of the barrier) can no longer overturn and is decided, the
    others run on for at most ``t_after`` seconds.

    height, width: m, scalars or arrays of N; acc: m/s^2, shape (n,) or (n, N),
    samples every ``dt`` s (positive East, the sign convention of the module);
    restitution: None (Housner's eta of each block), a scalar or N values;
    max_step: the largest integration step (s), the sample interval divided evenly.

    Returns dict of arrays (N,): overturned (bool), overturn_time (s, NaN if not),
    overturn_direction (+1 East, -1 West, 0), first_side (side of the first uplift,
    0 none), uplift_time (s of the first uplift, NaN none), n_impacts,
    max_abs_theta (rad); plus alpha, p, restitution (arrays), steps (int),
    decided (bool: outcome certain when the integration stopped).
    """
    acc = _checked_samples(acc, dt, max_step, t_after)
    n_samples, n_cases = acc.shape
    blocks = _Blocks(*_block_arrays(height, width, restitution, n_cases, g), g)
    sub = max(1, math.ceil(dt / max_step - 1e-9))
    h = dt / sub
    total = (n_samples - 1) * sub + math.ceil(t_after / h)
    steps = 0
    # every block rests until the first sample that reaches an uplift threshold
    strong = np.any(np.abs(acc) >= blocks.uplift_acc * (1.0 - 1e-12), axis=1)
    first = max(int(np.argmax(strong)) - 1, 0) if strong.any() else n_samples - 1
    for step in range(first * sub, total):
        k, j = divmod(step, sub)
        t = step * h
        in_motion = k < n_samples - 1
        if in_motion:
            ground = tuple(acc[k] + (acc[k + 1] - acc[k]) * (f / sub) for f in (j, j + 0.5, j + 1))
        else:
            ground = (blocks.zero,) * 3
            if step == (n_samples - 1) * sub:       # the motion is over: decide the safe
                blocks.decide_safe()
        blocks.uplift(ground[0], t)
        active = (blocks.side != 0) & ~blocks.done
        if not active.any():
            if blocks.done.all() or not in_motion:
                break
            continue
        steps += 1
        blocks.advance(active, ground, h, t)
        if not in_motion:                      # free rocking: decided once below the barrier
            blocks.decide_safe()
        if blocks.done.all():
            break
    return blocks.result(steps)


def _checked_samples(acc, dt, max_step, t_after):
    """The ground accelerations (m/s^2) as an (n, N) array, the sampling checked."""
    acc = np.asarray(acc, float)
    if acc.ndim == 1:
        acc = acc[:, None]
    if acc.ndim != 2 or acc.shape[0] < 2 or not np.all(np.isfinite(acc)):
        raise InputError("acc must be finite samples of shape (n >= 2,) or (n, N)")
    if not (dt > 0 and max_step > 0 and t_after >= 0):
        raise InputError(f"dt {dt}, max_step {max_step} must be positive, t_after >= 0")
    return acc


class _Blocks:
    """The state of N rocking blocks of :func:`rocking_response_sampled`: angles (rad),
    angular velocities (rad/s), pivot sides (+1 / -1, 0 at rest) and what happened."""

    def __init__(self, alpha, R, p2, I0, eta, g):
        n_cases = alpha.size
        self.alpha, self.R, self.p2, self.I0, self.eta, self.g = alpha, R, p2, I0, eta, g
        self.uplift_acc = g * np.tan(alpha)
        self.omega_rest = _BATCH_REST_OMEGA_FRACTION * np.sqrt(p2) * alpha
        self.zero = np.zeros(n_cases)
        self.theta = np.zeros(n_cases)
        self.omega = np.zeros(n_cases)
        self.side = np.zeros(n_cases)
        self.done = np.zeros(n_cases, bool)
        self.overturned = np.zeros(n_cases, bool)
        self.overturn_time = np.full(n_cases, np.nan)
        self.direction = np.zeros(n_cases, int)
        self.first_side = np.zeros(n_cases, int)
        self.uplift_time = np.full(n_cases, np.nan)
        self.impacts = np.zeros(n_cases, int)
        self.max_abs = np.zeros(n_cases)

    def decide_safe(self):
        """Without ground motion: blocks at rest or below their barrier are decided."""
        self.done |= (self.side == 0) | _below_barrier(self.theta, self.omega, self.alpha,
                                                       self.R, self.I0, self.g)

    def uplift(self, a0, t):
        """Blocks at rest lift off where the ground acceleration a0 (m/s^2) at t (s)
        reaches their threshold."""
        start = (self.side == 0) & ~self.done & (np.abs(a0) >= self.uplift_acc * (1.0 - 1e-12))
        if start.any():
            self.side = np.where(start, -np.sign(a0), self.side)
            self.first_side = np.where(start & (self.first_side == 0), -np.sign(a0),
                                       self.first_side).astype(int)
            self.uplift_time = np.where(start & np.isnan(self.uplift_time), t, self.uplift_time)

    def advance(self, active, ground, h, t):
        """One step of h (s) from t (s) for the ``active`` blocks: Runge-Kutta, impacts,
        overturning."""
        theta, omega = self.theta, self.omega
        new_theta, new_omega = _rk4_step(theta, omega, self.side, ground, h, self.alpha,
                                         self.p2, self.g)
        # impacts: theta crossed 0 (to the other side of the pivot)
        hit = active & (self.side * new_theta < 0)
        if hit.any():
            new_theta, new_omega, self.side = _impact(theta, omega, new_theta, new_omega,
                                                      self.side, hit, self.eta,
                                                      self.omega_rest, h)
            self.impacts += hit
        self.theta = theta = np.where(active, new_theta, theta)
        self.omega = np.where(active, new_omega, omega)
        self.max_abs = np.maximum(self.max_abs, np.abs(theta))
        fell = active & (np.abs(theta) >= 0.5 * math.pi)
        if fell.any():
            self.overturned |= fell
            self.overturn_time = np.where(fell, t + h, self.overturn_time)
            self.direction = np.where(fell, np.sign(theta), self.direction).astype(int)
            self.max_abs = np.where(fell, 0.5 * math.pi, self.max_abs)
            self.done |= fell

    def result(self, steps):
        return dict(overturned=self.overturned, overturn_time=self.overturn_time,
                    overturn_direction=self.direction, first_side=self.first_side,
                    uplift_time=self.uplift_time, n_impacts=self.impacts,
                    max_abs_theta=self.max_abs, alpha=self.alpha, p=np.sqrt(self.p2),
                    restitution=np.asarray(self.eta, float), steps=steps,
                    decided=self.done.copy())


def _block_arrays(height, width, restitution, n_cases, g):
    """Per block of :func:`rocking_response_sampled`: alpha (rad), R (m), p^2 (1/s^2),
    I0 / m (m^2) and the restitution eta, the inputs checked."""
    height = np.broadcast_to(np.asarray(height, float), (n_cases,))
    width = np.broadcast_to(np.asarray(width, float), (n_cases,))
    if not (np.all(height > 0) and np.all(width > 0)):
        raise InputError("block heights and widths must be positive")
    alpha = np.arctan(width / height)
    R = 0.5 * np.hypot(height, width)
    p2 = 3.0 * g / (4.0 * R)
    I0 = 4.0 / 3.0 * R ** 2
    eta = (1.0 - 1.5 * np.sin(alpha) ** 2 if restitution is None
           else np.broadcast_to(np.asarray(restitution, float), (n_cases,)))
    if np.any((eta < 0) | (eta > 1)):
        raise InputError("coefficient of restitution must lie in [0, 1]")
    return alpha, R, p2, I0, eta


def _rk4_step(theta, omega, side, accelerations, h, alpha, p2, g):
    """One classical Runge-Kutta step of h (s) of the rocking equation about the pivots
    ``side`` (+1/-1), the ground acceleration at the step's start, middle and end."""
    a0, a1, a2 = accelerations

    def rhs(th, a):
        phi = side * alpha - th
        return -p2 * (np.sin(phi) + a / g * np.cos(phi))

    k1t, k1w = omega, rhs(theta, a0)
    k2t, k2w = omega + 0.5 * h * k1w, rhs(theta + 0.5 * h * k1t, a1)
    k3t, k3w = omega + 0.5 * h * k2w, rhs(theta + 0.5 * h * k2t, a1)
    k4t, k4w = omega + h * k3w, rhs(theta + h * k3t, a2)
    return (theta + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t),
            omega + h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w))


def _impact(theta, omega, new_theta, new_omega, side, hit, eta, omega_rest, h):
    """The blocks ``hit`` (theta crossed 0 in the step): the impact placed by linear
    interpolation, omega times eta, the rest of the step to first order on the other
    pivot; a block slower than ``omega_rest`` after it comes to rest.  Returns the new
    theta, omega and pivot sides."""
    frac = np.where(hit, theta / np.where(hit, theta - new_theta, 1.0), 0.0)
    omega_hit = eta * (omega + frac * (new_omega - omega))
    rest = hit & (np.abs(omega_hit) < omega_rest)
    new_theta = np.where(hit, omega_hit * (1.0 - frac) * h, new_theta)
    new_omega = np.where(hit, omega_hit, new_omega)
    side = np.where(hit, -side, side)
    side = np.where(rest, 0.0, side)
    new_theta = np.where(rest, 0.0, new_theta)
    new_omega = np.where(rest, 0.0, new_omega)
    return new_theta, new_omega, side


def _below_barrier(theta, omega, alpha, R, I0, g):
    """True where a block in free rocking can never overturn: inside its barrier with
    less energy than the barrier's top (energy only decreases without ground motion)."""
    energy = 0.5 * I0 * omega ** 2 + g * R * np.cos(alpha - np.abs(theta))
    return (np.abs(theta) < alpha) & (energy < g * R)


def free_rocking_peaks(t, theta, rise=None):
    """Impacts and amplitudes of a recorded free-rocking decay: ``t`` (s, increasing) and
    ``theta`` (rad, signed tilt); with ``rise`` (m, the centre of mass above its rest
    height, one per sample) also the highest rise of each swing (``rise_peaks``).  An impact is a change of sign of theta (linear
    interpolation between samples); the amplitude of a swing is the largest |theta|
    between two impacts (the first swing: from the start to the first impact).  Returns
    dict: impact_times (s), peaks (rad, index k = amplitude after k impacts), swing_s
    (s, durations between successive impacts)."""
    t = np.asarray(t, float)
    theta = np.asarray(theta, float)
    if t.ndim != 1 or t.shape != theta.shape or t.size < 3:
        raise InputError("free rocking: time and tilt need the same length, at least 3 samples")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(theta))):
        raise InputError("free rocking: time and tilt must be finite numbers")
    if np.any(np.diff(t) <= 0):
        raise InputError("free rocking: time must increase from sample to sample")
    crossing = np.flatnonzero(np.sign(theta[1:]) * np.sign(theta[:-1]) < 0)
    impacts = t[crossing] - theta[crossing] * (t[crossing + 1] - t[crossing]) / \
        (theta[crossing + 1] - theta[crossing])
    bounds = np.concatenate([[0], crossing + 1, [t.size]])
    peaks = np.array([np.max(np.abs(theta[a:b])) for a, b in zip(bounds[:-1], bounds[1:])
                      if b > a])
    # the swing after the last impact counts only when it has turned back (a peak inside)
    turned = not (crossing.size and
                  np.argmax(np.abs(theta[bounds[-2]:])) == t.size - 1 - bounds[-2])
    if not turned:
        peaks = peaks[:-1]
    out = dict(impact_times=impacts, peaks=peaks, swing_s=np.diff(impacts))
    if rise is not None:
        rise = np.asarray(rise, float)
        out["rise_peaks"] = np.array([np.max(rise[a:b]) for a, b in
                                      zip(bounds[:-1], bounds[1:]) if b > a])[:peaks.size]
    return out


def fit_free_rocking(height, width, t=None, theta=None, frequency_hz=None,
                     amplitude_ratios=None, g=MODEL_GRAVITY):
    """The rocking coefficient of restitution (eta: angular velocity after / before an
    impact) that reproduces a free-rocking decay of a block of ``height`` and ``width``
    (m, width in the rocking plane), from either a tilt record (``t`` s, ``theta`` rad:
    successive amplitudes, :func:`restitution_from_peaks`, exact for the rigid block) or
    the rocking frequency (Hz, full cycle, at the amplitudes measured) and the ratios of
    successive amplitudes (the amplitude from the frequency by Housner's linearised
    period, eq 7: theta / alpha = 1 - 1 / cosh(p T / 4)).  Returns dict: restitution
    (mean over impacts), restitution_sd (scatter of single impacts; None for one),
    restitution_se (standard error of the mean; None for one), restitution_per_impact,
    impacts, housner_restitution (1 - 1.5 sin^2 alpha), alpha (rad), p (1/s)."""
    c = block_constants(height, width, g)
    alpha = c["alpha"]
    if t is not None:
        peaks = swing_amplitudes(t, theta)
        if np.any(peaks >= alpha):
            raise InputError(f"free rocking: an amplitude of {np.max(peaks):.4g} rad is at or "
                             f"beyond the block's overturning angle alpha {alpha:.4g} rad "
                             "(wrong block size, or tilt in degrees given as radians?)")
        eta = restitution_from_peaks(peaks, alpha)["eta_per_impact"]
        restitution, se = decay_fit(peaks, alpha)
    else:
        if frequency_hz is None or not amplitude_ratios:
            raise InputError("free rocking: give a tilt record, or the rocking frequency and "
                             "the ratios of successive amplitudes")
        slowest = slowest_rocking_hz(height, width, g)
        if not frequency_hz >= slowest:
            raise InputError(f"free rocking at {frequency_hz:g} Hz: a {height:.3g} x "
                             f"{width:.3g} m block rocks no slower than {slowest:.3g} Hz below "
                             f"{MAX_AMPLITUDE_OF_ALPHA:g} of its overturning angle (Housner's "
                             "linearised period): no block of that size rocks at that "
                             "frequency")
        amplitude = 1.0 - 1.0 / math.cosh(c["p"] / (4.0 * frequency_hz))
        ratios = np.asarray(amplitude_ratios, float)
        energy = lambda ratio: np.cos(alpha - ratio * alpha) - math.cos(alpha)  # noqa: E731
        eta = np.sqrt(energy(amplitude * ratios) / energy(amplitude))
        restitution, se = float(np.mean(eta)), None
    n = eta.size
    sd = float(np.std(eta, ddof=1)) if n > 1 else None
    if t is None and sd is not None:
        se = sd / math.sqrt(n)
    return dict(restitution=restitution, restitution_sd=sd, restitution_se=se,
                restitution_per_impact=eta, impacts=int(n),
                housner_restitution=c["restitution"], alpha=alpha, p=c["p"])


def slowest_rocking_hz(height, width, g=MODEL_GRAVITY):
    """The lowest rocking frequency (Hz, full cycles) of a block of ``height`` and
    ``width`` (m) in free rocking below MAX_AMPLITUDE_OF_ALPHA of its overturning angle:
    Housner's linearised period (eq 7) T = 4 / p acosh(1 / (1 - theta / alpha)) grows
    without bound as theta nears alpha."""
    p = block_constants(height, width, g)["p"]
    return p / (4.0 * math.acosh(1.0 / (1.0 - MAX_AMPLITUDE_OF_ALPHA)))


def tilt_noise_sd(theta):
    """Standard deviation (rad) of white noise on a sampled tilt, robustly: the median
    absolute deviation of its second differences (6 sd^2 for the noise; a sampled swing's
    are far smaller, an impact's few) / 0.6745 / sqrt(6)."""
    d2 = np.diff(np.asarray(theta, float), 2)
    return float(np.median(np.abs(d2 - np.median(d2))) / (0.6745 * math.sqrt(6.0)))


def swing_amplitudes(t, theta):
    """Successive swing amplitudes (rad) of a recorded free-rocking decay (``t`` s,
    ``theta`` rad; swings between changes of sign, as :func:`free_rocking_peaks`) that
    stand above its noise (sd :func:`tilt_noise_sd`): a swing under NOISE_SWINGS sd is
    noise crossing zero (about an impact, or once the block is at rest) and is left out.
    On a noisy record a swing's amplitude is the top of a parabola fitted to its samples
    within NOISE_SWINGS / 2 sd of its highest (the highest sample alone reads high by
    about 2 sd).  InputError with fewer than two swings."""
    free_rocking_peaks(t, theta)                     # the checks of a record
    t, theta = np.asarray(t, float), np.asarray(theta, float)
    sd = tilt_noise_sd(theta)
    crossing = np.flatnonzero(np.sign(theta[1:]) * np.sign(theta[:-1]) < 0)
    bounds = np.concatenate([[0], crossing + 1, [t.size]])
    amplitudes = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        swing = np.abs(theta[a:b])
        top = int(np.argmax(swing))
        if swing[top] <= NOISE_SWINGS * sd or a + top == t.size - 1:
            continue                              # noise, or still rising at the end
        near = swing >= swing[top] - 0.5 * NOISE_SWINGS * sd
        amplitudes.append(_parabola_top(t[a:b][near], swing[near], swing[top]))
    if len(amplitudes) < 2:
        raise InputError("free rocking: at least one impact with amplitudes before and after "
                         f"it is needed (above the record's noise: {NOISE_SWINGS * sd:.2g} rad)")
    return np.array(amplitudes)


def _parabola_top(t, y, highest):
    """The top of a least-squares parabola through (t, y) when it opens downward with its
    top inside t; else ``highest``."""
    if t.size < 5:
        return float(highest)
    tau = t - t.mean()
    c2, c1, c0 = np.polyfit(tau, y, 2)
    if not c2 < 0 or not tau[0] <= -c1 / (2 * c2) <= tau[-1]:
        return float(highest)
    return float(c0 - c1 ** 2 / (4 * c2))


def decay_fit(peaks, alpha, confidence=0.95):
    """(restitution, its standard error or None for one impact) from successive swing
    amplitudes ``peaks`` (rad) of a block of critical angle ``alpha`` (rad): a robust line
    (Theil-Sen) through the swings' ln energy, ln(cos(alpha - theta_k) - cos(alpha)),
    against the swing number k, whose slope is 2 ln(restitution) (:func:`restitution_from_peaks`
    gives each impact's).  InputError when the slope's ``confidence`` interval reaches 0:
    amplitudes that do not decay are no free-rocking decay."""
    energy = np.cos(alpha - np.asarray(peaks, float)) - math.cos(alpha)
    fit = theilslopes(np.log(energy), np.arange(energy.size, dtype=float), alpha=confidence)
    if not fit.high_slope < 0.0:
        raise InputError(f"free rocking: the {energy.size} swing amplitudes do not decay (their "
                         f"energy changes by a factor {math.exp(fit.slope):.4f} a swing, "
                         f"{confidence:.0%} interval {math.exp(fit.low_slope):.4f}-"
                         f"{math.exp(fit.high_slope):.4f}): not a free-rocking decay")
    restitution = math.exp(fit.slope / 2.0)
    if energy.size < 3:
        return restitution, None
    z = norm.ppf(0.5 + confidence / 2.0)
    return restitution, restitution * (fit.high_slope - fit.low_slope) / (4.0 * z)
