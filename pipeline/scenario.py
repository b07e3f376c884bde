"""Scenario stage: write a YADE scene directory and run YADE on it.

A scenario directory holds ``params.json`` (all parameters), ``motion.npz``
(the pedestal's ground motion: ``dt`` s, ``acc`` m/s^2 and ``disp`` m, n x 3
East/North/Up) and ``scene.py``, an unchanged copy of
``yade_scripts/column_scene.py``.  ``yade -n -x scene.py`` runs it on its own
and writes ``trajectory.npz``.  Values are never pasted into code.
"""
import json
import math
import os
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np

from pipeline import YADE_SCRIPTS_DIR
from pipeline.files import InputError, write_json, write_npz

SCENE_TEMPLATE = YADE_SCRIPTS_DIR / "column_scene.py"

# Paper defaults (Hinzen 2009): column 3.5 m, h/d 6, marble 2.96 Mg/m^3, 7 drums,
# kn 1.2e8 N/m, damping ratio 0.36, mu_s 0.7, mu_k 0.6.
COLUMN_DEFAULTS = {"height": 3.5, "hd": 6.0, "n_drums": 7, "density": 2960.0}
CONTACT_DEFAULTS = {"kn": 1.2e8, "damping": 0.36, "mu_s": 0.7, "mu_k": 0.6}
NUMERICS_DEFAULTS = {
    "rim_points": 16,            # contact spheres per rim
    "rim_sphere_radius": 0.005,  # m
    "verlet_distance": 0.02,     # m: collider bound enlargement (fewer collider runs)
    "dt_factor": 0.3,            # dt = f sqrt(m_min / (kn x rim_points)); converged, see make bench
    "drive": "inertial",         # or "kinematic" (per-step pedestal velocity, slow)
    "drive_interval_s": 0.002,   # gravity update interval of the inertial drive
    "friction": "switch",        # mu_s while sticking, mu_k while sliding; or "static"
    "friction_interval_s": 0.002,
    "record_hz": 100.0,
    "rest_velocity": 0.005,      # m/s: bodies slower than this are at rest
    "rest_length": 1.0,          # m: angular velocity times this counts as a velocity
    "rest_duration_s": 0.5,
    "tail_s": 10.0,              # simulated time allowed after the motion ends
}
PEDESTAL = {"size": 5.0, "thickness": 1.0, "mass": 74000.0,
            # the top face extends beyond the 5 m block so that a column falling over
            # the edge still lands at pedestal level (impact points up to ~4 m away)
            "contact_half_size": 12.0}
TWIN_OFFSET_M = 1.5


def _positive(name, value):
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number, got {value!r}")


def check_contact(kn, damping, mu_s, mu_k):
    """Validate contact parameters; raise InputError naming an impossible one."""
    _positive("kn", kn)
    if not (math.isfinite(damping) and damping >= 0):
        raise InputError(f"damping ratio must be a non-negative number, got {damping!r}")
    _positive("mu_s", mu_s)
    _positive("mu_k", mu_k)
    if mu_k > mu_s:
        raise InputError(f"mu_k ({mu_k}) must not exceed mu_s ({mu_s})")


def column_specs(column="both", hd=6.0, height=3.5, n_drums=7, density=2960.0, centred=None):
    """Column definitions: 'both' is the paper's twin model (drums at x = -1.5 m,
    monolith at x = +1.5 m); a single column stands at the centre unless centred=False."""
    _positive("h/d", hd)
    _positive("height", height)
    _positive("density", density)
    if int(n_drums) != n_drums or n_drums < 1:
        raise InputError(f"number of drums must be a positive integer, got {n_drums!r}")
    if column not in ("both", "monolithic", "drums"):
        raise InputError(f"column must be both, monolithic or drums, got {column!r}")
    diameter = height / hd
    kinds = ["drums", "monolithic"] if column == "both" else [column]
    if centred is None:
        centred = column != "both"
    specs = []
    for kind in kinds:
        x = 0.0 if centred else (-TWIN_OFFSET_M if kind == "drums" else TWIN_OFFSET_M)
        specs.append({"name": kind, "kind": kind, "x": x, "y": 0.0, "height": height,
                      "diameter": diameter, "n_drums": int(n_drums) if kind == "drums" else 1,
                      "density": density})
    return specs


def scene_params(columns=(), block=None, motion_duration=0.0, t_max=None, **overrides):
    """Full parameter dict of a scene (JSON-serialisable).

    columns: list from column_specs; block: dict(height, width, depth, density,
    theta0_rad) for the verification block; overrides: contact and numerics keys.
    """
    unknown = set(overrides) - set(CONTACT_DEFAULTS) - set(NUMERICS_DEFAULTS)
    if unknown:
        raise InputError(f"unknown scene parameter(s): {', '.join(sorted(unknown))}")
    contact = {k: float(overrides.get(k, v)) for k, v in CONTACT_DEFAULTS.items()}
    check_contact(**contact)
    numerics = {k: overrides.get(k, v) for k, v in NUMERICS_DEFAULTS.items()}
    if numerics["drive"] not in ("inertial", "kinematic"):
        raise InputError(f"drive must be inertial or kinematic, got {numerics['drive']!r}")
    if numerics["friction"] not in ("switch", "static"):
        raise InputError(f"friction must be switch or static, got {numerics['friction']!r}")
    if block is not None:
        for key in ("height", "width", "depth", "density"):
            _positive(f"block {key}", block[key])
    if not columns and block is None:
        raise InputError("a scene needs at least one column or a block")
    if t_max is None:
        t_max = motion_duration + numerics["tail_s"]
    _positive("simulated duration", t_max)
    return {"columns": list(columns), "block": block, "contact": contact,
            "pedestal": dict(PEDESTAL), **numerics, "t_max": float(t_max),
            "motion_file": None, "output": "trajectory.npz"}


def write_scenario(run_dir, params, motion=None):
    """Write params.json, motion.npz (if motion) and scene.py into run_dir.

    motion: dict with dt (s), acc (n x 3, m/s^2), disp (n x 3, m).
    """
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    params = dict(params)
    if motion is not None:
        acc, disp = np.asarray(motion["acc"], float), np.asarray(motion["disp"], float)
        if acc.ndim != 2 or acc.shape[1] != 3 or acc.shape != disp.shape:
            raise InputError("motion needs acc and disp arrays of shape (n, 3)")
        if not (np.isfinite(acc).all() and np.isfinite(disp).all()):
            raise InputError("motion contains NaN or infinite samples")
        write_npz(run_dir / "motion.npz", dt=float(motion["dt"]), acc=acc, disp=disp)
        params["motion_file"] = "motion.npz"
    write_json(run_dir / "params.json", params)
    shutil.copyfile(SCENE_TEMPLATE, run_dir / "scene.py")
    return run_dir / "scene.py"


def yade_command():
    exe = shutil.which("yade")
    if exe is None:
        raise InputError("YADE is not installed (the 'yade' command is missing): run 'make setup'")
    return exe


def run_yade(run_dir, timeout_s=None):
    """Run scene.py in run_dir with single-thread YADE; return the trajectory dict.

    The YADE log goes to run_dir/yade.log; failure raises RuntimeError with its tail.
    """
    run_dir = Path(run_dir)
    out = run_dir / "trajectory.npz"
    if out.exists():
        out.unlink()
    env = dict(os.environ, OMP_NUM_THREADS="1")
    start = time.perf_counter()
    with open(run_dir / "yade.log", "w") as log:
        proc = subprocess.run([yade_command(), "-n", "-j1", "-x", "scene.py"], cwd=run_dir,
                              stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                              env=env, timeout=timeout_s)
    wall = time.perf_counter() - start
    if proc.returncode != 0 or not out.exists():
        tail = (run_dir / "yade.log").read_text(errors="replace").strip().splitlines()[-5:]
        raise RuntimeError(f"YADE failed in {run_dir} (exit {proc.returncode}): " + " | ".join(tail))
    trajectory = load_trajectory(out)
    trajectory["wall_s"] = wall
    return trajectory


def load_trajectory(path):
    """trajectory.npz as a dict: t (n,), pedestal_disp (n,3), pos/vel/angvel (n,nb,3) in the
    pedestal frame, quat (n,nb,4) (w,x,y,z), bodies (list of dicts), dt, stopped_early."""
    with np.load(path) as data:
        traj = {key: data[key] for key in data.files}
    traj["bodies"] = json.loads(str(traj["bodies"]))
    for key in ("dt", "motion_end"):
        traj[key] = float(traj[key])
    traj["stopped_early"] = bool(traj["stopped_early"])
    return traj
