"""Per-column outcome of a :class:`~pipeline.outcome.Trajectory`: toppled or not,
impact time, impact points and downfall azimuth.

All positions are in the pedestal frame (pedestal top face z = 0, metres).
A column has toppled when one of its bodies struck the pedestal other than
by its base: any rim of a body above the bottom one, or any rim of the bottom
body but its base (the top rim of a drum or monolith; a capital's abacus
edge on a monolith of that outline).  A body tilted past 90 deg that struck
nothing (upside down, or thrown off the pedestal), or still tilted past 60 deg when the
scene stopped (the scene takes it as lying and stops without waiting for its strike),
has toppled too: a column is
never "standing" then, whatever the input; its azimuth is that of the body's
axis when it passed 90 deg (``toppled_by`` says which rule decided).  A mesh specimen
(a scanned rock, whose hull points near its footprint touch the table while it rocks)
has overturned when it ends tilted past its critical angle (``overturn_tilt_deg``: it no
longer stands on its footprint); its "impact" is the time from which it stayed past
that angle and its azimuth that of its centre of mass's displacement.  Rims are the outlines a body carries
contact spheres on (``bodies[].rims`` of the trajectory, body frame about the
centre of mass: circles and polygons).  The downfall azimuth points from the
column's initial axis to the mass-weighted mean of the centres of mass of
the struck bodies at their first strike (clockwise from North, degrees).
"""

import numpy as np
from scipy.spatial.transform import Rotation

from pipeline.constants import LIES_TILT_DEG, MODEL_GRAVITY
from pipeline.motion import azimuth_deg
from pipeline.outcome.colonnade import ColonnadeOutcome
from pipeline.outcome.damage import column_damage
from pipeline.outcome.summary import ColumnOutcome, RunSummary

CONTACT_TOLERANCE_M = 0.02   # a rim this close to the pedestal top has struck it


def body_axes(quat):
    """Unit long axes (..., 3) of bodies from quaternions (..., 4) ordered (w, x, y, z)."""
    q = np.asarray(quat, float)
    return rotations(q).apply([0.0, 0.0, 1.0]).reshape(q.shape[:-1] + (3,))


def rotations(quat):
    """scipy Rotation of quaternions (..., 4) ordered (w, x, y, z), flattened."""
    return Rotation.from_quat(np.asarray(quat, float).reshape(-1, 4)[:, [1, 2, 3, 0]])


def rotation_from_start_deg(trajectory):
    """Largest rotation (deg) of any body away from where it was placed (its
    ``initial_rotation``) over the whole trajectory."""
    return float(max(np.degrees((Rotation.from_matrix(body["initial_rotation"]).inv()
                                 * rotations(trajectory.quat[:, j])).magnitude()).max()
                     for j, body in enumerate(trajectory.bodies)))


def body_rims(body):
    """Rims of a trajectory body in its frame about the centre of mass: dicts with role
    ("base" or "edge"), z, and kind "circle" (radius, centre) or "polygon" (vertices).
    Trajectories written before column files carry cylinders and boxes instead."""
    if "rims" in body:
        return body["rims"]
    h = body["height"] / 2
    if body["shape"] == "cylinder":
        face = {"kind": "circle", "radius": body["radius"], "centre": [0.0, 0.0]}
    else:
        w, d = body["width"] / 2, body["depth"] / 2
        face = {"kind": "polygon", "vertices": [[-w, -d], [w, -d], [w, d], [-w, d]]}
    return [dict(face, role="base", z=-h), dict(face, role="edge", z=h)]


def rim_lowest(pos, quat, rim, axis=None):
    """Lowest z (m, per sample) of one rim of a body at positions ``pos`` (n x 3) and
    orientations ``quat`` (n x 4, w x y z)."""
    axis = body_axes(quat) if axis is None else axis
    az = np.clip(axis[..., 2], -1.0, 1.0)
    if rim["kind"] == "circle":
        low = pos[..., 2] + rim["z"] * az - rim["radius"] * np.sqrt(1.0 - az ** 2)
        cx, cy = rim["centre"]
        if cx or cy:
            row = rotations(quat).as_matrix()[:, 2, :]
            low = low + row[:, 0] * cx + row[:, 1] * cy
        return low
    row = rotations(quat).as_matrix()[:, 2, :]
    v = np.asarray(rim["vertices"], float)
    heights = row[:, :2] @ v.T + (row[:, 2] * rim["z"])[:, None]
    return pos[..., 2] + heights.min(axis=1)


def stays_past(tilt, limit_deg):
    """[index of the first sample of the final stretch of ``tilt`` (deg) above
    ``limit_deg``], or an empty array when the last sample is not above it."""
    if tilt[-1] <= limit_deg:
        return np.array([], int)
    below = np.flatnonzero(tilt <= limit_deg)
    return np.array([below[-1] + 1 if below.size else 0])


def tilt_deg(axis):
    return np.degrees(np.arccos(np.clip(axis[..., 2], -1.0, 1.0)))


def column_outcomes(trajectory, start_in_file_s=0.0):
    """List of per-column result dicts (see module docstring), times (s) on the record's
    clock: the trajectory's (the motion's) clock + ``start_in_file_s``."""
    t = trajectory.t + start_in_file_s
    axes = body_axes(trajectory.quat)
    columns = {}
    for j, body in enumerate(trajectory.bodies):
        columns.setdefault(body["column"], []).append(j)
    results = []
    for name, members in columns.items():
        first = trajectory.bodies[members[0]]
        origin = np.array(first.get("column_position", first["initial_pos"][:2]), float)
        bodies = [entry for j in members
                  if (entry := _body_outcome(trajectory, j, t, axes, origin)) is not None]
        if bodies:
            result = _column_outcome(name, bodies, trajectory.pos[:, members[0], :2],
                                     first, origin)
            result["damage"] = None if first.get("rests_on") is not None else \
                _damage(trajectory, members, result["toppled"]).to_dict()   # not for beams
            results.append(result)
    return results


def _damage(trajectory, members, toppled):
    """The column's :class:`~pipeline.outcome.damage.DamageMeasures` (its bodies
    ``members``, bottom up)."""
    members = sorted(members, key=lambda j: trajectory.bodies[j]["index"])
    bodies = [trajectory.bodies[j] for j in members]
    return column_damage(trajectory.pos[:, members], trajectory.quat[:, members], bodies,
                         [body_rims(b) for b in bodies], toppled)


def _body_outcome(trajectory, j, t, axes, origin):
    """Body ``j``'s result dict (see module docstring), or None for a body with nothing
    to strike with (the base block's base rim does not count)."""
    pos = trajectory.pos
    b = trajectory.bodies[j]
    rims = [r for r in body_rims(b) if b["index"] > 0 or r["role"] != "base"]
    critical = b.get("overturn_tilt_deg")      # a mesh specimen (see module doc)
    if not rims and critical is None:
        return None
    tilt = tilt_deg(axes[:, j])
    if critical is None:
        struck = np.min([rim_lowest(pos[:, j], trajectory.quat[:, j], r, axes[:, j])
                         for r in rims], axis=0)
        hits = np.flatnonzero(struck <= CONTACT_TOLERANCE_M)
    else:
        hits = stays_past(tilt, critical)
    over = np.flatnonzero(tilt > 90.0)
    lying = not over.size and tilt[-1] > LIES_TILT_DEG    # the scene stopped it lying
    if lying:
        over = stays_past(tilt, LIES_TILT_DEG)
    entry = {"index": b["index"], **({"name": b["block_name"]} if b.get("block_name")
                                     else {}),
             "mass_kg": b["mass"], "struck": bool(hits.size),
             "impact_time_s": None, "impact_point_m": None, "azimuth_deg": None,
             "max_tilt_deg": float(tilt.max()),
             "final_position_m": (pos[-1, j, :2] - origin).round(4).tolist(),
             "past_90_s": float(t[over[0]]) if over.size else None,
             "lying_at_end": bool(lying),
             "past_90_azimuth_deg": azimuth_deg(*axes[over[0], j, :2])
             if over.size else None}
    if hits.size:
        k = hits[0]
        point = pos[k, j, :2] - origin
        if critical is not None:              # where its centre of mass went
            point = pos[-1, j, :2] - np.asarray(b["initial_pos"][:2], float)
        entry.update(impact_time_s=float(t[k]), impact_point_m=point.tolist(),
                     azimuth_deg=azimuth_deg(*point))
    return entry


def _column_outcome(name, bodies, base_xy, first, origin):
    """A column's result dict from its bodies' (``base_xy``: its first body's horizontal
    path, (n, 2) m; ``first``: that body's trajectory entry)."""
    struck = [b for b in bodies if b["struck"]]
    upset = [b for b in bodies if b["past_90_s"] is not None]
    result = {"column": name, "toppled": bool(struck or upset),
              "toppled_by": ("rests past its critical angle" if struck and
                             first.get("overturn_tilt_deg") is not None else
                             "impact" if struck else None),
              "downfall_azimuth_deg": None,
              "impact_time_s": None, "impact_point_m": None,
              "max_tilt_deg": max(b["max_tilt_deg"] for b in bodies),
              "base_slip_m": float(np.hypot(*(base_xy - first["initial_pos"][:2]).T).max()),
              "position_m": origin.tolist(), "bodies": bodies}
    if upset and not struck:
        result["toppled_by"] = ("tilt past 90 deg" if any(not b["lying_at_end"]
                                                         for b in upset)
                                else "lying past 60 deg when the run stopped")
    if struck:
        weights = np.array([b["mass_kg"] for b in struck])
        points = np.array([b["impact_point_m"] for b in struck])
        centre = weights @ points / weights.sum()
        result.update(downfall_azimuth_deg=azimuth_deg(*centre),
                      impact_time_s=min(b["impact_time_s"] for b in struck),
                      impact_point_m=centre.tolist())
    elif upset:          # thrown over without striking the pedestal: never "standing"
        first_over = min(upset, key=lambda b: b["past_90_s"])
        result.update(downfall_azimuth_deg=first_over["past_90_azimuth_deg"],
                      impact_time_s=first_over["past_90_s"])
    return result


def total_energy(trajectory, g=MODEL_GRAVITY):
    """Kinetic + potential energy (J) of all bodies per sample, in the pedestal frame
    (meaningful for a still pedestal)."""
    energy = np.zeros(len(trajectory.t))
    for j, b in enumerate(trajectory.bodies):
        m, h = b["mass"], b["height"]
        if "inertia" in b:
            inertia = np.asarray(b["inertia"], float)
        elif b["shape"] == "cylinder":
            r = b["radius"]
            inertia = np.diag([m * (3 * r * r + h * h) / 12] * 2 + [m * r * r / 2])
        else:
            w, d = b["width"], b["depth"]
            inertia = np.diag(m / 12 * np.array([d * d + h * h, w * w + h * h, w * w + d * d]))
        omega_body = rotations(trajectory.quat[:, j]).inv().apply(trajectory.angvel[:, j])
        energy += (0.5 * m * (trajectory.vel[:, j] ** 2).sum(axis=1)
                   + 0.5 * np.einsum("ni,ij,nj->n", omega_body, inertia, omega_body)
                   + m * g * trajectory.pos[:, j, 2])
    return energy


def summarise(trajectory, record, back_azimuth_deg=None, parameters=None, provenance=None,
              quiet_after_s=None, start_in_file_s=0.0, colonnade=None):
    """The :class:`~pipeline.outcome.summary.RunSummary` of a simulated run, its times on
    the record's clock: the trajectory's clock (and ``quiet_after_s``'s, the scene's) +
    ``start_in_file_s`` (s, the record time of the motion's first sample); ``colonnade``:
    the name of the colonnade the scene holds (its per-colonnade outcome), or None."""
    offset = float(start_in_file_s)
    columns = [ColumnOutcome(**c) for c in column_outcomes(trajectory, offset)]
    beams = {b["column"] for b in trajectory.bodies if b.get("rests_on") is not None}
    whole = None if colonnade is None else ColonnadeOutcome.of(
        colonnade, [c for c in columns if c.column not in beams],
        [c for c in columns if c.column in beams])
    end = float(trajectory.t[-1]) if len(trajectory.t) else trajectory.start_s
    return RunSummary(
        record=record, back_azimuth_deg=back_azimuth_deg, parameters=parameters or {},
        columns=columns, colonnade=whole,
        simulated_s=trajectory.simulated_s,
        simulated_window_s=[trajectory.start_s + offset, end + offset],
        motion_end_s=trajectory.motion_end + offset,
        stopped_early=bool(trajectory.stopped_early),
        time_step_s=trajectory.dt, wall_s=trajectory.wall_s, provenance=provenance or {},
        quiet_after_s=None if quiet_after_s is None else quiet_after_s + offset,
        start_in_file_s=offset)
