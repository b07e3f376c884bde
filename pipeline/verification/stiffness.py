"""Housner free rocking against the contact stiffness: the paper's marble block and the
paper's monolithic column released from rest at ``THETA0_RATIO`` of their overturning
angle, at contact stiffness kn x 1, 3, 10 (``FACTORS``) with the damping ratio, friction
and rim spheres fixed (``make contact-convergence``).

Per body and factor: the impact times and the restitution of every impact (angular
velocity after / before it, from the successive amplitudes of the trajectory:
:func:`pipeline.rocking.decay.restitution_from_peaks`), against Housner's rigid body (his
perfectly inelastic impact: :func:`pipeline.rocking.housner.block_constants`,
:func:`pipeline.rocking.housner.cylinder_constants`; the impact times from his equation
integrated with that restitution) and against x1; the time step (s) the scene used and the
wall time (s) of the YADE run.  The damping ratio is ``HOUSNER_DAMPING`` (critical): the
setting whose impact is Housner's (docs/campaigns.md, Verification).  The same runs at the
other ``DAMPINGS`` (the paper's 0.36, the middle of the twin ensembles' range, and the
rock's calibrated 0.05: impacts that keep more) give the restitution against the
stiffness where the model is used (``at_damping``).
"""
import math
from pathlib import Path

import numpy as np

from pipeline import paper
from pipeline.rocking.decay import free_rocking_peaks, restitution_from_peaks
from pipeline.rocking.housner import SHAPES
from pipeline.rocking.response import housner_free_rocking
from pipeline.files import InputError
from pipeline.verification.checks import (HOUSNER_DAMPING, MARBLE_BLOCK, MARBLE_CONTACT,
                                          run_block, run_cylinder)

FACTORS = (1, 3, 10)
THETA0_RATIO = 0.5
IMPACTS = 5
DAMPINGS = (HOUSNER_DAMPING, paper.DAMPING_RATIO, 0.05)
BODIES = {   # name: what it is, shape, sizes (m; width: a cylinder's diameter), contact
    "block": {"label": "the paper's marble block", "shape": "block", **MARBLE_BLOCK,
              "contact": {**MARBLE_CONTACT, "damping": HOUSNER_DAMPING}},
    "column": {"label": "the paper's monolithic column", "shape": "cylinder",
               "height": paper.COLUMN_HEIGHT_M,
               "width": paper.COLUMN_HEIGHT_M / paper.COLUMN_HD,
               "contact": {"kn": paper.COLUMN_KN_N_M, "damping": HOUSNER_DAMPING,
                           "mu_s": paper.MU_STATIC, "mu_k": paper.MU_KINETIC}},
}


def check_factors(factors):
    """InputError unless ``factors`` are stiffness factors from 1 (x1 the reference) up."""
    if not factors or any(isinstance(f, bool) or not isinstance(f, (int, float))
                          or not math.isfinite(f) or f < 1 for f in factors) \
            or min(factors) != 1:
        raise InputError(f"stiffness factors must be numbers >= 1 including 1, got {factors!r}")
    return tuple(sorted(set(factors)))


def reference(body, theta0_ratio=THETA0_RATIO, impacts=IMPACTS):
    """Housner's rigid body of ``body`` (a BODIES entry): its constants and the impact
    times (s) of its free rocking from theta0_ratio x alpha."""
    constants = SHAPES[body["shape"]](body["height"], body["width"])
    free = housner_free_rocking(body["height"], body["width"],
                                        theta0_ratio * constants["alpha"], n_impacts=impacts,
                                        shape=body["shape"])
    return constants, free


def measure(t, theta, alpha, impacts=IMPACTS):
    """Impact times (s) and restitution of each impact from a free-rocking trajectory (t s,
    theta rad): the first ``impacts`` impacts that have an amplitude after them."""
    found = free_rocking_peaks(t, theta)
    peaks = found["peaks"][:impacts + 1]
    if peaks.size < 2:
        raise InputError("free rocking: no impact with an amplitude after it")
    eta = restitution_from_peaks(peaks, alpha)["eta_per_impact"]
    return {"impact_times_s": found["impact_times"][:eta.size].tolist(),
            "restitution_per_impact": eta.tolist(), "restitution": float(np.mean(eta))}


def run_body(name, factor, run_dir, theta0_ratio=THETA0_RATIO, impacts=IMPACTS, damping=None):
    """One YADE free-rocking run of BODIES[name] at kn x ``factor`` (and ``damping``, else
    the body's): its measure, time step (s), wall time (s) and simulated time (s)."""
    body = BODIES[name]
    constants, free = reference(body, theta0_ratio, impacts)
    contact = {**body["contact"], "kn": body["contact"]["kn"] * factor}
    if damping is not None:
        contact["damping"] = damping
    # a body whose impacts keep more than Housner's swings longer: 25 % more time
    duration = 1.25 * float(free["peak_times"][impacts]) + 0.05
    theta0 = theta0_ratio * constants["alpha"]
    if body["shape"] == "block":
        t, theta, trajectory = run_block(run_dir, body["height"], body["width"], body["depth"],
                                         theta0, duration=duration, **contact)
    else:
        t, theta, trajectory = run_cylinder(run_dir, body["height"], body["width"], theta0,
                                            duration=duration, **contact)
    return {"kn": contact["kn"], **measure(t, theta, constants["alpha"], impacts),
            "time_step_s": float(trajectory.dt), "wall_s": float(trajectory.wall_s),
            "simulated_s": float(t[-1] - t[0])}


def summarise(name, runs, theta0_ratio=THETA0_RATIO, impacts=IMPACTS):
    """The free-rocking table of BODIES[name] from ``runs`` ({factor: :func:`run_body`
    result}, factor 1 among them): Housner's restitution and impact times, and per factor
    (keys x1, x3, ...) its run with the largest differences from Housner and from x1."""
    body = BODIES[name]
    constants, free = reference(body, theta0_ratio, impacts)
    housner_times = free["impact_times"][:impacts]
    base = runs[1]
    factors = {}
    for factor in sorted(runs):
        run = runs[factor]
        eta = np.asarray(run["restitution_per_impact"])
        times = np.asarray(run["impact_times_s"])
        n = min(times.size, housner_times.size)
        m = min(eta.size, len(base["restitution_per_impact"]))
        k = min(times.size, len(base["impact_times_s"]))
        factors[f"x{factor:g}"] = {
            **run, "impacts": int(eta.size),
            "max_abs_restitution_minus_housner": float(np.max(np.abs(
                eta - constants["restitution"]))),
            "max_rel_error_impact_times_housner": float(np.max(np.abs(
                times[:n] - housner_times[:n]) / housner_times[:n])) if n else None,
            "max_abs_restitution_minus_x1": float(np.max(np.abs(
                eta[:m] - np.asarray(base["restitution_per_impact"][:m])))) if m else None,
            "max_abs_impact_time_minus_x1_s": float(np.max(np.abs(
                times[:k] - np.asarray(base["impact_times_s"][:k])))) if k else None,
            "time_step_vs_x1": run["time_step_s"] / base["time_step_s"],
            "wall_vs_x1": run["wall_s"] / base["wall_s"] if base["wall_s"] > 0 else None}
    return {"body": body["label"], "shape": body["shape"], "height_m": body["height"],
            "width_m": body["width"],
            **({"depth_m": body["depth"]} if "depth" in body else {}),
            "contact": body["contact"], "theta0_ratio": theta0_ratio,
            "alpha_rad": constants["alpha"], "housner_restitution": constants["restitution"],
            "housner_impact_times_s": housner_times.tolist(), "factors": factors}


def free_rocking_table(out_dir, factors=FACTORS, bodies=tuple(BODIES), dampings=DAMPINGS,
                       log=print):
    """Run every body of ``bodies`` at every factor and damping ratio (run directories
    under ``out_dir``) and return {body: :func:`summarise` at the body's own (critical)
    damping, with ``at_damping``: [{damping, factors: :func:`other_damping`}, ...] for the
    other dampings}."""
    factors = check_factors(factors)
    unknown = set(bodies) - set(BODIES)
    if unknown:
        raise InputError(f"unknown free-rocking body {', '.join(sorted(unknown))} (known: "
                         f"{', '.join(BODIES)})")
    table = {}
    for name in bodies:
        own = BODIES[name]["contact"]["damping"]
        by_damping = {}
        for damping in dict.fromkeys((own, *dampings)):
            runs = by_damping[damping] = {}
            for factor in factors:
                runs[factor] = run_body(name, factor, Path(out_dir) /
                                        f"{name}-damping{damping:g}-x{factor:g}",
                                        damping=damping)
                r = runs[factor]
                log(f"free rocking, {name} damping {damping:g} kn x{factor:g}: restitution "
                    f"{r['restitution']:.4f}, time step {r['time_step_s']:.3g} s, wall "
                    f"{r['wall_s']:.1f} s")
        table[name] = {**summarise(name, by_damping[own]),
                       "at_damping": [{"damping": d, "factors": other_damping(runs)}
                                      for d, runs in by_damping.items() if d != own]}
    return table


def other_damping(runs):
    """{x1: ..., x3: ...}: restitution (mean and per impact), time step (s), wall time (s)
    and the largest difference of an impact's restitution from x1's (``runs``: {factor:
    :func:`run_body` result})."""
    base = np.asarray(runs[1]["restitution_per_impact"])
    out = {}
    for factor in sorted(runs):
        eta = np.asarray(runs[factor]["restitution_per_impact"])
        n = min(eta.size, base.size)
        out[f"x{factor:g}"] = {key: runs[factor][key] for key in (
            "kn", "restitution", "restitution_per_impact", "time_step_s", "wall_s")}
        out[f"x{factor:g}"]["max_abs_restitution_minus_x1"] = float(
            np.max(np.abs(eta[:n] - base[:n]))) if n else None
    return out
