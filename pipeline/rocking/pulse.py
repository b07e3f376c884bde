"""One-sine ground pulses (Zhang & Makris 2000): the pulse a(t) (m/s^2), the block's
response and its mode (no overturn, overturn after or without an impact), and the modes
over amplitude and frequency ratios."""
import math

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.rocking.housner import RockingBody
from pipeline.rocking.response import _integrate

MODE_NO_OVERTURN = 0
MODE_OVERTURN_AFTER_IMPACT = 1
MODE_OVERTURN_WITHOUT_IMPACT = 2
MODE_NAMES = {MODE_NO_OVERTURN: "no_overturn",
              MODE_OVERTURN_AFTER_IMPACT: "overturn_after_impact",
              MODE_OVERTURN_WITHOUT_IMPACT: "overturn_without_impact"}


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
    """Block (height, width in m) under a one-sine pulse; see :func:`body_sine_pulse_response`."""
    body = RockingBody.of_shape(height, width, "block", g, restitution)
    return body_sine_pulse_response(body, amplitude_ratio, omega_ratio, psi, t_after, dt_out)


def body_sine_pulse_response(body, amplitude_ratio, omega_ratio, psi=None, t_after=30.0,
                             dt_out=0.005):
    """A :class:`~pipeline.rocking.housner.RockingBody` under a one-sine pulse
    a_g = A sin(omega t + psi) (Zhang & Makris 2000).

    A = amplitude_ratio * alpha * g (m/s^2, > 0: the first half-cycle pushes the
    body West, theta < 0), omega = omega_ratio * p (rad/s).  psi (rad) defaults
    to asin(g tan(alpha) / A), the phase at which uplift starts, placed at t = 0;
    the pulse runs to phase 2 pi (the part before uplift moves nothing).  If
    A <= g tan(alpha) the body never uplifts (psi = 0).

    Returns the rocking_response dict plus: mode (int, MODE_*), mode_name,
    relative_direction (+1 overturned towards the side of the first push,
    -1 away from it, 0 not overturned), psi (rad), pulse_end (s),
    amplitude (m/s^2), omega (rad/s).
    """
    amplitude = amplitude_ratio * body.alpha * body.g
    omega = omega_ratio * body.p
    if not (amplitude > 0 and omega > 0):
        raise InputError("sine pulse amplitude and frequency ratios must be positive")
    if psi is None:
        psi = math.asin(body.uplift_acc / amplitude) if amplitude > body.uplift_acc else 0.0
    acc, t_pulse = sine_pulse(amplitude, omega, psi)
    out = _integrate(body, acc, t_pulse + t_after, 0.0, 0.0, max_impacts=None,
                     still_after=t_pulse, linearised=False, dt_out=dt_out,
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

