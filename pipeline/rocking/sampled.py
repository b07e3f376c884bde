"""Many rigid blocks rocking at once under sampled ground accelerations (m/s^2): fixed-step
Runge-Kutta on Housner's nonlinear equation, vectorised over the blocks (the fast path of
:func:`pipeline.rocking.response.rocking_response` for records)."""
import math

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError

_BATCH_REST_OMEGA_FRACTION = 1e-5   # rest when |omega| after an impact < this * p * alpha


def rocking_response_sampled(height, width, acc, dt, t_after=30.0, restitution=None, g=MODEL_GRAVITY,
                             max_step=1e-3):
    """Rocking of N rigid blocks under sampled ground accelerations, all at once.

    The fast path of :func:`~pipeline.rocking.response.rocking_response` for records
    (no scalar callback, no event location by root finding): fixed-step classical
    Runge-Kutta on the same nonlinear equation, vectorised over the N cases, the ground
    acceleration linear between its samples.  An impact (theta crossing 0 within a step) is
    placed by linear interpolation inside the step, the angular velocity there
    multiplied by eta and the rest of the step continued to first order; uplift
    from rest is checked at every step (timing error <= one step).  After the
    motion the ground is still; a block inside its barrier (|theta| < alpha) whose
    energy about its pivot, (1/2) I0 omega^2 / m + g R cos(alpha - |theta|), is
    below g R (the top of the barrier) can no longer overturn and is decided, the
    others run on for at most ``t_after`` seconds.

    height, width: m, scalars or arrays of N; acc: m/s^2, shape (n,) or (n, N),
    samples every ``dt`` s (positive East, the sign convention of
    :mod:`~pipeline.rocking.response`);
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
