"""Housner's equation of a rigid block rocking in a plane, integrated event by event: free
rocking and the response to a ground acceleration (m/s^2).

Theory after Housner (1963), Zhang & Makris (2000) and Augusti & Sinopoli (1992),
as summarised in Hinzen (2009), eqs 1-8; constants in :mod:`.housner`.  The
equations of motion are integrated with ``scipy.integrate.solve_ivp`` and its events
(impacts, peaks, overturning, uplift).

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

Time series returned by the integrators are sampled every ``dt_out`` seconds,
plus the states at every event; at an impact the time appears twice, with the
angular velocity before and after the impact.
"""
import math

import numpy as np
from scipy.integrate import solve_ivp

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.rocking.housner import RockingBody

_RTOL = 1e-10
_ATOL = 1e-12
_REST_OMEGA_FRACTION = 1e-7   # rest when |omega| after impact < this * p * alpha
_MAX_EVENTS = 5000
_FREE_ROCKING_T_MAX = 1e4     # s, bound only: free rocking stops at its last peak


def housner_free_rocking(height, width, theta0, n_impacts=10, restitution=None, g=MODEL_GRAVITY,
                         linearised=False, dt_out=0.001, shape="block"):
    """Free rocking released from rest at theta0 (rad, != 0), Housner's equation; of a
    block, or with ``shape`` "cylinder" of a cylinder of diameter ``width``
    (:func:`~pipeline.rocking.housner.cylinder_constants`).  See :func:`free_rocking`."""
    body = RockingBody.of_shape(height, width, shape, g, restitution)
    return free_rocking(body, theta0, n_impacts, linearised, dt_out)


def free_rocking(body, theta0, n_impacts=10, linearised=False, dt_out=0.001):
    """Free rocking of a :class:`~pipeline.rocking.housner.RockingBody` released from rest
    at theta0 (rad, != 0).

    ``linearised`` uses theta'' = p^2 (theta - alpha sgn theta) instead of the
    full nonlinear equation.  Integrates up to the peak after impact n_impacts.

    Returns dict: t (s), theta (rad), omega (rad/s) samples; impact_times (s),
    impact_omega_before, impact_omega_after (rad/s); peak_times (s), peak_theta
    (rad, signed; index k = amplitude after k impacts, index 0 = theta0),
    peak_ratio (|peak| / alpha); alpha, p, restitution, overturned (bool).
    """
    if theta0 == 0:
        raise InputError("free rocking needs a non-zero initial tilt theta0")
    out = _integrate(body, None, _FREE_ROCKING_T_MAX, theta0, 0.0, max_impacts=n_impacts,
                     still_after=None, linearised=linearised, dt_out=dt_out)
    peak_t = np.concatenate([[0.0], out["peak_times"]])
    peak_theta = np.concatenate([[float(theta0)], out["peak_theta"]])
    return dict(t=out["t"], theta=out["theta"], omega=out["omega"],
                impact_times=out["impact_times"],
                impact_omega_before=out["impact_omega_before"],
                impact_omega_after=out["impact_omega_after"],
                peak_times=peak_t, peak_theta=peak_theta,
                peak_ratio=np.abs(peak_theta) / body.alpha, alpha=body.alpha, p=body.p,
                restitution=out["restitution"], overturned=out["overturned"])


def rocking_response(height, width, acc_func, t_end, restitution=None, g=MODEL_GRAVITY, theta0=0.0,
                     omega0=0.0, still_after=None, dt_out=0.005, rest_max_step=1e-3):
    """Rocking of the rigid block (height, width in m) under a horizontal ground
    acceleration; see :func:`body_response`."""
    body = RockingBody.of_shape(height, width, "block", g, restitution)
    return body_response(body, acc_func, t_end, theta0, omega0, still_after, dt_out,
                         rest_max_step)


def body_response(body, acc_func, t_end, theta0=0.0, omega0=0.0, still_after=None,
                  dt_out=0.005, rest_max_step=1e-3):
    """Rocking of a :class:`~pipeline.rocking.housner.RockingBody` (a block, a cylinder or
    a frame) under a horizontal ground acceleration.

    acc_func(t) -> a_g (m/s^2, positive East), called with scalar t (s).
    Integrates from t = 0 to t_end (s) or until the body overturns.  If
    ``still_after`` (s) is given, a_g is taken as 0 from then on and the run
    stops early once the outcome is certain (a swing peaks below alpha, or the
    body rests).  While resting, the uplift condition |a_g| > g tan(alpha) is
    watched with steps of at most rest_max_step (s).

    Returns dict: t (s), theta (rad), omega (rad/s) samples; impact_times (s);
    uplift_times (s); peak_times (s), peak_theta (rad); overturned (bool);
    overturn_direction (+1 East, -1 West, 0 none); overturn_time (s, None if not);
    n_impacts (before overturning, or in total); first_side (+1/-1 side of the
    first uplift, 0 if none); max_abs_theta (rad); stop_reason (str);
    alpha, p, restitution.
    """
    if not t_end > 0:
        raise InputError(f"t_end must be positive, got {t_end}")
    return _integrate(body, acc_func, t_end, theta0, omega0, max_impacts=None,
                      still_after=still_after, linearised=False, dt_out=dt_out,
                      rest_max_step=rest_max_step)


def _event(func, direction, terminal):
    func.direction = direction
    func.terminal = terminal
    return func


def _integrate(body, acc_func, t_end, theta0, omega0, max_impacts, still_after, linearised,
               dt_out, rest_max_step=1e-3):
    """Hybrid integration of ``body`` (a RockingBody): rest / rocking segments joined at
    impacts and uplifts."""
    alpha, p2, eta, g = body.alpha, body.p ** 2, body.restitution, body.g
    omega_rest = _REST_OMEGA_FRACTION * body.p * alpha

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
                    and abs(acc(t)) < body.uplift_acc * (1.0 - 1e-12):
                stop_reason = "rest"
                break
            t, side = _rest(t, t_end, still_after, acc, body.uplift_acc, rest_max_step, samples)
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
                max_abs_theta=max_abs, stop_reason=stop_reason, alpha=alpha, p=body.p,
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
