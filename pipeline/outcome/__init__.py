"""Outcome stage: a YADE :class:`Trajectory` and what it says per column
(toppled, downfall azimuth, impact time and points): :mod:`pipeline.outcome.columns`."""
import json
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Trajectory:
    """Bodies' motion written by the YADE scene (``trajectory.npz``), pedestal frame.

    t (n,) s; pedestal_disp (n, 3) m; pos, vel (n, nb, 3) m, m/s; angvel (n, nb, 3)
    rad/s; quat (n, nb, 4) ordered (w, x, y, z); bodies: one dict per body (shape,
    column, index, height, radius or width/depth, mass, initial_pos); dt: time step
    (s); motion_end: end of the ground motion (s); start_s: time on the motion's clock at
    which the simulation started (after a skipped quiet lead-in; t is on that clock);
    wall_s: wall-clock time of the run.
    """
    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    bodies: list
    vel: np.ndarray = None
    angvel: np.ndarray = None
    pedestal_disp: np.ndarray = None
    dt: float = 0.0
    motion_end: float = 0.0
    stopped_early: bool = False
    start_s: float = 0.0
    wall_s: float = None
    extra: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.vel is None:
            self.vel = np.zeros_like(self.pos)
        if self.angvel is None:
            self.angvel = np.zeros_like(self.pos)
        if self.pedestal_disp is None:
            self.pedestal_disp = np.zeros((len(self.t), 3))

    @classmethod
    def load(cls, path, wall_s=None):
        """Read ``trajectory.npz`` as written by ``yade_scripts/column_scene.py``."""
        with np.load(path) as data:
            raw = {key: data[key] for key in data.files}
        return cls(t=raw["t"], pos=raw["pos"], quat=raw["quat"],
                   bodies=json.loads(str(raw["bodies"])), vel=raw["vel"], angvel=raw["angvel"],
                   pedestal_disp=raw["pedestal_disp"], dt=float(raw["dt"]),
                   motion_end=float(raw["motion_end"]), stopped_early=bool(raw["stopped_early"]),
                   start_s=float(raw.get("start_s", 0.0)), wall_s=wall_s)

    @property
    def simulated_s(self):
        """Simulated time (s): from the start to the last sample."""
        return float(self.t[-1]) - self.start_s if len(self.t) else 0.0
