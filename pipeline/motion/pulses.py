"""Analytic ground motions shared by the tests, the benchmark and the verification:
one-sine acceleration pulses with their exact velocity and displacement."""
import math

import numpy as np
from scipy.integrate import cumulative_trapezoid

from pipeline.motion import Motion
from pipeline.rocking.pulse import sine_pulse


def one_sine_pulse(azimuth_deg=0.0, amplitude=5.0, period=1.0, duration=6.0, dt=0.005):
    """a(t) = amplitude sin(2 pi t / period) (m/s^2) for t < period, zero after, along the
    horizontal azimuth ``azimuth_deg``; velocity and displacement integrated exactly."""
    t = np.arange(0.0, duration, dt)
    w = 2 * math.pi / period
    on = t < period
    acc = np.where(on, amplitude * np.sin(w * t), 0.0)
    vel = np.where(on, amplitude / w * (1 - np.cos(w * t)), 0.0)
    disp = np.where(on, amplitude / w * (t - np.sin(w * t) / w), amplitude / w * period)
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0.0])
    meta = {"record_id": f"pulse_{azimuth_deg:g}deg_{amplitude:g}ms2_{period:g}s",
            "back_azimuth_deg": None, "has_vertical": False}
    return Motion(dt, acc[:, None] * u, vel[:, None] * u, disp[:, None] * u, meta=meta)


def phased_sine_pulse(amplitude, omega, psi, dt=0.001, tail_s=4.0):
    """a(t) = A sin(omega t + psi) from phase psi to 2 pi along East, then zero for
    ``tail_s`` seconds (the pulse of :func:`pipeline.rocking.pulse.sine_pulse`), integrated
    to velocity and displacement (trapezoid)."""
    acc_func, t_pulse = sine_pulse(amplitude, omega, psi)
    t = np.arange(0.0, t_pulse + tail_s, dt)
    acc_e = np.array([acc_func(ti) for ti in t])
    vel_e = cumulative_trapezoid(acc_e, dx=dt, initial=0)
    disp_e = cumulative_trapezoid(vel_e, dx=dt, initial=0)
    zeros = np.zeros_like(t)
    return Motion(dt, np.column_stack([acc_e, zeros, zeros]), np.column_stack([vel_e, zeros, zeros]),
                  np.column_stack([disp_e, zeros, zeros]),
                  meta={"record_id": "sine_pulse", "has_vertical": False})


def raw_pulse(kind="sine", amplitude=6.0, frequency=0.75, azimuth_deg=0.0, start_s=8.0,
              duration=30.0, dt=0.01):
    """Unprocessed 3-component acceleration (n, 3) m/s^2 East/North/Up of one cycle of a
    one-sine (``kind`` "sine": Makris & Roussos 2000 type A, a forward fling leaving the
    displacement amplitude / (2 pi frequency^2)) or one-cosine ("cosine": type B, ends at
    rest) acceleration pulse along ``azimuth_deg``, starting ``start_s`` into a file of
    ``duration`` s of zeros: what a file from a user holds, for the processing."""
    if kind not in ("sine", "cosine"):
        raise ValueError(f"kind must be 'sine' or 'cosine', got {kind!r}")
    tau = np.arange(0.0, duration, dt) - start_s
    on = (tau >= 0) & (tau <= 1.0 / frequency)
    shape = np.sin if kind == "sine" else np.cos
    acc = np.where(on, amplitude * shape(2 * math.pi * frequency * tau), 0.0)
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0.0])
    return acc[:, None] * u


def one_cosine_pulse(pga_m_s2, pgv_pga_s, azimuth_deg=0.0, dt=0.005, tail_s=4.0):
    """One cycle of the one-cosine displacement pulse d(t) = A - A cos(2 pi F t) with
    F = 1 / (2 pi PGV/PGA) (the Virtual Shake Robot's pulse: Chen et al. 2024), so that
    PGA = A (2 pi F)^2 and PGV = A 2 pi F exactly, horizontal along ``azimuth_deg``
    (deg clockwise from North), then ``tail_s`` s at rest for the body to settle.
    Acceleration, velocity and displacement are the exact derivatives, sampled at most
    every ``dt`` s (shortened so that a quarter period is a whole number of samples: the
    samples hold the peaks); the displacement is back to zero at the end of the cycle."""
    for name, value in (("pga_m_s2", pga_m_s2), ("pgv_pga_s", pgv_pga_s), ("dt", dt)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"one_cosine_pulse: {name} must be a positive number, got {value!r}")
    w = 1.0 / pgv_pga_s                          # 2 pi F (rad/s)
    amplitude = pga_m_s2 / w ** 2                # A (m)
    period = 2 * math.pi / w
    n_cycle = 4 * int(math.ceil(period / (4 * dt)))
    dt = period / n_cycle
    t = np.arange(n_cycle + 1 + int(math.ceil(tail_s / dt))) * dt
    on = t <= period
    phase = w * np.minimum(t, period)
    disp = np.where(on, amplitude * (1 - np.cos(phase)), 0.0)
    vel = np.where(on, amplitude * w * np.sin(phase), 0.0)
    acc = np.where(on, amplitude * w ** 2 * np.cos(phase), 0.0)
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0.0])
    meta = {"record_id": f"cosine_pulse_{pga_m_s2:.6g}ms2_{pgv_pga_s:.6g}s_{azimuth_deg:g}deg",
            "back_azimuth_deg": None, "has_vertical": False,
            "pulse": {"kind": "one-cosine displacement", "pga_m_s2": pga_m_s2,
                      "pgv_m_s": pga_m_s2 * pgv_pga_s, "pgv_pga_s": pgv_pga_s,
                      "amplitude_m": amplitude, "frequency_hz": 1 / period,
                      "azimuth_deg": azimuth_deg, "tail_s": tail_s}}
    return Motion(dt, acc[:, None] * u, vel[:, None] * u, disp[:, None] * u, meta=meta)
