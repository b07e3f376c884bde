# YADE scene: rigid columns (monolithic or drums) or a test block on a pedestal.
#
# Run on its own with:  yade -n -x column_scene.py
# It reads params.json (and the motion npz it names) from its own directory
# and writes trajectory.npz there.  No value is ever pasted into this file:
# pipeline/scenario/writer.py copies it unchanged next to the data files.
#
# Bodies are clumps (see ../shared/notes/yade-modeling.md): small spheres on
# the bottom and top rims, a Box plate as the top face a drum above stands on,
# and a tiny dense core sphere at the true centroid; mass and inertia are then
# set to those of the solid body.  Contacts are ViscElMat (kn, cn explicit).
#
# Pedestal drive: "inertial" (default) keeps the pedestal still and sets
# gravity to (-a_E, -a_N, -g - a_U), exact for a pedestal in pure
# translation; positions are then relative to the pedestal.  "kinematic"
# imposes the pedestal velocity every step from Python (slow, for checks).
import json
import math
import os
import sys
import time

import numpy as np
from yade import O, Quaternion, Vector3, utils
from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, Ig2_Box_Sphere_ScGeom,
                          Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                          Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic,
                          NewtonIntegrator, PyRunner, ViscElMat)

# ---------------------------------------------------------------- parameters
# Every value comes from params.json beside this script (written by
# pipeline/scenario/writer.py from the dataclasses of pipeline/scenario/parameters.py).
HERE = os.path.dirname(os.path.abspath(sys.argv[0]))
with open(os.path.join(HERE, "params.json")) as fh:
    P = json.load(fh)
G = 9.81                              # m/s^2, the model's gravity (pipeline.constants)
COLUMNS = P["columns"]                # name, kind, x, y (m), height (m), diameter (m), n_drums, density (kg/m^3)
BLOCK = P.get("block")                # test block: height, width, depth (m), density, theta0_rad; or None
CONTACT = P["contact"]                # kn (N/m per rim point), damping (ratio), mu_s, mu_k
PEDESTAL = P["pedestal"]              # thickness (m), contact_half_size (m)
RIM_POINTS = P["rim_points"]          # contact spheres per rim
RIM_R = P["rim_sphere_radius"]        # m
RIM_PHASE_DEG = P.get("rim_phase_deg", 0.0)  # angular phase of the rim points (deg)
DT_FACTOR = P["dt_factor"]            # dt = DT_FACTOR sqrt(m_min / (kn RIM_POINTS))
DRIVE = P["drive"]                    # "inertial" (gravity table) or "kinematic"
DRIVE_INTERVAL_S = P["drive_interval_s"]
FRICTION = P["friction"]              # "switch" (mu_s sticking, mu_k sliding) or "static"
FRICTION_INTERVAL_S = P["friction_interval_s"]
RECORD_HZ = P["record_hz"]            # trajectory samples per second
REST_VELOCITY = P["rest_velocity"]    # m/s
REST_LENGTH = P["rest_length"]        # m
REST_DURATION_S = P["rest_duration_s"]
T_MAX = P["t_max"]                    # s, simulated time at most
VERLET_DISTANCE = P["verlet_distance"]  # m
MOTION_FILE = P.get("motion_file")    # processed-motion npz (dt, acc, disp; East, North, Up)
OUTPUT = P["output"]                  # trajectory file name
CORE_MASK = 1 << 29          # collides with nothing
# the clump's reference point is its members' centre of mass: a tiny, very dense
# core sphere at the body's centroid puts it there (mass set per density, not state.mass)
CORE = O.materials.append(ViscElMat(density=1e20, kn=0, ks=0, cn=0, cs=0))


def rotation_matrix(q):
    """3x3 numpy rotation matrix of a YADE Quaternion."""
    m = q.toRotationMatrix()
    return np.array([[m[i, j] for j in range(3)] for i in range(3)])


def yade_quaternion(R):
    """YADE Quaternion from a 3x3 numpy rotation matrix (Shepperd's method)."""
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return Quaternion(w, x, y, z)


def contact_material(mass, n_points):
    """ViscElMat for rim contact points of normal stiffness kn each (N/m per point).

    Two materials combine in series, so each carries twice the per-point values.
    Damping: ratio zeta of critical for the body's mass on a face of n_points points,
    c = 2 zeta sqrt(kn m / n_points) per point.
    """
    k_point = CONTACT["kn"]
    c_point = 2 * CONTACT["damping"] * math.sqrt(k_point * mass / n_points)
    return O.materials.append(ViscElMat(
        density=1e-3, kn=2 * k_point, ks=2 * k_point, cn=2 * c_point, cs=2 * c_point,
        frictionAngle=math.atan(CONTACT["mu_s"])))


def rim_points(shape, n):
    """Contact points of a base outline in the body frame (x, y), metres."""
    if shape["shape"] == "cylinder":
        ang = 2 * math.pi * np.arange(n) / n + math.radians(RIM_PHASE_DEG)
        return np.column_stack([shape["radius"] * np.cos(ang), shape["radius"] * np.sin(ang)])
    half_w, half_d = shape["width"] / 2, shape["depth"] / 2
    ys = np.linspace(-half_d, half_d, max(2, n // 2))
    return np.vstack([np.column_stack([np.full_like(ys, -half_w), ys]),
                      np.column_stack([np.full_like(ys, half_w), ys])])


def add_body(shape, centre, R, mask_base, mask_top, material):
    """Add one rigid body as a clump; return its clump id.

    shape: dict with shape 'cylinder' (radius) or 'box' (width, depth), height, mass,
    top_plate (bool), top_rim (bool).  centre: world position of the centroid (m);
    R: 3x3 rotation body -> world; body z is the long axis.
    """
    h = shape["height"]
    centre = np.asarray(centre, float)
    members = []

    def world(p):
        return tuple(centre + R @ np.asarray(p, float))

    pts = rim_points(shape, RIM_POINTS)
    for x, y in pts:
        members.append(utils.sphere(world((x, y, -h / 2 + RIM_R)), RIM_R, material=material,
                                    mask=mask_base))
    if shape.get("top_rim"):
        for x, y in pts:
            members.append(utils.sphere(world((x, y, h / 2 - RIM_R)), RIM_R, material=material,
                                        mask=mask_top))
    if shape.get("top_plate"):
        half = (shape["radius"] + RIM_R if shape["shape"] == "cylinder"
                else max(shape["width"], shape["depth"]) / 2 + RIM_R)
        plate_ht = 0.005
        members.append(utils.box(world((0, 0, h / 2 - plate_ht)), (half, half, plate_ht),
                                 orientation=yade_quaternion(R), material=material,
                                 mask=mask_base))
    members.append(utils.sphere(world((0, 0, 0)), 1e-3, material=CORE, mask=CORE_MASK))
    clump_id, _ = O.bodies.appendClumped(members)
    clump = O.bodies[clump_id]
    # mass and inertia of the solid body, expressed in the clump's principal frame
    m = shape["mass"]
    if shape["shape"] == "cylinder":
        r = shape["radius"]
        i_body = np.diag([m * (3 * r * r + h * h) / 12] * 2 + [m * r * r / 2])
    else:
        w, d = shape["width"], shape["depth"]
        i_body = np.diag([m * (d * d + h * h) / 12, m * (w * w + h * h) / 12, m * (w * w + d * d) / 12])
    i_world = R @ i_body @ R.T
    Rc = rotation_matrix(clump.state.ori)
    i_clump = Rc.T @ i_world @ Rc
    clump.state.mass = m
    clump.state.inertia = Vector3(*np.diag(i_clump))
    clump.state.pos = Vector3(*centre)          # exact centroid (core sphere ~ there already)
    # the clump frame is the members' principal frame (axes may be permuted):
    # body orientation = clump orientation * body_offset
    body_offset[clump_id] = yade_quaternion(Rc.T @ R)
    return clump_id


# ---------------------------------------------------------------- scene
bodies = []        # metadata for the trajectory file
clumps = []        # clump ids in the same order
body_offset = {}   # clump id -> Quaternion of the body frame in the clump frame
pedestal_ids = []


def add_pedestal(mask, material):
    half = PEDESTAL["contact_half_size"]
    thick = PEDESTAL["thickness"]
    pid = O.bodies.append(utils.box((0, 0, -thick / 2), (half, half, thick / 2), fixed=True,
                                    material=material, mask=mask))
    pedestal_ids.append(pid)


for c, col in enumerate(COLUMNS):
    mask_base, mask_top = 1 << (2 * c), 1 << (2 * c + 1)
    n_bodies = col["n_drums"] if col["kind"] == "drums" else 1
    body_h = col["height"] / n_bodies
    mass = col["density"] * math.pi * (col["diameter"] / 2) ** 2 * body_h
    material = contact_material(mass, RIM_POINTS)
    add_pedestal(mask_base | mask_top, material)
    x0, y0 = col["x"], col["y"]
    for k in range(n_bodies):
        shape = {"shape": "cylinder", "radius": col["diameter"] / 2, "height": body_h, "mass": mass,
                 "top_plate": k < n_bodies - 1, "top_rim": True}
        centre = (x0, y0, (k + 0.5) * body_h)
        clumps.append(add_body(shape, centre, np.eye(3), mask_base, mask_top, material))
        bodies.append(dict(shape, name=f"{col['name']}[{k}]", column=col["name"], index=k,
                           initial_pos=list(centre)))

if BLOCK:
    blk = BLOCK
    shape = {"shape": "box", "width": blk["width"], "depth": blk["depth"], "height": blk["height"],
             "mass": blk["density"] * blk["width"] * blk["depth"] * blk["height"],
             "top_plate": False, "top_rim": False}
    material = contact_material(shape["mass"], 2 * max(2, RIM_POINTS // 2))
    add_pedestal(1, material)
    # initial tilt theta0 about the North (y) axis through the +x (East) bottom edge:
    # positive theta0 lifts the West edge, the block leans East.
    th = blk.get("theta0_rad", 0.0)
    Ry = np.array([[math.cos(th), 0, math.sin(th)], [0, 1, 0], [-math.sin(th), 0, math.cos(th)]])
    pivot = np.array([blk["width"] / 2, 0, 0])
    centre = pivot + Ry @ (np.array([0, 0, blk["height"] / 2]) - pivot)
    clumps.append(add_body(shape, centre, Ry, 1, 1, material))
    bodies.append(dict(shape, name="block", column="block", index=0, initial_pos=list(centre)))

# ---------------------------------------------------------------- time step
# a body resting on a whole face of rim points: stiffness kn x points
k_face = CONTACT["kn"] * RIM_POINTS
m_min = min(b["mass"] for b in bodies)
O.dt = DT_FACTOR * math.sqrt(m_min / k_face)

# ---------------------------------------------------------------- motion
motion = None
motion_end = 0.0
if MOTION_FILE:
    with np.load(os.path.join(HERE, MOTION_FILE)) as mf:
        motion = {"dt": float(mf["dt"]), "acc": np.array(mf["acc"], float),
                  "disp": np.array(mf["disp"], float)}
    motion["t"] = motion["dt"] * np.arange(len(motion["acc"]))
    motion_end = float(motion["t"][-1])


def motion_at(key, times):
    """Motion (len(times) x 3, E/N/U) interpolated linearly; acc is zero and disp
    frozen after the record ends."""
    times = np.atleast_1d(times)
    if motion is None:
        return np.zeros((len(times), 3))
    out = np.column_stack([np.interp(times, motion["t"], motion[key][:, j]) for j in range(3)])
    if key == "acc":
        out[times > motion_end] = 0.0
    return out


drive_steps = max(1, int(round(DRIVE_INTERVAL_S / O.dt)))
newton = NewtonIntegrator(damping=0.0, gravity=(0, 0, -G))
# inertial drive: gravity in the pedestal frame, -a(t) averaged over each drive interval
# (sampled at its midpoint), precomputed so that each update is a table look-up
n_drive = int((motion_end + DRIVE_INTERVAL_S) / (drive_steps * O.dt)) + 2
drive_acc = motion_at("acc", (np.arange(n_drive) + 0.5) * drive_steps * O.dt)
GRAVITY_TABLE = [Vector3(-a[0], -a[1], -G - a[2]) for a in drive_acc] + [Vector3(0, 0, -G)]


def drive_inertial():
    newton.gravity = GRAVITY_TABLE[min(O.iter // drive_steps, len(GRAVITY_TABLE) - 1)]


def drive_kinematic():
    """Pedestal velocity (d(t + dt) - d(t)) / dt for the coming step."""
    d = motion_at("disp", [O.time, O.time + O.dt])
    v = Vector3(*((d[1] - d[0]) / O.dt))
    for pid in pedestal_ids:
        O.bodies[pid].state.vel = v


# ---------------------------------------------------------------- friction
TAN_S, TAN_K = CONTACT["mu_s"], CONTACT["mu_k"]


def switch_friction():
    """Static mu_s while a contact sticks, kinetic mu_k while it slides."""
    for i in O.interactions:
        ph = i.phys
        fn = ph.normalForce.norm()
        if fn <= 0:
            continue
        fs = ph.shearForce.norm()
        if ph.tangensOfFrictionAngle > TAN_K:        # sticking: switch at the static limit
            if fs >= 0.999 * TAN_S * fn:
                ph.tangensOfFrictionAngle = TAN_K
        elif fs < 0.99 * TAN_K * fn:                  # sliding stopped: back to static
            ph.tangensOfFrictionAngle = TAN_S


# ---------------------------------------------------------------- recording and stopping
samples = []       # per record: (time, [(pos, ori, vel, angVel) per clump], pedestal pos, vel)
record_steps = max(1, int(round(1.0 / (RECORD_HZ * O.dt))))
state = {"rest_since": None, "stopped_early": False}
states = [O.bodies[c].state for c in clumps]
pedestal_state = O.bodies[pedestal_ids[0]].state
pedestal_origin = Vector3(pedestal_state.pos)


def record_state():
    samples.append((O.time, [(Vector3(s.pos), Quaternion(s.ori), Vector3(s.vel), Vector3(s.angVel))
                             for s in states],
                    pedestal_state.pos - pedestal_origin, Vector3(pedestal_state.vel)))
    if O.time >= T_MAX:
        O.pause()    # the main thread writes the output once the loop has stopped


def overturning_barrier(col):
    """Smallest energy (J) that tips any stack of drums (k..top) of a column over its edge:
    M g (sqrt((H/2)^2 + r^2) - H/2) for the stack of mass M and height H."""
    n, r = (col["n_drums"] if col["kind"] == "drums" else 1), col["diameter"] / 2
    h = col["height"] / n
    m = col["density"] * math.pi * r * r * h
    return min((n - k) * m * G * (math.hypot((n - k) * h / 2, r) - (n - k) * h / 2)
               for k in range(n))


BARRIERS = {col["name"]: overturning_barrier(col) for col in COLUMNS}
SETTLED_FRACTION = 0.9   # after the motion, energy below the barrier cannot tip a stack (10 % margin)


def settled(rel):
    """True when, after the motion, every body still stands (tilt < 30 deg) and no column
    holds more than 90 % of the energy it needs to tip any stack over: energy only
    decreases then, so no column can fall.  Scenes with a test block (verification) or a
    column that has begun to fall never count as settled."""
    energy = dict.fromkeys(BARRIERS, 0.0)
    for b, s, c in zip(bodies, states, clumps):
        if b["column"] not in BARRIERS:
            return False
        if (s.ori * body_offset[c] * Vector3(0, 0, 1))[2] < 0.866:     # tilted > 30 deg
            return False
        w = s.ori.conjugate() * s.angVel                               # clump frame
        energy[b["column"]] += (0.5 * b["mass"] * (s.vel - rel).squaredNorm()
                                + 0.5 * sum(s.inertia[i] * w[i] ** 2 for i in range(3))
                                + b["mass"] * G * (s.pos[2] - b["initial_pos"][2]))
    return all(energy[k] < SETTLED_FRACTION * BARRIERS[k] for k in BARRIERS)


def check_stop():
    """Stop once the standing bodies rest and either the motion is over or every column
    has fallen, or once the motion is over and no column can topple any more (energy).
    Bodies lying on the pedestal (tilt > 60 deg) may roll on: their impact is recorded
    already and a rolling cylinder takes long to stop."""
    v_rest, length = REST_VELOCITY, REST_LENGTH
    rel = pedestal_state.vel
    if BARRIERS and O.time > motion_end and settled(rel):
        state["stopped_early"] = True
        record_state()
        O.pause()
        return
    at_rest, fallen = True, {}
    for b, s, c in zip(bodies, states, clumps):
        lying = (s.ori * body_offset[c] * Vector3(0, 0, 1))[2] < 0.5
        fallen[b["column"]] = fallen.get(b["column"], False) or lying
        if not lying and ((s.vel - rel).norm() >= v_rest or s.angVel.norm() * length >= v_rest):
            at_rest = False
    if at_rest and (O.time > motion_end or all(fallen.values())):
        if state["rest_since"] is None:
            state["rest_since"] = O.time
        elif O.time - state["rest_since"] >= REST_DURATION_S:
            state["stopped_early"] = True
            record_state()
            O.pause()
    else:
        state["rest_since"] = None


def quat_multiply(q, r):
    """Hamilton product of (..., 4) arrays ordered (w, x, y, z)."""
    w1, x1, y1, z1 = np.moveaxis(q, -1, 0)
    w2, x2, y2, z2 = np.moveaxis(r, -1, 0)
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2],
                    axis=-1)


def finish():
    """Write trajectory.npz (atomically) in the pedestal frame."""
    t = np.array([s[0] for s in samples])
    pos = np.array([[list(b[0]) for b in s[1]] for s in samples]).reshape(len(t), len(clumps), 3)
    ori = np.array([[[b[1][3], b[1][0], b[1][1], b[1][2]] for b in s[1]] for s in samples])
    vel = np.array([[list(b[2]) for b in s[1]] for s in samples]).reshape(pos.shape)
    angvel = np.array([[list(b[3]) for b in s[1]] for s in samples]).reshape(pos.shape)
    shift = np.array([list(s[2]) for s in samples])[:, None, :]
    ped_vel = np.array([list(s[3]) for s in samples])[:, None, :]
    offsets = np.array([[body_offset[c][3], body_offset[c][0], body_offset[c][1], body_offset[c][2]]
                        for c in clumps])
    if DRIVE == "kinematic":
        disp = shift[:, 0, :]
    else:
        disp = motion_at("disp", t)
    out = os.path.join(HERE, OUTPUT)
    tmp = out + ".tmp.npz"
    np.savez_compressed(
        tmp, t=t, pedestal_disp=disp, pos=pos - shift,
        quat=quat_multiply(ori.reshape(len(t), len(clumps), 4), offsets[None]), vel=vel - ped_vel,
        angvel=angvel, bodies=json.dumps(bodies), dt=O.dt,
        stopped_early=state["stopped_early"], motion_end=motion_end)
    os.replace(tmp, out)


# ---------------------------------------------------------------- engines
friction_steps = max(1, int(round(FRICTION_INTERVAL_S / O.dt)))
stop_steps = max(1, int(round(0.1 / O.dt)))
driven = motion is not None
# recorders run before NewtonIntegrator so that O.time and positions agree
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()], verletDist=VERLET_DISTANCE),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                    [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
                    [Law2_ScGeom_ViscElPhys_Basic()]),
    PyRunner(command="switch_friction()", iterPeriod=friction_steps,
             dead=not (FRICTION == "switch" and TAN_K < TAN_S)),
    PyRunner(command="drive_inertial()", iterPeriod=drive_steps,
             dead=not (driven and DRIVE == "inertial")),
    PyRunner(command="drive_kinematic()", iterPeriod=1, dead=not (driven and DRIVE == "kinematic")),
    PyRunner(command="record_state()", iterPeriod=record_steps),
    PyRunner(command="check_stop()", iterPeriod=stop_steps),
    newton,
]
if driven and DRIVE == "inertial":
    drive_inertial()
O.run()
O.wait()
while O.running:
    time.sleep(0.01)
finish()
