"""The contact damping ratio that gives a block a stated rocking restitution in YADE.

YADE's contact law (ViscElMat: a spring kn and a dashpot of damping ratio ``damping`` per
contact point) has no restitution of rocking of its own: a block's restitution (angular
velocity after / before an impact) comes out of the impacts of its corner springs.  It is
measured here by free rocking of the block in YADE (released from rest at half its
overturning angle, :func:`pipeline.verification.checks.run_block`; the restitution from its
successive amplitudes, :func:`pipeline.rocking.decay.fit_free_rocking`), and the damping found
by bisection: the restitution falls monotonically with the damping, from an almost
elastic impact at 0 to Housner's perfectly inelastic value (1 - 1.5 sin^2 alpha) at 1.
A restitution outside that range is not reachable by this law and is refused.  Each
measured restitution is kept in a cache file (JSON, ``CACHE``) by block, density, kn,
damping and the model's code, so a block mapped once is not run again.
"""
import contextlib
import dataclasses
import json
import math
import statistics
import tempfile

import numpy as np
from scipy.spatial.transform import Rotation

from pipeline import RESULTS_DIR, paper
from pipeline.files import InputError, code_hash, content_hash, write_json
from pipeline.outcome.columns import rotations
from pipeline.rocking.decay import fit_free_rocking, free_rocking_peaks
from pipeline.rocking.response import housner_free_rocking
from pipeline.scenario import ColumnSpec, Contact, Numerics, run_yade, scene_params
from pipeline.scenario.parameters import split_options
from pipeline.scenario.scene_file import base_points, released, support_line
from pipeline.scenario.writer import write_scenario
from pipeline.verification.checks import MARBLE_CONTACT, run_block

RESTITUTION_TOLERANCE = 0.0005   # |measured - stated| restitution the bisection stops at
DAMPING_TOLERANCE = 0.002        # or the damping interval below this
RELEASE_RATIO = 0.5              # released from rest at this fraction of alpha
IMPACTS = 6
SPECIMEN_RELEASES = (0.3, 0.4, 0.5)   # a specimen's map: the median over these releases
SETTLING_IMPACTS = 1             # a specimen's first impacts not counted (see specimen_rocking)
CACHE = RESULTS_DIR / "contact" / "restitution_map.json"


def rocking_restitution(height, width, depth, damping, kn=paper.MARBLE_BLOCK_KN_N_M,
                        density=paper.MARBLE_DENSITY_KG_M3, release_ratio=RELEASE_RATIO):
    """The restitution (mean over its first impacts) of the block rocking freely in YADE
    at contact damping ratio ``damping`` and stiffness ``kn`` (N/m per point), released
    from rest at ``release_ratio`` of its overturning angle."""
    alpha = math.atan(width / height)
    reference = housner_free_rocking(height, width, release_ratio * alpha,
                                             n_impacts=IMPACTS)
    duration = float(reference["peak_times"][IMPACTS]) + 0.05
    with tempfile.TemporaryDirectory(prefix="toppling-contact-") as run_dir:
        t, theta, _ = run_block(run_dir, height, width, depth, release_ratio * alpha,
                                duration=duration, density=density,
                                **{**MARBLE_CONTACT, "kn": kn, "damping": damping})
    return fit_free_rocking(height, width, t=t, theta=theta)["restitution"]


def cached_measure(measure, key, cache=CACHE):
    """(measured, runs): ``measured(damping)`` is ``measure(damping)`` (one YADE run) unless
    ``cache`` (a JSON file, or None) holds it under ``key`` (what was run), the damping
    and the model's code; ``runs()`` counts the runs made."""
    cached = json.loads(cache.read_text()) if cache is not None and cache.is_file() else {}
    model = code_hash("scenario", "verification", "yade_scripts")
    runs = [0]

    def measured(damping):
        name = f"{key},{damping:.6g},{model}"
        if name not in cached:
            cached[name] = measure(damping)
            runs[0] += 1
            if cache is not None:
                write_json(cache, cached)
        return cached[name]

    return measured, lambda: runs[0]


def bisect_damping(restitution, measured, what, log=print, clip=False):
    """(damping, measured restitution): the damping ratio in [0, 1] whose ``measured``
    restitution (a function falling with the damping) is ``restitution``, by bisection.
    Outside the reachable range: InputError (one line naming the range of ``what``), or
    with ``clip`` the end of the range nearest to it."""
    low, high = 0.0, 1.0
    r_low, r_high = measured(low), measured(high)
    if not r_high - RESTITUTION_TOLERANCE <= restitution <= r_low + RESTITUTION_TOLERANCE:
        if clip:
            return (low, r_low) if restitution > r_low else (high, r_high)
        raise InputError(f"restitution {restitution:.3f}: {what} reaches "
                         f"{r_high:.3f}-{r_low:.3f} with contact damping 1-0 in YADE; a "
                         "lower one needs a lossier contact than the perfectly inelastic "
                         "impact of Housner's")
    best = min(((abs(r_low - restitution), low, r_low), (abs(r_high - restitution), high, r_high)))
    while best[0] > RESTITUTION_TOLERANCE and high - low > DAMPING_TOLERANCE:
        middle = 0.5 * (low + high)
        r_middle = measured(middle)
        log(f"damping {middle:.4f}: restitution {r_middle:.4f}")
        best = min(best, (abs(r_middle - restitution), middle, r_middle))
        if r_middle > restitution:        # too elastic: more damping
            low = middle
        else:
            high = middle
    if best[0] > RESTITUTION_TOLERANCE:
        log(f"warning: {what}: restitution {restitution:.4f} not met within "
            f"{RESTITUTION_TOLERANCE:g}: the nearest measured is {best[2]:.4f} at damping "
            f"{best[1]:.4f} (the restitution does not fall smoothly with the damping there)")
    return best[1], best[2]


INTERVAL_MEANING = ("damping ratios whose restitution in YADE is the stated restitution plus "
                    "(low) and minus (high) its standard error; an end of the reachable "
                    "range (0 or 1) where that restitution lies beyond it")


def damping_interval(restitution, restitution_se, measured, what, log=print):
    """The damping interval of a restitution +- its standard error (dict low, high,
    restitution_low, restitution_high, clipped: which ends lie beyond the reachable range,
    meaning); None without a standard error."""
    if restitution_se is None:
        return None
    upper, lower = restitution + restitution_se, restitution - restitution_se
    low, _ = bisect_damping(upper, measured, what, log, clip=True)
    high, _ = bisect_damping(lower, measured, what, log, clip=True)
    clipped = [name for name, r, end in (("low", upper, 0.0), ("high", lower, 1.0))
               if (r > measured(end) if end == 0.0 else r < measured(end))]
    return {"low": low, "high": high, "restitution_low": lower, "restitution_high": upper,
            "clipped": clipped, "meaning": INTERVAL_MEANING}


def block_measure(height, width, depth, kn=paper.MARBLE_BLOCK_KN_N_M,
                  density=paper.MARBLE_DENSITY_KG_M3, cache=CACHE):
    """:func:`cached_measure` of the block's :func:`rocking_restitution`."""
    return cached_measure(
        lambda damping: rocking_restitution(height, width, depth, damping, kn, density),
        f"{height:.6g},{width:.6g},{depth:.6g},{density:.6g},{kn:.6g}", cache)


# ---------------------------------------------------------------- any specimen
def _scene(geometry, contact, numerics):
    """(scene file, its one column dict) of the specimen (a column description as the
    monolith of its outline) alone at the table's centre, at rest."""
    spec = ColumnSpec("specimen", "monolithic", 0.0, 0.0, geometry.monolithic())
    scene = scene_params(columns=[spec], contact=contact, numerics=numerics, t_max=1.0)
    return scene, scene.columns[0]


def weakest_azimuth(column, step_deg=1.0):
    """Azimuth (deg) toward which a scene column's critical angle is smallest (the weak
    side), on a grid of ``step_deg``."""
    azimuths = [k * step_deg for k in range(int(round(360.0 / step_deg)))]
    return min(azimuths, key=lambda a: support_line(column, a)["critical_angle_rad"])


def specimen_rocking(geometry, damping, kn, azimuth_deg=None, release_ratio=RELEASE_RATIO,
                     impacts=IMPACTS, run_dir=None, **options):
    """Free rocking of any specimen in YADE (a mesh specimen, or a column description as
    the monolith of its outline): released from rest, turned about its footprint's
    support line toward ``azimuth_deg`` (default the weak side, :func:`weakest_azimuth`)
    by ``release_ratio`` of its critical angle that way
    (:func:`pipeline.scenario.scene_file.released`).  The restitution of each impact
    from the successive highest rises z_k of the centre of mass above its rest height:
    the kinetic energy at an impact is the potential energy of the swing before, so
    eta_k^2 = z_k+1 / z_k (for a rigid block Housner's amplitude formula, exactly).  The
    rise is the rigid body's (the centre of mass above the lowest point of its base
    outline, from its orientation), so the springs' static sink does not enter.  A rock
    rocks in 3D: its swings to either side differ and part of its energy wobbles about
    the other axis, so its peak rises scatter from impact to impact
    (``restitution_from_rises``); the restitution is taken from its whole energy instead
    (kinetic, of translation and rotation, and the rise; the median over the middle half
    of each swing), E_k+1 / E_k = eta_k^2, which for a block is the same as the rises.
    The first SETTLING_IMPACTS impacts are not counted (released about one point of its
    footprint, a rock settles onto the edge it rocks about there), and the restitution
    is the geometric mean of the next ``impacts`` (E_n / E_0)^(1 / 2n): the mean decay of
    its energy per impact (for a block, the mean of its impacts').  ``options``: other Contact and Numerics fields.  Returns dict
    restitution (over the first ``impacts``, an even number: whole cycles),
    restitution_per_impact, impacts, azimuth_deg,
    critical_angle_deg, release_deg, and the record (t s, tilt rad about the support
    line, rise m).  ``run_dir``: keep the run there (default: a temporary directory)."""



    contact, numerics = split_options(options)
    scene, column = _scene(geometry, Contact(**{**contact, "kn": kn, "damping": damping}),
                           Numerics(**{"record_hz": 1000.0, "rest_duration_s": 0.3,
                                       **numerics}))
    azimuth = weakest_azimuth(column) if azimuth_deg is None else float(azimuth_deg)
    line, radius, (h, b) = equivalent_block(column, azimuth, geometry.name)
    alpha = line["critical_angle_rad"]
    tilt = release_ratio * alpha
    body = column["bodies"][0]
    counted = impacts + SETTLING_IMPACTS
    duration = _free_rocking_s(body, line, radius, scene.gravity, h, b, tilt, counted)
    scene = dataclasses.replace(scene, columns=[released(column, azimuth, tilt)],
                                t_max=duration)
    with contextlib.nullcontext(run_dir) if run_dir is not None else \
            tempfile.TemporaryDirectory(prefix="toppling-contact-") as where:
        write_scenario(where, scene)
        trajectory = run_yade(where)
    turns, theta, rise = _turn_and_rise(trajectory, body, line)
    found = free_rocking_peaks(trajectory.t, theta, rise=rise)
    z = found["rise_peaks"][SETTLING_IMPACTS:counted + 1]
    if z.size < 2 or not np.all(z > 0):
        raise InputError(f"{geometry.name}: no impact with swings before and after it in "
                         f"{duration:.2f} s of free rocking")
    energy = _energy_above_rest(trajectory, body, turns, rise, scene.gravity)
    times = np.concatenate([[trajectory.t[0]], found["impact_times"]])
    swings = [np.median(energy[(trajectory.t > a + 0.25 * (b - a)) &
                               (trajectory.t < b - 0.25 * (b - a))])
              for a, b in zip(times[:-1], times[1:])][SETTLING_IMPACTS:counted + 1]
    eta = np.sqrt(np.asarray(swings[1:]) / swings[:-1])
    eta_rise = np.sqrt(z[1:] / z[:-1])
    return {"restitution": float((swings[-1] / swings[0]) ** (0.5 / eta.size)),
            "restitution_per_impact": [float(e) for e in eta], "impacts": int(eta.size),
            "restitution_from_rises": float((z[-1] / z[0]) ** (0.5 / eta_rise.size)),
            "restitution_per_impact_from_rises": [float(e) for e in eta_rise],
            "azimuth_deg": azimuth, "critical_angle_deg": math.degrees(alpha),
            "release_deg": math.degrees(tilt), "t": trajectory.t, "tilt": theta, "rise": rise}


def equivalent_block(column, azimuth_deg, name):
    """(support line dict, R m, (height m, width m)) of a scene column toward
    ``azimuth_deg``: R the distance from the support line to the centre of mass, and the
    block of the same critical angle and R; InputError when the centre of mass is not
    above the footprint that way (``name``: the specimen's)."""

    line = support_line(column, azimuth_deg)
    alpha = line["critical_angle_rad"]
    if not alpha > 0:
        raise InputError(f"{name}: its centre of mass is not above its footprint "
                         f"toward {azimuth_deg:g} deg")
    arm = line["pivot"] - line["com"]
    radius = float(np.linalg.norm(arm - (arm @ line["axis"]) * line["axis"]))
    return line, radius, (2 * radius * math.cos(alpha), 2 * radius * math.sin(alpha))


def _free_rocking_s(body, line, radius, gravity, h, b, tilt, counted):
    """Duration (s) of a free-rocking run that holds ``counted`` impacts: Housner's block
    (h x b, released at ``tilt`` rad), its swings scaled by the specimen's own rocking
    frequency about the support line (p^2 = m g R / I_pivot)."""
    rotation = np.asarray(body["rotation"], float)
    inertia = line["axis"] @ rotation @ np.asarray(body["inertia"], float) @ rotation.T @ \
        line["axis"] + body["mass"] * radius ** 2
    p_specimen = math.sqrt(body["mass"] * gravity * radius / inertia)
    p_block = math.sqrt(0.75 * gravity / radius)
    reference = housner_free_rocking(h, b, tilt, n_impacts=counted)
    return 1.5 * float(reference["peak_times"][counted]) * p_block / p_specimen + 0.1


def _turn_and_rise(trajectory, body, line):
    """(rotations from the start (scipy), tilt rad about the support line, rise m of the
    centre of mass above its rest height: the rigid body's, above the lowest point of its
    base outline) of the trajectory's first body."""

    turns = rotations(trajectory.quat[:, 0])
    start = Rotation.from_matrix(np.asarray(body["rotation"], float))
    theta = (turns * start.inv()).as_rotvec() @ line["axis"]
    points = base_points(body)
    lowest = lambda r: (r.as_matrix()[..., 2, :] @ points.T).min(axis=-1)   # noqa: E731
    return turns, theta, float(lowest(start)) - lowest(turns)


def _energy_above_rest(trajectory, body, turns, rise, gravity):
    """The first body's whole energy above rest (J) at each sample: translation, rotation,
    rise."""
    inertia_world = turns.as_matrix() @ np.asarray(body["inertia"], float) @ \
        turns.as_matrix().transpose(0, 2, 1)
    w = trajectory.angvel[:, 0]
    return body["mass"] * (0.5 * (trajectory.vel[:, 0] ** 2).sum(axis=1) +
                           gravity * rise) + \
        0.5 * np.einsum("ti,tij,tj->t", w, inertia_world, w)


def specimen_measure(geometry, kn, azimuth_deg, cache=CACHE, **options):
    """:func:`cached_measure` of the specimen's restitution: the median of
    :func:`specimen_rocking` over the releases SPECIMEN_RELEASES (a rock's single
    releases scatter; key: the description's content, azimuth, kn, options)."""

    key = content_hash(geometry.to_dict(), azimuth_deg, kn, SPECIMEN_RELEASES, IMPACTS,
                       options)
    return cached_measure(lambda damping: statistics.median(
        specimen_rocking(geometry, damping, kn, azimuth_deg, release_ratio=ratio,
                         **options)["restitution"] for ratio in SPECIMEN_RELEASES),
        f"specimen {key}", cache)
