"""Damage measures of a column's run and the damage states they give.

Three measures per column (lengths m, angles deg; positions in the pedestal frame):

- the peak capital displacement: the largest horizontal displacement, over the run, of
  the centre of the column's top face (its top body's highest rim) from where it was
  placed, and the same over the base width ``D`` (twice the smallest distance from the
  base face's centre to its outline's edges: the diameter of a drum, the smaller side of
  a block);
- the residual dislocation of each joint at the end of the run: the horizontal slide of
  the upper body's base-face centre, and its rotation about the vertical (twist), both
  relative to the body below (the pedestal for the bottom body) and expressed in that
  body's frame, so that a column leaning as one rigid piece shows none;
- the largest rotation over the critical angle, theta_max / alpha: theta the angle by
  which any of the column's bodies turned its vertical away from the vertical (from its
  placement), alpha the column's critical angle, the smallest over its stacks of
  atan(lever / height) of the stack's centre of mass over the edge of the face it stands
  on (atan of the column's uplift ratio; a mesh specimen's ``overturn_tilt_deg``).

The states (:class:`DamageState`) and their limits (:data:`LEVELS`) are set out in
docs/damage.md.
"""
import enum
import math
from dataclasses import dataclass, fields

import numpy as np
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from pipeline.files import InputError, finite_number

CIRCLE_POINTS = 360          # points on a circular face's outline


class DamageState(enum.IntEnum):
    """A column's damage state: how many limits of a measure it passed, or collapse."""
    NONE = 0
    SLIGHT = 1
    MODERATE = 2
    SEVERE = 3
    COLLAPSE = 4

    @property
    def label(self):
        return self.name.lower()

    @classmethod
    def of(cls, value, limits):
        """The state of a measure ``value`` (None: not known) against three ``limits``."""
        return None if value is None else cls(int(np.searchsorted(limits, value, "right")))


@dataclass(frozen=True)
class DamageLevels:
    """The limits (slight, moderate, severe) of each measure (docs/damage.md):
    ``capital`` on the peak capital displacement over the base width, ``residual`` on
    the largest residual slide of a joint over the base width, ``rotation`` on
    theta_max / alpha."""
    capital: tuple = (0.1, 0.35, 0.7)
    residual: tuple = (0.005, 0.025, 0.1)
    rotation: tuple = (0.1, 0.35, 0.7)


LEVELS = DamageLevels()


def _number(value, name, minimum=0.0, allow_none=False):
    if value is None and not allow_none:
        raise InputError(f"damage: {name} must be a number, got None")
    return finite_number(value, f"damage: {name}", minimum)


@dataclass(frozen=True, kw_only=True)
class JointDislocation:
    """The residual dislocation of one joint: ``lower`` (a body's name, or "pedestal")
    under ``upper``; ``slide_m`` the horizontal slide (m) and ``twist_deg`` the rotation
    about the vertical (deg, counter-clockwise seen from above, in (-180, 180]) of the
    upper body against the lower since the start."""
    lower: str
    upper: str
    slide_m: float
    twist_deg: float

    def __post_init__(self):
        object.__setattr__(self, "slide_m", _number(self.slide_m, "slide_m"))
        twist = _number(self.twist_deg, "twist_deg", minimum=-180.0)
        if twist > 180.0:
            raise InputError(f"damage: twist_deg {twist:g} not in (-180, 180]")
        object.__setattr__(self, "twist_deg", twist)


@dataclass(frozen=True, kw_only=True)
class DamageMeasures:
    """A column's damage measures (module docstring): ``peak_capital_displacement_m``,
    ``base_width_m`` (D), ``max_rotation_deg`` (theta_max), ``critical_angle_deg``
    (alpha, from the placement: for a block released tilted the angle left to tip; None
    when a stack's centre of mass is not above its face), one :class:`JointDislocation` per
    joint bottom up, and whether the column ``toppled`` (its state is then collapse)."""
    peak_capital_displacement_m: float
    base_width_m: float
    max_rotation_deg: float
    critical_angle_deg: float
    joints: tuple
    toppled: bool

    DERIVED = ("capital_displacement_ratio", "rotation_ratio", "max_residual_slide_m",
               "max_residual_twist_deg", "capital_state", "residual_state",
               "rotation_state", "damage_state")

    def __post_init__(self):
        object.__setattr__(self, "peak_capital_displacement_m", _number(
            self.peak_capital_displacement_m, "peak_capital_displacement_m"))
        if _number(self.base_width_m, "base_width_m") <= 0.0:
            raise InputError(f"damage: base_width_m must be > 0, got {self.base_width_m!r}")
        object.__setattr__(self, "max_rotation_deg", _number(self.max_rotation_deg,
                                                             "max_rotation_deg"))
        alpha = _number(self.critical_angle_deg, "critical_angle_deg", allow_none=True)
        if alpha is not None and alpha <= 0.0:
            raise InputError(f"damage: critical_angle_deg must be > 0, got {alpha:g}")
        object.__setattr__(self, "joints", tuple(
            j if isinstance(j, JointDislocation) else JointDislocation(**j)
            for j in self.joints))
        if not isinstance(self.toppled, bool):
            raise InputError("damage: toppled must be true or false")

    @property
    def capital_displacement_ratio(self):
        return self.peak_capital_displacement_m / self.base_width_m

    @property
    def rotation_ratio(self):
        """theta_max / alpha (None without a critical angle)."""
        if self.critical_angle_deg is None:
            return None
        return self.max_rotation_deg / self.critical_angle_deg

    @property
    def max_residual_slide_m(self):
        return max((j.slide_m for j in self.joints), default=0.0)

    @property
    def max_residual_twist_deg(self):
        return max((abs(j.twist_deg) for j in self.joints), default=0.0)

    def _state(self, value, limits):
        return DamageState.COLLAPSE if self.toppled else DamageState.of(value, limits)

    @property
    def capital_state(self):
        return self._state(self.capital_displacement_ratio, LEVELS.capital)

    @property
    def residual_state(self):
        return self._state(self.max_residual_slide_m / self.base_width_m, LEVELS.residual)

    @property
    def rotation_state(self):
        return self._state(self.rotation_ratio, LEVELS.rotation)

    @property
    def damage_state(self):
        """The worst of the three states."""
        return max(s for s in (self.capital_state, self.residual_state,
                               self.rotation_state) if s is not None)

    def to_dict(self):
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["joints"] = [{f.name: getattr(j, f.name) for f in fields(j)} for j in self.joints]
        for name in self.DERIVED:
            value = getattr(self, name)
            out[name] = value.label if isinstance(value, DamageState) else value
        return out

    @classmethod
    def from_dict(cls, data):
        """The measures of a ``to_dict`` (its derived values are recomputed)."""
        if not isinstance(data, dict):
            raise InputError("damage: not a mapping")
        unknown = set(data) - {f.name for f in fields(cls)} - set(cls.DERIVED)
        if unknown:
            raise InputError(f"damage: unknown keys {', '.join(sorted(unknown))}")
        return cls(**{f.name: data[f.name] for f in fields(cls) if f.name in data})


# ---------------------------------------------------------------- geometry of the rims
def rim_face_points(rim, circle_points=CIRCLE_POINTS, polygon="vertices"):
    """Points (n, 3; m, body frame) of a rim's outline in its face: a points rim's points,
    ``circle_points`` on a circle, a polygon's "vertices" or its perimeter "points"
    (``polygon``)."""
    if rim["kind"] == "points":
        return np.asarray(rim["points"], float)
    if rim["kind"] == "circle":
        angle = 2 * np.pi * np.arange(circle_points) / circle_points
        xy = rim["radius"] * np.column_stack([np.cos(angle), np.sin(angle)]) + rim["centre"]
    else:
        xy = np.asarray(rim[polygon], float)
    n = np.asarray(rim.get("normal", (0.0, 0.0, 1.0)), float)
    return np.column_stack([xy, rim["z"] - (n[0] * xy[:, 0] + n[1] * xy[:, 1]) / n[2]])


def rim_centre(rim):
    """Centre (3,; m, body frame) of a rim's face: its circle's centre, its vertices'
    mean, or for points their mean across and their highest or lowest along z."""
    points = rim_face_points(rim)
    centre = points.mean(axis=0)
    if rim["kind"] == "points":
        centre[2] = points[:, 2].max() if rim["role"] != "base" else points[:, 2].min()
    elif rim["kind"] == "circle":
        n = np.asarray(rim.get("normal", (0.0, 0.0, 1.0)), float)
        cx, cy = rim["centre"]
        centre = np.array([cx, cy, rim["z"] - (n[0] * cx + n[1] * cy) / n[2]])
    return centre


def inside_distance(outline_xy, point_xy):
    """Smallest distance (m) from ``point_xy`` to the edges of the convex hull of
    ``outline_xy`` (negative outside)."""
    hull = ConvexHull(np.asarray(outline_xy, float))
    return float(-(hull.equations[:, :2] @ np.asarray(point_xy, float)
                   + hull.equations[:, 2]).max())


def base_rim(rims):
    return next(r for r in rims if r["role"] == "base")


def face_lever(rim, centre, rotation, point_xy):
    """Smallest horizontal distance (m) from ``point_xy`` to the edge of a rim's face
    placed at ``centre`` (3,), ``rotation`` (3, 3) (negative outside): exact for a level
    circle, else to its outline's convex hull."""
    if rim["kind"] == "circle" and abs(rotation[2, 2]) == 1.0 and \
            np.allclose(rim.get("normal", (0.0, 0.0, 1.0))[:2], 0.0, atol=0.0):
        middle = centre + rotation @ rim_centre(rim)
        return rim["radius"] - math.dist(middle[:2], point_xy)
    face = centre + rim_face_points(rim) @ rotation.T
    return inside_distance(face[:, :2], point_xy)


def base_width_m(rims):
    """D (m): twice the smallest distance from the base face's centre to its edges."""
    rim = base_rim(rims)
    return 2.0 * face_lever(rim, np.zeros(3), np.eye(3), rim_centre(rim)[:2])


def critical_angle_deg(bodies, rims, centres, rotations):
    """alpha (deg) of a column placed at ``centres`` (nb, 3), ``rotations`` (nb, 3, 3),
    bodies bottom up: the smallest over its stacks of atan(lever / height) of the
    stack's centre of mass over its bottom body's base face; a mesh specimen's
    ``overturn_tilt_deg``; None when a stack's centre of mass is not above its face."""
    if bodies[0].get("overturn_tilt_deg") is not None:
        return float(bodies[0]["overturn_tilt_deg"])
    masses = np.array([b["mass"] for b in bodies], float)
    angles = []
    for k in range(len(bodies)):
        rim = base_rim(rims[k])
        face = centres[k] + rim_face_points(rim) @ rotations[k].T
        com = masses[k:] @ centres[k:] / masses[k:].sum()
        lever = face_lever(rim, centres[k], rotations[k], com[:2])
        height = com[2] - face[:, 2].mean()
        if lever <= 0.0 or height <= 0.0:
            return None
        angles.append(math.atan2(lever, height))
    return math.degrees(min(angles))


def _matrices(quat):
    """(n, 3, 3) rotation matrices of quaternions (n, 4) ordered (w, x, y, z)."""
    return Rotation.from_quat(np.asarray(quat, float)[:, [1, 2, 3, 0]]).as_matrix()


def _twist_deg(matrix):
    """Rotation (deg, in (-180, 180]) about z of the twist part of a rotation matrix."""
    x, y, z, w = Rotation.from_matrix(matrix).as_quat()
    twist = (math.degrees(2.0 * math.atan2(z, w)) + 180.0) % 360.0 - 180.0
    return 180.0 if twist == -180.0 else twist


def joint_dislocations(bodies, rims, start, end):
    """One :class:`JointDislocation` per joint, bottom up (the bottom body on the
    pedestal first), between the placement ``start`` and the pose ``end``: each a pair
    (centres (nb, 3), rotations (nb, 3, 3)) in the pedestal frame."""
    out = []
    for k, body in enumerate(bodies):
        point = rim_centre(base_rim(rims[k]))

        def relative(pose):
            centres, rot = pose
            lower_c, lower_r = (np.zeros(3), np.eye(3)) if k == 0 else (centres[k - 1],
                                                                      rot[k - 1])
            return (lower_r.T @ (centres[k] + rot[k] @ point - lower_c),
                    lower_r.T @ rot[k])
        (v0, r0), (v1, r1) = relative(start), relative(end)
        shift = v1 - v0
        out.append(JointDislocation(
            lower="pedestal" if k == 0 else body_name(bodies[k - 1]),
            upper=body_name(body), slide_m=float(math.hypot(shift[0], shift[1])),
            twist_deg=_twist_deg(r1 @ r0.T)))
    return out


def body_name(body):
    return body.get("name") or f"{body['column']}[{body['index']}]"


def column_damage(pos, quat, bodies, rims, toppled):
    """The :class:`DamageMeasures` of a column from its bodies' path (bottom up):
    ``pos`` (n, nb, 3) m and ``quat`` (n, nb, 4, w x y z) in the pedestal frame,
    ``bodies`` the trajectory's entries (``initial_pos``, ``initial_rotation``: the
    placement), ``rims`` each body's rims (body frame about its centre of mass)."""
    centres = np.array([b["initial_pos"] for b in bodies], float)
    rot0 = np.array([b.get("initial_rotation", np.eye(3)) for b in bodies], float)
    paths = [_matrices(quat[:, j]) for j in range(len(bodies))]
    # theta: the body's turn of the vertical away from the vertical, since its placement
    theta = max(float(np.degrees(np.arccos(np.clip((r @ r0.T)[:, 2, 2], -1.0, 1.0))).max())
                for r, r0 in zip(paths, rot0))
    top_rims = rims[-1]
    top = max((rim_centre(r) for r in top_rims), key=lambda c: c[2])
    path = pos[:, -1] + paths[-1] @ top
    shift = path - (centres[-1] + rot0[-1] @ top)
    end = (np.asarray(pos[-1], float), np.array([r[-1] for r in paths]))
    return DamageMeasures(
        peak_capital_displacement_m=float(np.hypot(shift[:, 0], shift[:, 1]).max()),
        base_width_m=base_width_m(rims[0]), max_rotation_deg=theta,
        critical_angle_deg=critical_angle_deg(bodies, rims, centres, rot0),
        joints=tuple(joint_dislocations(bodies, rims, (centres, rot0), end)),
        toppled=bool(toppled))


def damage_at_rest(bodies):
    """The :class:`DamageMeasures` of a column that never moved (``bodies``: its scene
    bodies, placed by ``centre`` and ``rotation``): all zero."""
    placed = [dict(b, initial_pos=b["centre"], initial_rotation=b["rotation"]) for b in bodies]
    quat = Rotation.from_matrix([b["rotation"] for b in bodies]).as_quat()[:, [3, 0, 1, 2]]
    pos = np.array([b["centre"] for b in bodies], float)
    return column_damage(pos[None], quat[None], placed, [b["rims"] for b in bodies], False)
