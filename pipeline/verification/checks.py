"""The YADE block model against analytic rocking theory (:mod:`pipeline.rocking`).

A rectangular block (width b along East, depth along North, height h) rocks
about its North-South bottom edges.  Its rotation theta (rad) is positive
when it leans East (standing on its East edge).  References come from
pipeline.rocking (Housner 1963; Zhang & Makris 2000; Augusti & Sinopoli 1992).
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

from pipeline import RESULTS_DIR, paper
from pipeline.rocking.decay import restitution_from_peaks
from pipeline.rocking.housner import augusti_sinopoli_mu_min, block_constants, housner_closed_form
from pipeline.rocking.pulse import sine_pulse_response
from pipeline.rocking.response import housner_free_rocking
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.pulses import phased_sine_pulse
from pipeline.outcome.columns import body_axes, rotation_from_start_deg
from pipeline.scenario import (Block, Column, ColumnGeometry, ColumnSpec, Contact, Numerics,
                               run_yade, scene_params, write_scenario)
from pipeline.scenario.solids import ColumnBlock, Frustum
from pipeline.scenario.parameters import kinetic_friction, split_options
from pipeline.scenario.time_step import time_step_s

MARBLE_BLOCK = paper.MARBLE_BLOCK_M
PULSE_BLOCK = paper.PULSE_BLOCK_M
MARBLE_CONTACT = {"kn": paper.MARBLE_BLOCK_KN_N_M, "damping": paper.DAMPING_RATIO,
                  "mu_s": paper.MU_STATIC, "mu_k": paper.MU_KINETIC,
                  "rim_sphere_radius": 0.001}   # b / 80: rounded edges shift alpha by < 1 %
# Housner's impact is perfectly inelastic: critically damped contacts reproduce his
# restitution within 0.2 %; the paper's 0.36 gives a 0.4 % higher one (docs/campaigns.md, Verification)
HOUSNER_DAMPING = 1.0
TOLERANCE = 0.02            # relative, impact times and peak amplitudes
MAX_IMPACTS = 20            # Housner's free rocking: impacts compared (decay below ~1e-3)
MAX_AMPLITUDE_RATIO = 50.0  # one-sine pulse: amplitude / (alpha g)
MAX_OMEGA_RATIO = 50.0      # one-sine pulse: omega / p (a pulse of ~20 time steps at most)


def check_theta0_ratio(theta0_ratio):
    """InputError unless 0 < theta0 / alpha < 1 (a block released inside its stability)."""
    if not 0 < theta0_ratio < 1:
        raise InputError(f"theta0 ratio must be between 0 and 1, got {theta0_ratio}")


def check_pulse_ratios(amplitude_ratio, omega_ratio):
    """InputError unless the one-sine pulse's A / (alpha g) and omega / p are in range."""
    if not (0 < amplitude_ratio <= MAX_AMPLITUDE_RATIO and 0 < omega_ratio <= MAX_OMEGA_RATIO):
        raise InputError(f"--amplitude-ratio must be in (0, {MAX_AMPLITUDE_RATIO:g}] and "
                         f"--omega-ratio in (0, {MAX_OMEGA_RATIO:g}] (the pulse must last "
                         f"steps of the model), got {amplitude_ratio:g} and {omega_ratio:g}")


def run_block(run_dir, height, width, depth, theta0=0.0, motion=None, duration=5.0,
              density=paper.MARBLE_DENSITY_KG_M3, record_hz=1000.0, **options):
    """Run the block scene; return (t, theta, trajectory) with theta in rad (+ = leaning East).

    options: Contact and Numerics fields (kn, damping, mu_s, mu_k, rim_sphere_radius, ...).
    """
    block = Block(height=height, width=width, depth=depth, density=density, theta0_rad=theta0)
    return run_released(run_dir, block=block, motion=motion, duration=duration,
                        record_hz=record_hz, **options)


def run_cylinder(run_dir, height, diameter, theta0, duration=5.0,
                 density=paper.MARBLE_DENSITY_KG_M3, record_hz=1000.0, **options):
    """Run a monolithic cylinder (the paper's column: ``height``, ``diameter`` m) released
    from rest on the East (theta0 > 0, rad) or West point of its base rim; return (t,
    theta, trajectory) as :func:`run_block`."""
    geometry = ColumnGeometry("column", density, (ColumnBlock(
        Frustum(height, diameter, diameter), tilt_deg=math.degrees(abs(theta0)),
        tilt_azimuth_deg=90.0 if theta0 >= 0 else 270.0, tilt_mode="edge"),),
        edge_rims=False, settles=False)
    return run_released(run_dir, columns=[ColumnSpec("column", "monolithic", 0.0, 0.0,
                                                     geometry)],
                        duration=duration, record_hz=record_hz, **options)


def run_released(run_dir, columns=(), block=None, motion=None, duration=5.0, record_hz=1000.0,
                 **options):
    """Run one body (a :class:`Block` or one column spec) and return (t, theta,
    trajectory), theta (rad) the tilt of its long axis about North (+ = leaning East)."""
    contact, numerics = split_options(options)
    params = scene_params(columns=columns, block=block, contact=Contact(**contact),
                          numerics=Numerics(**{"record_hz": record_hz, "rest_duration_s": 0.3,
                                               **numerics}), t_max=duration)
    write_scenario(run_dir, params, motion)
    trajectory = run_yade(run_dir)
    axis = body_axes(trajectory.quat)[:, 0]
    theta = np.arctan2(axis[:, 0], axis[:, 2])
    return trajectory.t, theta, trajectory


def impacts_and_peaks(t, theta):
    """Impact times (s, zero crossings of theta, interpolated) and peak |theta| (rad)
    of each half cycle between consecutive impacts, the first from release."""
    sign = np.sign(theta)
    idx = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    times = t[idx] - theta[idx] * (t[idx + 1] - t[idx]) / (theta[idx + 1] - theta[idx])
    bounds = np.concatenate([[0], idx + 1, [len(t)]])
    peaks = np.array([np.abs(theta[a:b]).max() for a, b in zip(bounds[:-1], bounds[1:]) if b > a])
    return times, peaks


def _relative_error(model, reference):
    n = min(len(model), len(reference))
    if n == 0:
        return math.inf
    return float(np.max(np.abs(np.asarray(model[:n]) - reference[:n]) / np.abs(reference[:n])))


def verify_housner(height=MARBLE_BLOCK["height"], width=MARBLE_BLOCK["width"],
                   depth=MARBLE_BLOCK["depth"], theta0_ratio=0.5, n_impacts=5, run_dir=None,
                   **contact):
    """Free rocking from theta0 = R alpha: YADE against Housner's nonlinear equation
    (integrated) and his closed form (eq 6), first n_impacts impacts."""
    check_theta0_ratio(theta0_ratio)
    if isinstance(n_impacts, bool) or not isinstance(n_impacts, int) or \
            not 1 <= n_impacts <= MAX_IMPACTS:
        raise InputError(f"--impacts must be an integer in [1, {MAX_IMPACTS}], got {n_impacts!r}")
    contact = {**MARBLE_CONTACT, "damping": HOUSNER_DAMPING, **contact}
    const = block_constants(height, width)
    alpha = const["alpha"]
    ref = housner_free_rocking(height, width, theta0_ratio * alpha, n_impacts=n_impacts)
    ref_times = ref["impact_times"][:n_impacts]
    ref_peaks = ref["peak_ratio"][1:n_impacts + 1]        # after impact 1..n
    duration = float(ref["peak_times"][n_impacts]) + 0.05
    run_dir = Path(run_dir or RESULTS_DIR / "verification" / "runs" / f"housner_{theta0_ratio:g}")
    t, theta, _ = run_block(run_dir, height, width, depth, theta0_ratio * alpha,
                            duration=duration, **contact)
    times, peaks = impacts_and_peaks(t, theta)
    times, peaks = times[:n_impacts], peaks[1:n_impacts + 1] / alpha   # peaks after each impact
    closed = housner_closed_form(theta0_ratio, const["energy_ratio"], n_impacts)[1:]
    r_eff = restitution_from_peaks(np.concatenate([[theta0_ratio], peaks]) * alpha,
                                           alpha)["eta"]
    result = {
        "test": "housner", "height_m": height, "width_m": width, "depth_m": depth,
        "alpha_rad": alpha, "p_per_s": const["p"], "theta0_ratio": theta0_ratio,
        "contact": contact, "housner_restitution": const["restitution"],
        "effective_restitution": r_eff,
        "yade": {"impact_times_s": times.tolist(), "peaks_over_alpha": peaks.tolist()},
        "integration": {"impact_times_s": ref_times.tolist(), "peaks_over_alpha": ref_peaks.tolist()},
        "closed_form": {"peaks_over_alpha": np.asarray(closed).tolist()},
        "max_rel_error_impact_times": _relative_error(times, ref_times),
        "max_rel_error_peaks": _relative_error(peaks, ref_peaks),
        "max_rel_error_peaks_closed_form": _relative_error(peaks, np.asarray(closed)),
        "tolerance": TOLERANCE}
    result["passed"] = bool(len(times) >= n_impacts
                            and result["max_rel_error_impact_times"] <= TOLERANCE
                            and result["max_rel_error_peaks"] <= TOLERANCE)
    return result


def sine_pulse_motion(reference, dt=0.001, tail_s=4.0):
    """The one-sine ground motion (East) of a sine_pulse_response result."""
    return phased_sine_pulse(reference["amplitude"], reference["omega"], reference["psi"],
                             dt=dt, tail_s=tail_s)


def classify_rocking(t, theta, alpha):
    """Mode of a block's response: overturned once |theta| passes min(90 deg, 3 alpha),
    far beyond the point of no return alpha; returns (mode, direction, impacts before
    overturning) with direction +1 East, -1 West."""
    over = np.flatnonzero(np.abs(theta) > min(math.pi / 2, 3 * alpha))
    end = over[0] if over.size else len(t)
    impacts, _ = impacts_and_peaks(t[:end], theta[:end])
    if not over.size:
        return "no_overturn", 0, len(impacts)
    direction = int(np.sign(theta[over[0]]))
    mode = "overturn_after_impact" if len(impacts) else "overturn_without_impact"
    return mode, direction, len(impacts)


def verify_sine_pulse(height=PULSE_BLOCK["height"], width=PULSE_BLOCK["width"],
                      depth=PULSE_BLOCK["depth"], amplitude_ratio=6.5, omega_ratio=5.0,
                      run_dir=None, **contact):
    """One-sine pulse of amplitude K alpha g and circular frequency W p: YADE against
    the integration (overturned or not, impacts before overturning, direction)."""
    check_pulse_ratios(amplitude_ratio, omega_ratio)
    contact = {**dataclasses.asdict(Contact()), **contact}
    const = block_constants(height, width)
    ref = sine_pulse_response(height, width, amplitude_ratio, omega_ratio)
    motion = sine_pulse_motion(ref)
    run_dir = Path(run_dir or RESULTS_DIR / "verification" / "runs" /
                   f"pulse_{amplitude_ratio:g}_{omega_ratio:g}")
    t, theta, _ = run_block(run_dir, height, width, depth, motion=motion,
                            duration=motion.duration, **contact)
    mode, direction, n_impacts = classify_rocking(t, theta, const["alpha"])
    result = {"test": "sine-pulse", "height_m": height, "width_m": width,
              "amplitude_ratio": amplitude_ratio, "omega_ratio": omega_ratio, "contact": contact,
              "yade": {"mode": mode, "direction": direction, "impacts_before_overturning": n_impacts,
                       "max_abs_theta_over_alpha": float(np.abs(theta).max() / const["alpha"])},
              "integration": {"mode": ref["mode_name"], "direction": int(ref["overturn_direction"]),
                              "impacts_before_overturning": int(ref["n_impacts"])}}
    result["passed"] = bool(mode == ref["mode_name"]
                            and direction == int(ref["overturn_direction"]))
    return result


SLIDING_MU = (0.7, 0.6, 0.5, 0.4, 0.3, 0.25, 0.2, 0.175, 0.15, 0.14, 0.125, 0.1)
SLIDING_BELOW = 0.9      # mu_s at or below this x the Augusti & Sinopoli limit must slide


def check_sliding_mus(mu_values, height=MARBLE_BLOCK["height"], width=MARBLE_BLOCK["width"]):
    """Refuse (InputError) a set of mu_s with none at or below SLIDING_BELOW x the Augusti &
    Sinopoli limit of the block: the sliding check could not show that sliding starts
    there (the verify command asks this before any run), or a mu_s out of range."""
    for mu in mu_values:
        Contact(mu_s=mu)
    mu_min = augusti_sinopoli_mu_min(width, height)
    if not any(mu <= SLIDING_BELOW * mu_min for mu in mu_values):
        raise InputError(f"--mu-s needs a value at or below {SLIDING_BELOW * mu_min:.3f} "
                         f"({SLIDING_BELOW:g} x the Augusti & Sinopoli limit {mu_min:.3f} of "
                         "the block) to show that sliding starts below the limit")


def verify_sliding(mu_values=SLIDING_MU,
                   theta0_deg=10.0, height=MARBLE_BLOCK["height"], width=MARBLE_BLOCK["width"],
                   depth=MARBLE_BLOCK["depth"], duration=2.0,
                   run_dir=None,
                   **contact):
    """The paper's rock-sliding test (Fig. 6): free rocking of the marble block from
    theta0 for several mu_s (mu_k from mu_s by the contact's rule); slip of the base centre at the
    impacts against the Augusti & Sinopoli criterion (eq 8); passed: pure rocking from 0.4
    (or 1.1 x eq 8) up, sliding at and below 0.9 x eq 8.  Rigid-block theory puts
    the onset of sliding at eq 8 (0.149 for h/b = 5); the paper's model slid from ~0.3
    because its impacts lose more energy than Housner's
    (:func:`pipeline.rocking.housner.impact_friction_demand`)."""
    contact = {**MARBLE_CONTACT, **contact}
    const = block_constants(height, width)
    mu_min = augusti_sinopoli_mu_min(width, height)
    base = Path(run_dir or RESULTS_DIR / "verification" / "runs")
    rows = []
    for mu in mu_values:
        t, theta, traj = run_block(base / f"sliding_{mu:g}", height, width, depth,
                                   math.radians(theta0_deg), duration=duration,
                                   **{**contact, "mu_s": mu, "mu_k": kinetic_friction(mu)})
        axis = body_axes(traj.quat)[:, 0]
        base_x = traj.pos[:, 0, 0] - axis[:, 0] * height / 2      # bottom-face centre, East
        impacts, _ = impacts_and_peaks(t, theta)
        at_impacts = np.interp(impacts, t, base_x) if len(impacts) else np.array([])
        slip = float(np.abs(at_impacts).max()) if len(at_impacts) else float(np.abs(base_x).max())
        rows.append({"mu_s": mu, "mu_k": kinetic_friction(mu), "impacts": len(impacts),
                     "impact_times_s": impacts[:6].tolist(), "slip_at_impacts_m": slip,
                     "pure_rocking": slip < 0.01 * width,
                     "t": t[::10].tolist(), "base_x_m": base_x[::10].tolist()})
    rocking_mus = [r["mu_s"] for r in rows if r["pure_rocking"]]
    sliding_mus = [r["mu_s"] for r in rows if not r["pure_rocking"]]
    result = {"test": "sliding", "height_m": height, "width_m": width, "theta0_deg": theta0_deg,
              "contact": contact, "alpha_rad": const["alpha"],
              "augusti_sinopoli_mu_min": mu_min, "runs": rows,
              "lowest_mu_pure_rocking": min(rocking_mus) if rocking_mus else None,
              "highest_mu_sliding": max(sliding_mus) if sliding_mus else None}
    # pure rocking for mu_s >= 0.4 (paper) and above eq 8; sliding below eq 8 (10 % margins)
    result["passed"] = bool(
        all(r["pure_rocking"] for r in rows if r["mu_s"] >= min(0.4, 1.1 * mu_min))
        and not any(r["pure_rocking"] for r in rows if r["mu_s"] <= SLIDING_BELOW * mu_min))
    return result


STILL_MODELS = ("twin", "doric-peristyle")   # the paper's twin model; a column file on wedges


def still_rotation_deg(run_dir, model, damping, dt_factor, seconds=5.0):
    """Largest rotation (deg) of any body of ``model`` (one of STILL_MODELS) from where it
    was placed, standing ``seconds`` on a still pedestal with contact ``damping`` and
    time-step factor ``dt_factor`` (written past scene_params' stability check, so that
    refused pairs can be measured too).  An unstable pair rocks the column by degrees."""
    if model not in STILL_MODELS:
        raise InputError(f"unknown still model {model!r} (known: {', '.join(STILL_MODELS)})")
    column = Column("both") if model == "twin" else Column("both", column_file=model)
    n = int(round(seconds / 0.01)) + 1
    zeros = np.zeros((n, 3))
    still = Motion(0.01, zeros, zeros, zeros, meta={"record_id": "still"})
    contact = Contact(damping=damping)
    params = scene_params(columns=column.specs(), contact=contact,
                          motion_duration=still.duration, t_max=still.duration)
    params = dataclasses.replace(params, dt_factor=dt_factor, time_step_s=time_step_s(
        params.columns, contact, params.numerics["rim_points"], dt_factor))
    write_scenario(run_dir, params, still)
    return rotation_from_start_deg(run_yade(run_dir))
