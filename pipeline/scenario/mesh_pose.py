"""A mesh specimen's rest pose on the table: the solid (:mod:`pipeline.scenario.mesh_surface`)
settled onto its stable pose nearest the given orientation (or kept as given), turned to
its heading, its centre of mass above the origin and its lowest point on the table; the
footprint it stands on, the hull points it can land on and its mass properties per kg."""
import functools
from pathlib import Path

import numpy as np

from pipeline.files import InputError
from pipeline.scenario.mesh_surface import read_solid
from scipy.spatial.transform import Rotation
from scipy.spatial import ConvexHull, QhullError

MAX_POSE_HULL_FACES = 20_000      # the rest pose is found on a hull of at most this many


@functools.lru_cache(maxsize=8)
def _posed(path, digest, scale, rotation_wxyz, rest_pose, heading_deg, tolerance, close_base,
           where):
    """Mass properties (per kg), footprint and hull of the mesh in its rest pose, and what
    was repaired to read it (``close_base`` in metres)."""
    name = Path(path).name
    w, x, y, z = rotation_wxyz
    mesh, repairs, cap_area, _ = read_solid(path, scale, _matrix(Rotation.from_quat([x, y, z, w])),
                                            close_base, where)
    hull = mesh.convex_hull
    inside = ((mesh.center_mass - hull.triangles_center) * hull.face_normals).sum(axis=1)
    if not (inside < 0).all():     # the stable-pose search would sample it forever
        raise InputError(f"{where}: mesh {name}: its centre of mass is not inside its convex "
                         "hull (a self-intersecting or flat surface)")
    settle = _settled(mesh, hull, rest_pose, repairs, name, where)
    hull = _placed(mesh, hull, _matrix(Rotation.from_euler("z", -heading_deg, degrees=True)
                                       * settle))
    com = np.array(mesh.center_mass, float)
    outline = _footprint(hull, com, tolerance, where)
    inertia_per_kg = _inertia_per_kg(mesh, name, where)
    landing = hull[hull[:, 2] > tolerance + 1e-9]
    return {"volume": float(mesh.volume), "com": com,
            "inertia_per_kg": inertia_per_kg,
            "footprint": outline, "hull_points": landing,
            "extent": tuple(float(e) for e in np.ptp(mesh.vertices, axis=0)),
            "settled_by_deg": float(np.degrees((settle).magnitude())),
            "repairs": tuple(repairs), "cap_area_m2": cap_area}


def _settled(mesh, hull, rest_pose, repairs, name, where):
    """The rotation (scipy) from the given orientation to the rest pose: none for "given",
    else onto the stable pose whose up direction is nearest (rolled there on a large hull)."""
    if rest_pose != "nearest":
        return Rotation.identity()
    if len(hull.faces) > MAX_POSE_HULL_FACES:
        repairs.append(f"rest pose found by rolling on its convex hull of "
                       f"{len(hull.faces):,} faces (the stable poses are sought on "
                       f"at most {MAX_POSE_HULL_FACES:,})")
        return _rolled(hull, mesh.center_mass)
    transforms, _ = mesh.compute_stable_poses()
    if not len(transforms):
        raise InputError(f"{where}: mesh {name}: no stable pose found")
    ups = [np.linalg.inv(T[:3, :3]) @ [0.0, 0.0, 1.0] for T in transforms]
    # the stable pose whose up direction is nearest the given orientation's
    up = max(ups, key=lambda u: u[2])
    return Rotation.align_vectors([[0.0, 0.0, 1.0]], [up])[0]


def _placed(mesh, hull, matrix):
    """Turn ``mesh`` by ``matrix`` and move it onto the table, its centre of mass above
    the origin (in place); the hull's vertices moved with it, (n, 3)."""
    import trimesh  # lazy: trimesh, only for mesh specimens
    mesh.apply_transform(matrix)
    hull = trimesh.transform_points(hull.vertices, matrix)
    lowest = mesh.vertices[:, 2].min()
    com = mesh.center_mass
    shift = np.array([-com[0], -com[1], -lowest])
    mesh.apply_translation(shift)
    return hull + shift


def _footprint(hull, com, tolerance, where):
    """The (k, 2) outline of the hull points within ``tolerance`` (m) of the table;
    InputError when they do not hold the centre of mass up."""
    from matplotlib.path import Path as Polygon  # lazy: matplotlib, only for mesh specimens' footprints
    near = hull[hull[:, 2] <= tolerance + 1e-9]
    try:
        outline = near[ConvexHull(near[:, :2]).vertices][:, :2] if len(near) >= 3 else None
    except QhullError:                              # the points lie on a line
        outline = None
    if outline is None:
        raise InputError(f"{where}: fewer than 3 hull points within footprint_tolerance_m "
                         f"{tolerance:g} m of the table: it cannot stand (raise the tolerance)")
    if not Polygon(outline).contains_point(com[:2]):
        raise InputError(f"{where}: the centre of mass lies outside the footprint in this "
                         "pose: the specimen cannot stand (use rest_pose \"nearest\")")
    return outline


def _inertia_per_kg(mesh, name, where):
    """The 3 x 3 inertia per kg (m^2) about the centre of mass; InputError when it is not
    a solid's."""
    inertia_per_kg = np.array(mesh.moment_inertia, float) / mesh.volume
    moments = np.linalg.eigvalsh(inertia_per_kg)   # a solid's: positive, I3 <= I1 + I2
    if moments[0] <= 0 or moments[2] > (moments[0] + moments[1]) * (1 + 1e-9):
        raise InputError(f"{where}: mesh {name}: its surface crosses itself (its moments of "
                         "inertia are not those of a solid)")
    return inertia_per_kg


def _matrix(rotation):
    """The 4 x 4 transform of a scipy Rotation."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation.as_matrix()
    return matrix


def _rolled(hull, com):
    """The rotation that sets a body down on the table as it rolls there (hull: its convex
    hull, trimesh; com: its centre of mass, (3,)): from the hull face below the centre of
    mass, it tips over the edge of each face the centre of mass lies beyond onto the
    neighbouring face, until the centre of mass lies above the face it stands on."""
    normals, corners = hull.face_normals, hull.vertices[hull.faces]
    down = normals[:, 2] < 0          # the face a vertical line down from com leaves by
    drop = np.full(len(normals), np.inf)
    drop[down] = ((corners[down, 0] - com) * normals[down]).sum(axis=1) / -normals[down, 2]
    face = int(np.argmin(drop))
    n = len(hull.vertices)
    sides = np.sort(hull.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    keys = sides[:, 0] * n + sides[:, 1]
    order = np.argsort(keys, kind="stable")
    for _ in range(len(hull.faces)):              # each step lowers the centre of mass
        a, b, c = corners[face]
        normal = normals[face]
        p = com - ((com - a) @ normal) * normal       # com projected onto the face
        weights = np.linalg.solve(np.column_stack([b - a, c - a, normal]), p - a)[:2]
        weights = np.array([1 - weights.sum(), *weights])   # barycentric, at a, b, c
        if weights.min() >= -1e-12:
            break
        beyond = int(np.argmin(weights))               # the side opposite that corner
        u, v = sorted(hull.faces[face][[(beyond + 1) % 3, (beyond + 2) % 3]])
        found = order[np.searchsorted(keys, u * n + v, sorter=order):][:2] // 3
        face = int(found[found != face][0])
    return Rotation.align_vectors([[0.0, 0.0, -1.0]], [normals[face]])[0]
