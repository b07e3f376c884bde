# YADE scene: rigid columns (stacks of drums, capitals, bases, monoliths) or a test
# block on a pedestal.
#
# Run on its own with:  yade -n -x column_scene.py
# It reads params.json (and the motion npz it names) from its own directory
# and writes trajectory.npz there.  No value is ever pasted into this file:
# pipeline/scenario/writer.py copies it unchanged next to the data files.
#
# The geometry comes ready-made in params.json (pipeline/scenario/geometry.py): each
# column is a list of bodies, each body with its world placement (centre of mass,
# rotation), mass, inertia tensor about the centre of mass, rims and top plate.
# Bodies are clumps (README, "The YADE model"): small spheres on their
# rims (the base rim on the contact area with what is below, the other rims on the
# outer edges: they let a falling body strike the pedestal), a Box plate as the top
# face a body above stands on, and a tiny dense core sphere at the centre of mass;
# mass and inertia are then set to those of the solid body.  Contacts are ViscElMat
# (kn, cn explicit).
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
from yade import Matrix3, O, Quaternion, Vector3, utils
from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, Ig2_Box_Sphere_ScGeom,
                          Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                          Ip2_ViscElMat_ViscElMat_ViscElPhys, Law2_ScGeom_ViscElPhys_Basic,
                          NewtonIntegrator, PyRunner, ViscElMat)

# ---------------------------------------------------------------- parameters
# Every value comes from params.json beside this script: the scene file
# (pipeline/scenario/scene_file.py, SceneFile; its field names are the keys read here).
HERE = os.path.dirname(os.path.abspath(sys.argv[0]))
with open(os.path.join(HERE, "params.json")) as fh:
    P = json.load(fh)
G = P["gravity"]                      # m/s^2, the model's gravity
COLUMNS = P["columns"]                # name, x, y (m), bodies (see below), settles,
#                                       overturning_barrier_j (J); a test block is a column
#   body: name, column, index, mass (kg), inertia (3x3, kg m^2, body frame about the
#   centre of mass), principal_axes (3x3, columns), centre (m), rotation (3x3 body ->
#   world), rims [{role base|edge, z (m), normal (into the body), kind circle (radius,
#   centre) | polygon (points)}], plate {centre, half_size} or null (body frame, m)
CONTACT = P["contact"]                # kn (N/m per rim point), damping (ratio), mu_s, mu_k
PEDESTAL = P["pedestal"]              # thickness (m), contact_half_size (m)
NUMERICS = P["numerics"]
THRESHOLDS = P["thresholds"]          # the stop checks' (SceneFile.thresholds)
CLUMP = P["clump"]                    # how a body becomes a clump (m, kg/m^3)
RIM_POINTS = NUMERICS["rim_points"]   # contact spheres per circular rim
RIM_R = NUMERICS["rim_sphere_radius"]  # m
RIM_PHASE_DEG = NUMERICS["rim_phase_deg"]  # angular phase of circular rims (deg)
DRIVE = NUMERICS["drive"]             # "inertial" (gravity table) or "kinematic"
DRIVE_INTERVAL_S = NUMERICS["drive_interval_s"]
FRICTION = NUMERICS["friction"]       # "switch" (mu_s sticking, mu_k sliding) or "static"
FRICTION_INTERVAL_S = NUMERICS["friction_interval_s"]
RECORD_HZ = NUMERICS["record_hz"]     # trajectory samples per second
REST_VELOCITY = NUMERICS["rest_velocity"]  # m/s
REST_LENGTH = NUMERICS["rest_length"]  # m
REST_DURATION_S = NUMERICS["rest_duration_s"]
T_MAX = P["t_max"]                    # s, simulated time at most
VERLET_DISTANCE = NUMERICS["verlet_distance"]  # m
MOTION_FILE = P["motion_file"]        # processed-motion npz (dt, acc, disp; East, North, Up)
# the motion's quiet parts (pipeline/simulate.py, quiet_window): the scene starts at START_S
# on the motion's clock (no body can move before START_S + quiet_lead_s) and may stop once
# every body rests seated after QUIET_AFTER_S (no later sample can set it moving)
START_S = P["start_s"]                # s
QUIET_AFTER_S = P["quiet_after_s"]    # s, None: the motion's end
OUTPUT = P["output"]                  # trajectory file name
PLATE_HALF_THICKNESS = CLUMP["plate_half_thickness_m"]   # m, the top plate (a Box member)
CORE_MASK = 1 << 29          # collides with nothing
# the clump's reference point is its members' centre of mass: a tiny, very dense
# core sphere at the body's centroid puts it there (mass set per density, not state.mass)
CORE = O.materials.append(ViscElMat(density=CLUMP["core_density_kg_m3"], kn=0, ks=0, cn=0,
                                    cs=0))
# bodies other than an upright cylinder (whose members already have its principal axes)
# get pairs of dense "frame" spheres along the body's principal axes (masses 1:2, none
# on the third axis), so that the clump's principal frame, computed by YADE from its
# members, is the body's; they collide with nothing
FRAME_ARM, FRAME_RADIUS = CLUMP["frame_arm_m"], CLUMP["frame_radius_m"]   # m


def rotation_matrix(q):
    """3x3 numpy rotation matrix of a YADE Quaternion."""
    m = q.toRotationMatrix()
    return np.array([[m[i, j] for j in range(3)] for i in range(3)])


def yade_quaternion(R):
    """YADE Quaternion of a 3x3 numpy rotation matrix (minieigen's conversion), of the
    sign with w >= 0 (q and -q are the same rotation)."""
    q = Quaternion(Matrix3(*np.ravel(R)))
    return q if q[3] >= 0 else Quaternion(-q[3], -q[0], -q[1], -q[2])


def contact_material(mass, n_points):
    """ViscElMat for rim contact points of normal stiffness kn each (N/m per point).

    Two materials combine in series, so each carries twice the per-point values.
    Damping: ratio zeta of critical for the body's mass on a face of n_points points,
    c = 2 zeta sqrt(kn m / n_points) per point.
    """
    k_point = CONTACT["kn"]
    c_point = 2 * CONTACT["damping"] * math.sqrt(k_point * mass / n_points)
    return O.materials.append(ViscElMat(
        density=CLUMP["member_density_kg_m3"], kn=2 * k_point, ks=2 * k_point,
        cn=2 * c_point, cs=2 * c_point,
        frictionAngle=math.atan(CONTACT["mu_s"])))


def rim_spheres(rim, floor_z=None):
    """Centres (n x 3, body frame) of a rim's contact spheres: circles get RIM_POINTS
    points from the phase on, polygons their given points, point sets (a mesh specimen's
    footprint and hull) theirs one radius along their inward normals; each point lies in the rim's
    face (the plane through z with the rim's normal, e.g. a wedge joint) and its sphere
    one radius inside the body along that normal.  ``floor_z``: the base plane (body
    frame) no point-set sphere may reach below."""
    if rim["kind"] == "points":              # a mesh specimen: surface points, inward normals
        points = np.asarray(rim["points"], float)
        centres = points + RIM_R * np.asarray(rim["normals"], float)
        if floor_z is not None:
            # a sphere one radius in along a slanted normal reaches below its point: one
            # that would start inside the table (below the base) sits straight above its
            # point instead, touching it from above (no spring loaded at the start)
            below = centres[:, 2] - RIM_R < floor_z
            centres[below] = points[below] + [0.0, 0.0, RIM_R]
        return centres
    if rim["kind"] == "circle":
        ang = 2 * math.pi * np.arange(RIM_POINTS) / RIM_POINTS + math.radians(RIM_PHASE_DEG)
        xy = np.column_stack([rim["radius"] * np.cos(ang), rim["radius"] * np.sin(ang)])
        xy = xy + np.asarray(rim["centre"], float)
    else:
        xy = np.asarray(rim["points"], float)
    n = np.asarray(rim["normal"], float)
    z = rim["z"] - (n[0] * xy[:, 0] + n[1] * xy[:, 1]) / n[2]
    return np.column_stack([xy + RIM_R * n[:2], z + RIM_R * n[2]])


def add_body(body, mask_base, mask_top, material, mask_plate=None):
    """Add one rigid body (a params.json body) as a clump; return its clump id.  Its base
    rims' spheres take ``mask_base``, its other rims' ``mask_top``, its top plate
    ``mask_plate`` (default ``mask_base``)."""
    mask_plate = mask_base if mask_plate is None else mask_plate
    centre = np.asarray(body["centre"], float)
    R = np.asarray(body["rotation"], float)
    axes = R @ np.asarray(body["principal_axes"], float)          # world
    plain = (len(body["parts"]) == 1 and body["shape"] == "frustum"
             and body["parts"][0]["bottom_diameter"] == body["parts"][0]["top_diameter"]
             and np.all(np.isin(np.abs(axes), (0.0, 1.0))))

    def world(p):
        return tuple(centre + R @ np.asarray(p, float))

    def clump_members(frame_spheres):
        members = []
        floor_z = min((min(p[2] for p in rim["points"]) for rim in body["rims"]
                       if rim["role"] == "base" and rim["kind"] == "points"), default=None)
        for rim in body["rims"]:
            points = rim_spheres(rim, floor_z)
            for p in points:
                members.append(utils.sphere(world(p), RIM_R, material=material,
                                            mask=mask_base if rim["role"] == "base"
                                            else mask_top))
        plate = body["plate"]
        if plate:
            cx, cy, cz = plate["centre"]
            hx, hy = plate["half_size"]
            members.append(utils.box(world((cx, cy, cz - PLATE_HALF_THICKNESS)),
                                     (hx + RIM_R, hy + RIM_R, PLATE_HALF_THICKNESS),
                                     orientation=yade_quaternion(R), material=material,
                                     mask=mask_plate))
        members.append(utils.sphere(world((0, 0, 0)), CLUMP["core_radius_m"], material=CORE,
                                    mask=CORE_MASK))
        if frame_spheres:
            for axis, radius in ((axes[:, 0], FRAME_RADIUS),
                                 (axes[:, 1], FRAME_RADIUS * 2 ** (1 / 3))):
                for sign in (1, -1):
                    members.append(utils.sphere(tuple(centre + sign * FRAME_ARM * axis), radius,
                                                material=CORE, mask=CORE_MASK))
        return members

    # mass and inertia of the solid body, expressed in the clump's principal frame
    i_world = R @ np.asarray(body["inertia"], float) @ R.T
    frame_spheres = not plain
    while True:
        members = clump_members(frame_spheres)
        clump_id, _ = O.bodies.appendClumped(members)
        clump = O.bodies[clump_id]
        Rc = rotation_matrix(clump.state.ori)
        i_clump = Rc.T @ i_world @ Rc
        off_diagonal = np.abs(i_clump - np.diag(np.diag(i_clump))).max()
        if off_diagonal <= CLUMP["principal_tolerance"] * np.abs(i_clump).max():
            break
        if frame_spheres:
            raise RuntimeError(f"body {body['name']}: the clump frame is not its principal "
                               f"frame (off-diagonal inertia {off_diagonal:.3g} kg m^2)")
        O.bodies.erase(clump_id, True)          # members nearly isotropic: add the frame
        frame_spheres = True
    clump.state.mass = body["mass"]
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


def base_points(body):
    """Number of contact points of a body's base rims (a beam has one per support)."""
    return sum(RIM_POINTS if rim["kind"] == "circle" else len(rim["points"])
               for rim in body["rims"] if rim["role"] == "base")


# one material per (mass, base points): the contact damping follows the body resting
# on the contact; the pedestal takes the bottom body's
materials = {}


def material_of(body):
    key = (body["mass"], base_points(body))
    if key not in materials:
        materials[key] = contact_material(*key)
    return materials[key]


# collision masks: two bits per column (a colonnade's beams are columns of one body),
# base (its bodies' base rims and top plates) and top (its other rims); the top plates of
# a column or beam that beams rest on (``rests_on``) also take those beams' base bits, so
# that the beams' base rims meet them (and two beams on one capital never meet)
mask_plate = {col["name"]: 1 << (2 * c) for c, col in enumerate(COLUMNS)}
for c, col in enumerate(COLUMNS):
    for name in col.get("rests_on", ()):
        mask_plate[name] |= 1 << (2 * c)
for c, col in enumerate(COLUMNS):
    mask_base, mask_top = 1 << (2 * c), 1 << (2 * c + 1)
    add_pedestal(mask_base | mask_top, material_of(col["bodies"][0]))
    for body in col["bodies"]:
        clump_id = add_body(body, mask_base, mask_top, material_of(body),
                            mask_plate[col["name"]])
        clumps.append(clump_id)
        meta = {k: v for k, v in body.items() if k not in ("centre", "rotation")}
        bodies.append(dict(meta, initial_pos=list(body["centre"]),
                           initial_rotation=body["rotation"]))

# ---------------------------------------------------------------- time step
# from the lightest body resting on its whole base rim (pipeline.scenario.time_step.time_step_s)
O.dt = P["time_step_s"]

# ---------------------------------------------------------------- motion
motion = None
motion_end = 0.0
if MOTION_FILE:
    with np.load(os.path.join(HERE, MOTION_FILE)) as mf:
        motion = {"dt": float(mf["dt"]), "acc": np.array(mf["acc"], float),
                  "disp": np.array(mf["disp"], float)}
    motion["t"] = motion["dt"] * np.arange(len(motion["acc"]))
    motion_end = float(motion["t"][-1])
# the stop checks' end of the motion: the end of its signal when the processing gives one
# (after it, the band-pass filter's transient only, far below anything that moves a body;
# the pedestal is still driven by it while the run goes on)
signal_end = motion_end if P["signal_end_s"] is None else \
    min(motion_end, float(P["signal_end_s"]))
quiet_after = signal_end if QUIET_AFTER_S is None else QUIET_AFTER_S


def now():
    """Time (s) on the motion's clock."""
    return O.time + START_S


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
n_drive = int((motion_end - START_S + DRIVE_INTERVAL_S) / (drive_steps * O.dt)) + 2
drive_acc = motion_at("acc", START_S + (np.arange(n_drive) + 0.5) * drive_steps * O.dt)
GRAVITY_TABLE = [Vector3(-a[0], -a[1], -G - a[2]) for a in drive_acc] + [Vector3(0, 0, -G)]


def drive_inertial():
    newton.gravity = GRAVITY_TABLE[min(O.iter // drive_steps, len(GRAVITY_TABLE) - 1)]


def drive_kinematic():
    """Pedestal velocity (d(t + dt) - d(t)) / dt for the coming step."""
    d = motion_at("disp", [now(), now() + O.dt])
    v = Vector3(*((d[1] - d[0]) / O.dt))
    for pid in pedestal_ids:
        O.bodies[pid].state.vel = v


# ---------------------------------------------------------------- friction
TAN_S, TAN_K = CONTACT["mu_s"], CONTACT["mu_k"]
STICK_FRACTION, SLIDE_FRACTION = THRESHOLDS["stick_fraction"], THRESHOLDS["slide_fraction"]


def switch_friction():
    """Static mu_s while a contact sticks, kinetic mu_k while it slides."""
    for i in O.interactions:
        ph = i.phys
        fn = ph.normalForce.norm()
        if fn <= 0:
            continue
        fs = ph.shearForce.norm()
        if ph.tangensOfFrictionAngle > TAN_K:        # sticking: switch at the static limit
            if fs >= STICK_FRACTION * TAN_S * fn:
                ph.tangensOfFrictionAngle = TAN_K
        elif fs < SLIDE_FRACTION * TAN_K * fn:        # sliding stopped: back to static
            ph.tangensOfFrictionAngle = TAN_S


# ---------------------------------------------------------------- recording and stopping
samples = []       # per record: (time, [(pos, ori, vel, angVel) per clump], pedestal pos, vel)
record_steps = max(1, int(round(1.0 / (RECORD_HZ * O.dt))))
state = {"rest_since": None, "stopped_early": False}
states = [O.bodies[c].state for c in clumps]
pedestal_state = O.bodies[pedestal_ids[0]].state
pedestal_origin = Vector3(pedestal_state.pos)


def record_state():
    samples.append((now(), [(Vector3(s.pos), Quaternion(s.ori), Vector3(s.vel), Vector3(s.angVel))
                             for s in states],
                    pedestal_state.pos - pedestal_origin, Vector3(pedestal_state.vel)))
    if now() >= T_MAX:
        O.pause()    # the main thread writes the output once the loop has stopped


# smallest energy (J) that tips any stack of a column's bodies over its edge
BARRIERS = {col["name"]: col["overturning_barrier_j"] for col in COLUMNS if col["settles"]}
# after the motion, energy below this fraction of the barrier cannot tip a stack
SETTLED_FRACTION = THRESHOLDS["settled_fraction"]

# z of a body's axis: it stands (tilt below ~30 deg), lies (tilt past 60 deg)
STANDS_UP, LIES_UP = THRESHOLDS["stands_axis_z"], THRESHOLDS["lies_axis_z"]
# a mesh specimen (a rock) lies once tilted lies_past_critical_deg past its critical angle
# (at most lies_tilt_deg): it has overturned, and may chatter on its landing points for
# long before it rests
LIES_AT = [math.cos(math.radians(min(THRESHOLDS["lies_tilt_deg"], b["overturn_tilt_deg"]
                                     + THRESHOLDS["lies_past_critical_deg"])))
           if b["overturn_tilt_deg"] is not None else LIES_UP for b in bodies]


def up_axis(s, c):
    """World direction (Vector3) of the axis of the body of clump ``c`` (state ``s``)."""
    return s.ori * body_offset[c] * Vector3(0, 0, 1)


def settled(rel):
    """True when, after the motion, every column is decided: all its bodies lie on the
    pedestal (tilt > 60 deg: their impacts are recorded, they may roll on), or all still
    stand (tilt < 30 deg) and it holds less than 90 % of the energy it needs to tip any
    stack over (energy only decreases then, so it cannot fall).  Scenes with a test
    block (verification) and columns partly fallen are never decided this way."""
    energy = dict.fromkeys(BARRIERS, 0.0)
    tilt = {}          # column -> set of "stands" / "lies" / "between"
    for b, s, c, lies_up in zip(bodies, states, clumps, LIES_AT):
        if b["column"] not in BARRIERS:
            return False
        up = up_axis(s, c)[2]
        tilt.setdefault(b["column"], set()).add(
            "stands" if up >= STANDS_UP else "lies" if up < lies_up else "between")
        w = s.ori.conjugate() * s.angVel                               # clump frame
        energy[b["column"]] += (0.5 * b["mass"] * (s.vel - rel).squaredNorm()
                                + 0.5 * sum(s.inertia[i] * w[i] ** 2 for i in range(3))
                                + b["mass"] * G * (s.pos[2] - b["initial_pos"][2]))
    return all(tilt[k] == {"lies"} or (tilt[k] == {"stands"}
                                       and energy[k] < SETTLED_FRACTION * BARRIERS[k])
               for k in BARRIERS)


# a standing body is seated when, against the column's bottom body, it has shifted and
# tilted (times the column's height) by at most this fraction of the column's smallest
# rocking lever: the levers then differ from the start's by a few per cent, inside the
# pre-check's 10 % margin
SEATED_FRACTION = THRESHOLDS["seated_fraction"]
SEATED = []      # per body: (index of its column's bottom body, shift tolerance m, tilt tol rad)
for col in COLUMNS:
    bottom = len(SEATED)
    tol = SEATED_FRACTION * col["rocking_lever_m"]
    SEATED += [(bottom, tol, tol / col["height"])] * len(col["bodies"])
INITIAL_AXES = [Vector3(*np.asarray(b["initial_rotation"], float)[:, 2]) for b in bodies]


def seated(axes):
    """True when every standing body (``axes``: its z axis, None when lying) is seated
    (SEATED_FRACTION) on its column's bottom body as at the start."""
    for k, (axis, s, b) in enumerate(zip(axes, states, bodies)):
        if axis is None:
            continue
        bottom, shift_tol, tilt_tol = SEATED[k]
        if shift_tol <= 0 or axes[bottom] is None:
            return False
        shift = (s.pos - states[bottom].pos) - (Vector3(*b["initial_pos"])
                                               - Vector3(*bodies[bottom]["initial_pos"]))
        if math.hypot(shift[0], shift[1]) > shift_tol:
            return False
        if 1.0 - axis.dot(INITIAL_AXES[k]) > 0.5 * tilt_tol ** 2:
            return False
    return True


def check_stop():
    """Stop once the standing bodies rest and either the motion is over, or every column
    has fallen, or no later sample can set them moving again (after quiet_after, every
    standing body seated); or once the motion is over and no column can topple any more
    (energy).  Bodies lying on the pedestal (tilt > 60 deg) may roll on: their impact is
    recorded already and a rolling cylinder takes long to stop."""
    v_rest, length = REST_VELOCITY, REST_LENGTH
    rel = pedestal_state.vel
    t = now()
    if BARRIERS and t > signal_end and settled(rel):
        state["stopped_early"] = True
        record_state()
        O.pause()
        return
    at_rest, fallen, axes = True, {}, []
    for b, s, c, lies_up in zip(bodies, states, clumps, LIES_AT):
        axis = up_axis(s, c)
        lying = axis[2] < lies_up
        axes.append(None if lying else axis)
        fallen[b["column"]] = fallen.get(b["column"], False) or lying
        if not lying and ((s.vel - rel).norm() >= v_rest or s.angVel.norm() * length >= v_rest):
            at_rest = False
    if at_rest and (t > signal_end or all(fallen.values()) or (t > quiet_after and seated(axes))):
        if state["rest_since"] is None:
            state["rest_since"] = t
        elif t - state["rest_since"] >= REST_DURATION_S:
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
        disp = shift[:, 0, :] + (motion_at("disp", [START_S])[0] if START_S else 0.0)
    else:
        disp = motion_at("disp", t)
    out = os.path.join(HERE, OUTPUT)
    tmp = out + ".tmp.npz"
    np.savez_compressed(
        tmp, t=t, pedestal_disp=disp, pos=pos - shift,
        quat=quat_multiply(ori.reshape(len(t), len(clumps), 4), offsets[None]), vel=vel - ped_vel,
        angvel=angvel, bodies=json.dumps(bodies), dt=O.dt,
        stopped_early=state["stopped_early"], motion_end=motion_end, start_s=START_S)
    os.replace(tmp, out)


# ---------------------------------------------------------------- engines
friction_steps = max(1, int(round(FRICTION_INTERVAL_S / O.dt)))
stop_steps = max(1, int(round(THRESHOLDS["stop_interval_s"] / O.dt)))
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
if not P["early_stop"]:          # simulate to T_MAX: the motion lasts until then for the checks
    signal_end = quiet_after = T_MAX
MEASURE = P["measure"]
O.timingEnabled = MEASURE["engine_timing_file"] is not None
loop_start = (time.perf_counter(), time.process_time())
O.run()
O.wait()
while O.running:
    time.sleep(0.01)
if MEASURE["loop_clock_file"] is not None:
    with open(os.path.join(HERE, MEASURE["loop_clock_file"]), "w") as fh:
        json.dump({"loop_wall_s": time.perf_counter() - loop_start[0],
                   "loop_cpu_s": time.process_time() - loop_start[1]}, fh)
finish()
if MEASURE["engine_timing_file"] is not None:
    from yade import timing
    for engine in O.engines:
        if isinstance(engine, PyRunner):
            engine.label = engine.command.split("(")[0]
    print("ENGINE TIMING BEGIN")
    timing.stats()
    print("ENGINE TIMING END", flush=True)
    with open(os.path.join(HERE, MEASURE["engine_timing_file"]), "w") as fh:
        json.dump([{"engine": e.label or type(e).__name__, "exec_ns": e.execTime,
                    "count": e.execCount, "dead": e.dead} for e in O.engines], fh)
