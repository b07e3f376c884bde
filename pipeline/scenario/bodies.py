"""The rigid bodies of a described column (:class:`Body`: one block or several joined
ones, with mass properties, placement and contact rims), its statics, and a column placed
on the pedestal for the scene (:class:`ColumnSpec`)."""
import math
from dataclasses import dataclass, field

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.scenario.outline import Outline, _edge_distances, contact_outline, perimeter_points
from pipeline.scenario.scene_file import SceneBody, SceneColumn
from pipeline.scenario.solids import ColumnBlock
from pipeline.scenario.specimen import Specimen


@dataclass
class Part:
    """One block inside a body, in the body's base frame (origin at the body's bottom
    face centre, axes of its bottom block)."""
    block: ColumnBlock
    index: int                     # index of the block in the description
    bottom: np.ndarray             # bottom face centre (3,)
    mass: float
    centroid: np.ndarray           # (3,)
    inertia: tuple                 # principal, about its centroid, base-frame axes


@dataclass
class Body:
    """A rigid body of the scene: one block, or several joined blocks."""
    index: int
    parts: list
    mass: float
    com: np.ndarray                # in the base frame
    inertia: np.ndarray            # 3 x 3 about the COM, base-frame axes
    rotation: np.ndarray           # world rotation of the base frame
    base_world: np.ndarray         # world position of the bottom face centre
    contact: Outline               # contact area outline, base frame (x, y)
    support_rotation: np.ndarray   # world rotation of the plane it stands on
    edge_mode: bool
    rims: list = field(default_factory=list)

    @property
    def centre(self):
        return self.base_world + self.rotation @ self.com

    @property
    def top(self):
        """Top face centre of the top part (base frame) and its outline (centred at 0)."""
        p = self.parts[-1]
        return p.bottom + np.array([0.0, 0.0, p.block.solid.height]), \
            p.block.solid.outline("top")

    @property
    def name(self):
        names = [p.block.name for p in self.parts if p.block.name]
        if len(names) > 3:
            return f"{names[0]} .. {names[-1]}"
        return " + ".join(names) if names else None


def _build(geometry, x, y):
    bodies = []
    for k, block in enumerate(geometry.blocks):
        density = geometry.density if block.density is None else block.density
        m, zc, inertia = block.solid.mass_properties(density)
        offset = np.array([block.offset_m[0], block.offset_m[1], 0.0])
        if block.joined:
            body = bodies[-1]
            bottom = body.top[0] + offset
            body.parts.append(Part(block, k, bottom, m, bottom + np.array([0.0, 0.0, zc]),
                                   inertia))
            _finish(body)
            continue
        if bodies:                                   # stands on the top face below
            below = bodies[-1]
            top, support_face = below.top
            support_origin = below.base_world + below.rotation @ top
            support_rot = below.rotation
        else:                                        # on the pedestal (unlimited)
            support_origin, support_rot, support_face = np.array([x, y, 0.0]), np.eye(3), None
        R = block.rotation()
        Q = support_rot.T @ R                        # relative to the face it stands on
        own = block.solid.outline("bottom")
        try:
            contact = contact_outline(support_face, own.shifted(*block.offset_m))
        except InputError as exc:
            raise InputError(f"blocks[{k}] on the block below: {exc}") from None
        contact = contact.shifted(-block.offset_m[0], -block.offset_m[1])
        c = offset
        edge_mode = block.tilt_mode == "edge" and block.tilt_deg > 0
        if edge_mode:                                # pivot about the lowest edge point
            pivot = _lowest_point(own, Q)
            c = offset + (pivot - Q @ pivot)
        base_world = support_origin + support_rot @ c
        part = Part(block, k, np.zeros(3), m, np.array([0.0, 0.0, zc]), inertia)
        bodies.append(Body(len(bodies), [part], m, part.centroid, np.diag(inertia), R,
                           base_world, contact, support_rot, edge_mode))
    for body in bodies:
        body.rims = _rims(body, geometry.edge_rims)
    return bodies


def _finish(body):
    """Mass, centre of mass and inertia tensor of a body from its parts."""
    if len(body.parts) == 1:
        p = body.parts[0]
        body.mass, body.com, body.inertia = p.mass, p.centroid, np.diag(p.inertia)
        return
    masses = np.array([p.mass for p in body.parts])
    body.mass = math.fsum(masses)
    body.com = (masses[:, None] * np.array([p.centroid for p in body.parts])).sum(0) / body.mass
    tensor = np.zeros((3, 3))
    for p in body.parts:
        d = p.centroid - body.com
        tensor += np.diag(p.inertia) + p.mass * (d @ d * np.eye(3) - np.outer(d, d))
    body.inertia = tensor


def _lowest_point(outline, Q):
    """Point (3,) of a bottom outline (base frame, z = 0) lowest after rotation Q (ties:
    their mean, e.g. the midpoint of an edge)."""
    grad = Q[2, :2]
    if outline.kind == "circle":
        n = np.hypot(*grad)
        u = -grad / n if n > 0 else np.zeros(2)
        return np.array([outline.centre[0] + outline.radius * u[0],
                         outline.centre[1] + outline.radius * u[1], 0.0])
    v = outline.polygon()
    height = v @ grad
    lowest = v[height <= height.min() + 1e-12 * max(1.0, np.abs(v).max())]
    return np.append(lowest.mean(axis=0), 0.0)


def _rims(body, edge_rims):
    """Rims of contact spheres (base frame, z of the face, outline, normal into the body):
    the base rim on the contact area (role "base"), then unless ``edge_rims`` is False
    the body's other outer edges (role "edge"): its own bottom outline when it differs
    from the contact area, steps between joined parts, and the top face."""
    wedge = np.eye(3) if body.edge_mode else body.rotation.T @ body.support_rotation
    normal = wedge[:, 2]                     # support plane normal in the base frame
    rims = [{"role": "base", "z": 0.0, "outline": body.contact, "normal": normal}]
    if not edge_rims:
        return rims
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    first = body.parts[0]
    own = first.block.solid.outline("bottom").shifted(*first.bottom[:2])
    if not own.same_as(body.contact):
        rims.append({"role": "edge", "z": 0.0, "outline": own, "normal": up})
    for lower, upper in zip(body.parts, body.parts[1:]):
        z = upper.bottom[2]
        top = lower.block.solid.outline("top").shifted(*lower.bottom[:2])
        bottom = upper.block.solid.outline("bottom").shifted(*upper.bottom[:2])
        if top.same_as(bottom):
            continue                          # a continuous side: no edge
        if not top.contains(bottom):
            rims.append({"role": "edge", "z": z, "outline": bottom, "normal": up})
        if not bottom.contains(top):
            rims.append({"role": "edge", "z": z, "outline": top, "normal": down})
    top_centre, top_outline = body.top
    rims.append({"role": "edge", "z": top_centre[2],
                 "outline": top_outline.shifted(*top_centre[:2]), "normal": down})
    return rims


# ---------------------------------------------------------------- statics
def _statics(bodies, g):
    joints = []
    for k, body in enumerate(bodies):
        stack = bodies[k:]
        mass = math.fsum(b.mass for b in stack)
        com = np.array([math.fsum(b.mass * b.centre[i] for b in stack) for i in range(3)]) / mass
        if body.edge_mode:
            joints.append({"body": k, "from_block": body.parts[0].index, "ratio": 0.0,
                           "lever_m": 0.0, "barrier_j": 0.0, "mass_kg": mass,
                           "com_m": com.tolist()})
            continue
        plane_rot = body.support_rotation
        tilted = not np.array_equal(plane_rot, np.eye(3))
        contact = body.contact
        if contact.kind == "circle" and not tilted:
            centre = body.base_world[:2] + np.array(contact.centre)
            d = np.array([contact.radius - math.dist(com[:2], centre)])
            h = np.array([com[2] - body.base_world[2]])
        else:
            # contact area in the world: in the plane through the base centre
            poly = contact.polygon()
            world = body.base_world + np.column_stack(
                [poly, np.zeros(len(poly))]) @ plane_rot.T
            d = _edge_distances(world[:, :2], com[:2])
            h = com[2] - 0.5 * (world[:, 2] + np.roll(world[:, 2], -1))
        ratio = d / h
        barrier = mass * g * (np.hypot(d, h) - h)
        joints.append({"body": k, "from_block": body.parts[0].index,
                       "ratio": float(ratio.min()), "lever_m": float(d.min()),
                       "barrier_j": float(barrier.min()),
                       "mass_kg": mass, "com_m": com.tolist()})
    return joints


# ---------------------------------------------------------------- placed columns
@dataclass(frozen=True)
class ColumnSpec:
    """A column placed on the pedestal: ``name`` (its role in outputs: drums,
    monolithic, block), ``kind`` and position (m)."""
    name: str
    kind: str
    x: float
    y: float
    geometry: Specimen

    def scene(self, rim_points):
        """The ``params.json`` entry of this column
        (:class:`~pipeline.scenario.scene_file.SceneColumn`, as a dict)."""
        return self.geometry.scene_column(self, rim_points).to_dict()


def column_scene(geometry, spec, rim_points):
    """The :class:`~pipeline.scenario.scene_file.SceneColumn` of a column of blocks placed
    as ``spec``: bodies with placement, mass properties, rims and plates (body frames
    centred on the centre of mass), its rocking threshold (``uplift_ratio``), the smallest
    horizontal distance from a rocking edge to the centre of mass of the stack above it
    (``rocking_lever_m``) and the overturning energy barrier."""
    bodies = geometry.bodies(spec.x, spec.y)
    statics = _statics(bodies, MODEL_GRAVITY)
    n = len(bodies)
    # a body released on its edge is not at rest at the start: no energy criterion
    settles = geometry.settles and not any(b.edge_mode for b in bodies)
    return SceneColumn(
        name=spec.name, kind=spec.kind, x=spec.x, y=spec.y, description=geometry.name,
        height=geometry.height, n_bodies=n, uplift_ratio=min(j["ratio"] for j in statics),
        rocking_lever_m=min(j["lever_m"] for j in statics),
        overturning_barrier_j=min(j["barrier_j"] for j in statics) if settles else None,
        settles=settles, bodies=[_body_scene(spec, b, n, rim_points) for b in bodies])


def _body_scene(spec, body, n_bodies, rim_points):
    com = body.com
    inertia = body.inertia
    off = inertia - np.diag(np.diag(inertia))
    if np.abs(off).max() > 1e-12 * np.abs(inertia).max():
        _, axes = np.linalg.eigh(inertia)
    else:
        axes = np.eye(3)
    rims = []
    for rim in body.rims:
        o = rim["outline"]
        entry = {"role": rim["role"], "z": rim["z"] - com[2], "normal": list(rim["normal"])}
        if o.kind == "circle":
            entry.update(kind="circle", radius=o.radius,
                         centre=[o.centre[0] - com[0], o.centre[1] - com[1]])
        else:
            v = o.polygon() - com[:2]
            entry.update(kind="polygon", vertices=v.tolist(),
                         points=perimeter_points(v, rim_points).tolist())
        rims.append(entry)
    top, top_outline = body.top
    hx, hy = top_outline.half_extents()
    plate = None
    if body.index < n_bodies - 1:
        plate = {"centre": [top[0] - com[0], top[1] - com[1], top[2] - com[2]],
                 "half_size": [hx, hy]}
    parts = []
    for p in body.parts:
        entry = dict(p.block.solid.to_dict(), block=p.index, name=p.block.name,
                     bottom_centre=[p.bottom[0] - com[0], p.bottom[1] - com[1],
                                    p.bottom[2] - com[2]])
        parts.append(entry)
    centre = body.base_world + body.rotation @ com
    if np.array_equal(body.rotation, np.eye(3)):
        centre = body.base_world + com            # exact sums for an upright body
    shape = parts[0]["shape"] if len(parts) == 1 else "composite"
    return SceneBody(name=f"{spec.name}[{body.index}]", column=spec.name, index=body.index,
                     block_name=body.name, blocks=[p.index for p in body.parts], shape=shape,
                     height=float(top[2]), mass=body.mass, inertia=inertia.tolist(),
                     principal_axes=axes.tolist(), centre=centre.tolist(),
                     rotation=body.rotation.tolist(), column_position=[spec.x, spec.y],
                     parts=parts, rims=rims, plate=plate)
