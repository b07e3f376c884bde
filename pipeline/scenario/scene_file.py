"""The scene file ``params.json``: everything yade_scripts/column_scene.py uses, typed.

One writer (:meth:`SceneFile.write`, atomic) and one reader (:meth:`SceneFile.read`).
The scene itself runs under Debian's python3 without this package and reads the same
file as plain JSON (the keys are the field names below); it holds no physics constant:
gravity, the stop checks' thresholds and the clump model's sizes come from here.

A column's entry (:class:`SceneColumn`, one :class:`SceneBody` per rigid body) is
written by the specimen it places (:meth:`pipeline.scenario.specimen.Specimen.scene_column`).
"""
import dataclasses
import json
from dataclasses import dataclass, field

from pipeline.constants import (
    LIES_AXIS_Z,
    LIES_PAST_CRITICAL_DEG,
    LIES_TILT_DEG,
    MODEL_GRAVITY,
    STANDS_AXIS_Z,
)
from pipeline.files import write_json
from pipeline.outcome.damage import rim_face_points
import numpy as np
from scipy.spatial.transform import Rotation

FILE_NAME = "params.json"


@dataclass(frozen=True)
class SceneBody:
    """A rigid body of the scene (lengths m, mass kg; body frame about its centre of
    mass).  ``inertia``: 3 x 3 in the body frame; ``principal_axes``: its eigenvectors
    (columns); ``centre``, ``rotation``: world placement (body -> world); ``rims``: the
    outlines that carry contact spheres ({role base|edge, kind circle|polygon|points,
    ...}); ``plate``: the top face a body above stands on ({centre, half_size}) or None;
    ``overturn_tilt_deg``: a mesh specimen's critical angle (None for blocks);
    ``rests_on``: a colonnade's beam's supports (names; None for a column's bodies)."""
    name: str
    column: str
    index: int
    block_name: str
    blocks: list
    shape: str
    height: float
    mass: float
    inertia: list
    principal_axes: list
    centre: list
    rotation: list
    column_position: list
    parts: list
    rims: list
    plate: dict = None
    overturn_tilt_deg: float = None
    rests_on: list = None


@dataclass(frozen=True)
class SceneColumn:
    """A column placed on the pedestal (position m): its bodies, bottom up, and its
    statics: rocking threshold / g (``uplift_ratio``), smallest rocking lever (m), the
    smallest energy (J) that tips a stack over (None: never stop on energy), whether
    the scene may stop once no stack can tip (``settles``) and, for a beam of a
    colonnade, the columns or beams whose top plates it rests on (``rests_on``)."""
    name: str
    kind: str
    x: float
    y: float
    description: str
    height: float
    n_bodies: int
    uplift_ratio: float
    rocking_lever_m: float
    overturning_barrier_j: float
    settles: bool
    bodies: list            # of SceneBody
    rests_on: list = field(default_factory=list)

    def to_dict(self):
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class Thresholds:
    """The scene's stop checks: a body stands while its axis points up at least
    ``stands_axis_z``, lies below ``lies_axis_z`` (a mesh specimen once tilted
    ``lies_past_critical_deg`` past its critical angle, at most ``lies_tilt_deg``); a
    still column whose energy is below ``settled_fraction`` of its barrier cannot tip; a
    body is seated within ``seated_fraction`` of its column's rocking lever; friction
    switches to kinetic at ``stick_fraction`` of the static limit and back below
    ``slide_fraction`` of the kinetic; the stop checks run every ``stop_interval_s``."""
    stands_axis_z: float = STANDS_AXIS_Z
    lies_axis_z: float = LIES_AXIS_Z
    lies_tilt_deg: float = LIES_TILT_DEG
    lies_past_critical_deg: float = LIES_PAST_CRITICAL_DEG
    settled_fraction: float = 0.9
    seated_fraction: float = 0.02
    stick_fraction: float = 0.999
    slide_fraction: float = 0.99
    stop_interval_s: float = 0.1


@dataclass(frozen=True)
class ClumpModel:
    """How a body becomes a YADE clump: the top plate's half thickness (m); a tiny dense
    core sphere at the centre of mass (radius m, density kg/m^3) that puts the clump's
    reference point there; "frame" spheres along the principal axes (arm, radius m) for
    bodies whose members do not fix the principal frame; the rim spheres' material
    density (kg/m^3, their mass is overridden); the largest off-diagonal inertia, as a
    fraction of the largest moment, of a clump frame taken as principal."""
    plate_half_thickness_m: float = 0.005
    core_radius_m: float = 1e-3
    core_density_kg_m3: float = 1e20
    frame_arm_m: float = 0.01
    frame_radius_m: float = 2e-4
    member_density_kg_m3: float = 1e-3
    principal_tolerance: float = 1e-3


@dataclass(frozen=True)
class Measurement:
    """What the scene measures of itself besides the trajectory (make bench): with a file
    name, the simulation loop's wall and CPU time (s, ``loop_clock_file``: JSON
    loop_wall_s, loop_cpu_s) and YADE's engine timing (``engine_timing_file``: per
    engine exec_ns, count, dead; its table printed to the log)."""
    loop_clock_file: str = None
    engine_timing_file: str = None


@dataclass(frozen=True)
class SceneFile:
    """The content of ``params.json``.  ``columns``: the columns' entries
    (:meth:`SceneColumn.to_dict`); ``block``: the verification block's parameters or
    None; ``contact``, ``numerics``: the :class:`~pipeline.scenario.parameters.Contact`
    and :class:`~pipeline.scenario.parameters.Numerics` as dicts; ``pedestal``:
    thickness, size, mass, contact_half_size (m, kg); ``dt_factor`` and ``time_step_s``
    (s): the step used; ``t_max`` (s, the motion's clock): simulated time at most;
    ``gravity`` (m/s^2); ``motion_file``: the motion npz beside it (None: no motion);
    ``start_s``, ``quiet_after_s``, ``signal_end_s`` (s, the motion's clock): where the
    scene starts, after which every seated body may stop it, where the signal ends;
    ``early_stop`` False: simulate to ``t_max`` whatever the bodies do (the stop checks
    see the motion last until then)."""
    columns: list
    block: dict
    contact: dict
    numerics: dict
    pedestal: dict
    dt_factor: float
    time_step_s: float
    t_max: float
    gravity: float = MODEL_GRAVITY
    thresholds: Thresholds = field(default_factory=Thresholds)
    clump: ClumpModel = field(default_factory=ClumpModel)
    motion_file: str = None
    output: str = "trajectory.npz"
    start_s: float = 0.0
    quiet_after_s: float = None
    signal_end_s: float = None
    early_stop: bool = True
    measure: Measurement = field(default_factory=Measurement)

    def to_dict(self):
        return dataclasses.asdict(self)

    def write(self, run_dir):
        """Write ``run_dir/params.json`` atomically; return its path."""
        path = run_dir / FILE_NAME
        write_json(path, self.to_dict())
        return path

    @classmethod
    def from_dict(cls, data):
        return cls(**dict(data, thresholds=Thresholds(**data["thresholds"]),
                          clump=ClumpModel(**data["clump"]),
                          measure=Measurement(**data["measure"])))

    @classmethod
    def read(cls, run_dir):
        """The scene file of ``run_dir``."""
        return cls.from_dict(json.loads((run_dir / FILE_NAME).read_text()))


def base_points(body, circle_points=720):
    """Points (n, 3; m, body frame about the centre of mass) of the outline a scene body
    (a :class:`SceneBody` as a dict) stands on: its base rim, in the rim's face."""
    rim = next(r for r in body["rims"] if r["role"] == "base")
    return rim_face_points(rim, circle_points, polygon="points")


def support_line(column, azimuth_deg):
    """Where a scene column (a :class:`SceneColumn` as a dict) tips toward ``azimuth_deg``
    (deg clockwise from North): dict pivot (3,) (the point of its bottom body's base
    outline farthest that way, world m), axis (3,) (horizontal, across the azimuth: a
    positive rotation about it leans the column that way), com (3,) (the column's centre
    of mass, world m), critical_angle_rad (the tilt about that line at which the centre
    of mass stands above it)."""
    a = np.radians(azimuth_deg)
    u = np.array([np.sin(a), np.cos(a), 0.0])
    bottom = column["bodies"][0]
    world = np.asarray(bottom["centre"], float) + \
        base_points(bottom) @ np.asarray(bottom["rotation"], float).T
    pivot = world[np.argmax(world @ u)]
    masses = np.array([b["mass"] for b in column["bodies"]])
    com = masses @ np.array([b["centre"] for b in column["bodies"]], float) / masses.sum()
    lever, height = float((pivot - com) @ u), float(com[2] - pivot[2])
    return {"pivot": pivot, "axis": np.cross([0.0, 0.0, 1.0], u), "com": com,
            "critical_angle_rad": float(np.arctan2(lever, height))}


def released(column, azimuth_deg, tilt_rad):
    """The scene column (dict) turned rigidly by ``tilt_rad`` about its support line
    toward ``azimuth_deg`` (:func:`support_line`): a free-rocking release from rest, on
    the edge of its footprint.  It never stops on energy (``settles`` False: it is
    raised above its rest)."""
    line = support_line(column, azimuth_deg)
    turn = Rotation.from_rotvec(line["axis"] * tilt_rad).as_matrix()
    pivot = line["pivot"]
    bodies = [dict(b, centre=(pivot + turn @ (np.asarray(b["centre"], float) - pivot)).tolist(),
                   rotation=(turn @ np.asarray(b["rotation"], float)).tolist())
              for b in column["bodies"]]
    return dict(column, bodies=bodies, settles=False)
