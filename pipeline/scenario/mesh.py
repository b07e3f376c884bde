"""A specimen from a triangle mesh (a scanned rock): exact mass properties from the
mesh, its rest pose on the table, and contact points that follow its footprint and the
faces it can land on.

A mesh specimen is given as a mesh file (``.obj``, ``.ply``, ``.stl``, read by trimesh)
or as a JSON file that names one (schema in docs/shake-table.md, "Mesh specimens")::

    {"name": "SP1", "mesh": "SP1.obj", "mass_kg": 353.8,
     "units": "m", "rotation_wxyz": [1, 0, 0, 0], "rest_pose": "nearest",
     "heading_deg": 0, "footprint_tolerance_m": 0.003}

- ``mass_kg`` or ``density`` (kg/m^3; a bare mesh file gets DEFAULT_DENSITY, granite);
  the inertia is the mesh's, scaled to that mass.
- ``rotation_wxyz`` turns the mesh into the table frame (x East, y North, z up; default:
  the mesh's own axes, as a scan of a rock standing on the table has them).
- ``rest_pose``: "nearest" (default) lets the specimen settle onto the table: the stable
  pose of its convex hull (trimesh) nearest to the given orientation, reached by the
  smallest rotation; "given" keeps the orientation, which must then stand by itself.
- ``heading_deg`` turns the specimen clockwise (seen from above) about the vertical.
- ``footprint_tolerance_m``: the specimen stands on the hull's points within this height
  of the table (a rough base seats on its asperities); the outline of those points is
  the footprint, whose edges it rocks about.
- ``close_base``: "fit" or the ground plane's height (in ``units``): an open base is
  closed by a planar cap at that plane (fitted to the lowest hole's edge for "fit").

The mesh is read as its geometry (:func:`_geometry`): vertices merged by position
(texture coordinates and normals do not split a surface), degenerate and duplicate faces
dropped, the winding made consistent; only then is it judged closed.  What was repaired
is said in one line on stderr and kept as ``repairs`` in :meth:`MeshSpecimen.to_dict`.
Every limit is checked before the heavy work (MAX_FACES, counted in the file's bytes).

In the scene the specimen is one clump: contact spheres along the footprint's outline
(the base rim, ``rim_points`` per full turn of its corners as a column's rim) and on up to
LANDING_POINTS_PER_RIM_POINT x ``rim_points`` hull vertices elsewhere (the faces it can
land on), each sphere one radius inside the surface.
"""
import functools
import hashlib
import math
import multiprocessing
import re
import struct
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.scenario.column_format import DENSITY_RANGE
from pipeline.scenario.outline import perimeter_points
from pipeline.scenario.scene_file import SceneBody, SceneColumn
from pipeline.scenario.specimen import Specimen
from pipeline.userfiles import keys_text, number, show

MESH_SUFFIXES = (".obj", ".ply", ".stl")   # the mesh files trimesh reads here

MAX_MESH_BYTES = 200_000_000
MAX_FACES = 1_000_000             # triangles of a mesh (a scan decimated for simulation)
MAX_POSE_HULL_FACES = 20_000      # the rest pose is found on a hull of at most this many
ZERO_VOLUME = 1e-9                # volumes below this fraction of size^3 are flat surfaces
CLOSE_BASE_REACH = 0.25           # the ground plane within this fraction of the size
CLOSE_BASE_RANGE = (-1e7, 1e7)    # the ground plane's height, in the mesh's units
DEFAULT_DENSITY = 2650.0          # kg/m^3, granite
MASS_RANGE = (1e-3, 1e7)          # kg
SIZE_RANGE_M = (0.02, 30.0)       # largest extent of a specimen
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
REST_POSES = ("nearest", "given")
DEFAULT_FOOTPRINT_TOLERANCE_M = 0.003
FOOTPRINT_TOLERANCE_RANGE_M = (0.0, 0.05)
LANDING_POINTS_PER_RIM_POINT = 4
KEYS = {"name", "mesh", "mass_kg", "density", "units", "rotation_wxyz", "rest_pose",
        "heading_deg", "footprint_tolerance_m", "close_base", "source", "notes",
        "mesh_sha256", "repairs"}     # the last two written by to_dict


@dataclass(frozen=True)
class MeshSpecimen(Specimen):
    """A rigid specimen from a mesh, in its rest pose on the table (x East, y North, z
    up; the table at z = 0, the centre of mass above the origin).  Lengths m, mass kg."""
    name: str
    mesh_path: str
    mesh_sha256: str
    options: dict                   # the description's other keys, as given (to_dict)
    mass: float
    volume_m3: float
    com: np.ndarray = field(repr=False)            # (3,) table frame
    inertia: np.ndarray = field(repr=False)        # 3 x 3 about the centre of mass
    footprint: np.ndarray = field(repr=False)      # (k, 2) CCW outline it stands on
    hull_points: np.ndarray = field(repr=False)    # (n, 3) hull vertices above it
    extent_m: tuple = ()                           # (x, y, z) size of the posed specimen
    settled_by_deg: float = 0.0     # rotation from the given orientation to the rest pose
    source: str = None
    notes: str = None
    repairs: tuple = ()             # what was repaired to read the mesh (provenance)

    # ------------------------------------------------------------ loading
    @classmethod
    def load(cls, path):
        """A specimen from a bare mesh file (a JSON description naming one is read by
        :meth:`pipeline.scenario.geometry.ColumnGeometry.load`, as column files are)."""
        path = Path(path)
        return cls.from_dict({"name": path.stem, "mesh": str(path.resolve())},
                             where=path.name)

    @classmethod
    def from_dict(cls, data, where="specimen description", base=None):
        """Validate a description dict (``mesh`` relative to ``base``); one-line InputError."""
        if not isinstance(data, dict) or "mesh" not in data:
            raise InputError(f"{where}: a mesh specimen needs a 'mesh' file")
        unknown = set(data) - KEYS
        if unknown:
            raise InputError(f"{where}: unknown key(s) {keys_text(unknown)} "
                             f"(allowed: {', '.join(sorted(KEYS))})")
        name = data.get("name", "specimen")
        if not isinstance(name, str) or not name.strip() or len(name) > 80:
            raise InputError(f"{where}: 'name' must be a non-empty string (at most 80 "
                             "characters)")
        if not isinstance(data["mesh"], str):
            raise InputError(f"{where}: 'mesh' must be a file name, got {show(data['mesh'])}")
        mesh = Path(data["mesh"])
        if not mesh.is_absolute() and base is not None:
            mesh = Path(base) / mesh
        if mesh.suffix.lower() not in MESH_SUFFIXES:
            raise InputError(f"{where}: mesh {mesh.name}: not a mesh file "
                             f"({', '.join(MESH_SUFFIXES)})")
        if "mass_kg" in data and "density" in data:
            raise InputError(f"{where}: give 'mass_kg' or 'density', not both")
        mass = _number(data, "mass_kg", None, *MASS_RANGE, where)
        density = _number(data, "density", None, *DENSITY_RANGE, where)
        units = data.get("units", "m")
        if units not in UNITS:
            raise InputError(f"{where}: 'units' must be one of {', '.join(UNITS)}, got "
                             f"{show(units)}")
        rotation = data.get("rotation_wxyz", [1.0, 0.0, 0.0, 0.0])
        if not isinstance(rotation, list) or len(rotation) != 4:
            raise InputError(f"{where}: 'rotation_wxyz' must be 4 finite numbers, not all "
                             f"zero (a quaternion w, x, y, z), got {show(rotation)}")
        rotation = [number(q, f"{where}: 'rotation_wxyz'") for q in rotation]
        largest = max(abs(q) for q in rotation)
        if largest == 0:
            raise InputError(f"{where}: 'rotation_wxyz' must not be all zero (a quaternion "
                             "w, x, y, z)")
        rotation = [q / largest for q in rotation]          # any length: a direction
        rest_pose = data.get("rest_pose", "nearest")
        if rest_pose not in REST_POSES:
            raise InputError(f"{where}: 'rest_pose' must be one of {', '.join(REST_POSES)}, "
                             f"got {show(rest_pose)}")
        heading = _number(data, "heading_deg", 0.0, -360.0, 360.0, where)
        tolerance = _number(data, "footprint_tolerance_m", DEFAULT_FOOTPRINT_TOLERANCE_M,
                            *FOOTPRINT_TOLERANCE_RANGE_M, where)
        close_base = data.get("close_base")
        if close_base is not None and close_base != "fit":
            if isinstance(close_base, str):
                raise InputError(f"{where}: 'close_base' must be \"fit\" or the ground "
                                 f"plane's height (a number), got {show(close_base)}")
            close_base = number(close_base, f"{where}: 'close_base'", *CLOSE_BASE_RANGE)
            close_base *= UNITS[units]
        for key in ("source", "notes"):
            if data.get(key) is not None and not isinstance(data[key], str):
                raise InputError(f"{where}: '{key}' must be a string")
        if not mesh.is_file():
            raise InputError(f"{where}: mesh file not found: {mesh}")
        if mesh.stat().st_size > MAX_MESH_BYTES:
            raise InputError(f"{where}: mesh {mesh.name} is larger than "
                             f"{MAX_MESH_BYTES // 1_000_000} MB")
        content = mesh.read_bytes()
        digest = hashlib.sha256(content).hexdigest()
        if data.get("mesh_sha256") not in (None, digest):
            raise InputError(f"{where}: mesh {mesh.name} is not the file described "
                             "(its SHA-256 differs from 'mesh_sha256')")
        for count, what, most in zip(_declared(content, mesh.suffix.lower())[::-1],
                                     ("faces", "vertices"), (MAX_FACES, 3 * MAX_FACES)):
            if count is not None and count > most:
                raise InputError(f"{where}: mesh {mesh.name} has {count:,} {what}, more "
                                 f"than {most:,}: decimate it first")
        del content
        options = {k: data[k] for k in ("mass_kg", "density", "units", "rotation_wxyz",
                                         "rest_pose", "heading_deg", "footprint_tolerance_m",
                                         "close_base")
                   if k in data}
        posed = _posed(str(mesh), digest, UNITS[units], tuple(rotation), rest_pose, heading,
                       tolerance, close_base, where)
        volume = posed["volume"]
        if mass is None:
            mass = (DEFAULT_DENSITY if density is None else density) * volume
        elif not DENSITY_RANGE[0] <= mass / volume <= DENSITY_RANGE[1]:
            raise InputError(f"{where}: 'mass_kg' {mass:g} over the mesh's volume "
                             f"{volume:.4g} m^3 is a density of {mass / volume:.4g} kg/m^3: "
                             f"expected {DENSITY_RANGE[0]:g}-{DENSITY_RANGE[1]:g} kg/m^3 "
                             "(check 'mass_kg' and 'units')")
        if posed["repairs"]:
            _say(f"{'note' if posed['cap_area_m2'] is None else 'warning'}: {where}: mesh "
                 f"{mesh.name} read as its geometry: {', '.join(posed['repairs'])}")
        return cls(name.strip(), str(mesh), digest, options, float(mass), volume,
                   posed["com"], posed["inertia_per_kg"] * mass, posed["footprint"],
                   posed["hull_points"], posed["extent"], posed["settled_by_deg"],
                   data.get("source"), data.get("notes"), posed["repairs"])

    def to_dict(self):
        """The description (absolute mesh path and its SHA-256: run ids follow the file)."""
        out = self._described({"name": self.name, "mesh": self.mesh_path,
                               "mesh_sha256": self.mesh_sha256, **self.options})
        if self.repairs:
            out["repairs"] = list(self.repairs)
        return out

    # ------------------------------------------------------------ what campaigns ask
    @property
    def height(self):
        """Height (m) of the specimen standing on the table."""
        return float(self.extent_m[2])

    @property
    def base_width(self):
        """Smallest width (m) of the footprint."""
        return float(2 * min(self._edge_levers()))

    @property
    def density(self):
        """Mean density (kg/m^3): mass over the mesh's volume."""
        return self.mass / self.volume_m3

    def monolithic(self):
        """The specimen itself: it is one stone."""
        return self

    def bodies(self, x=0.0, y=0.0):
        """Its rigid bodies: itself (one stone)."""
        return [self]

    def _edge_levers(self):
        """Horizontal distance (m) from the centre of mass to each footprint edge."""
        a = self.footprint
        b = np.roll(a, -1, axis=0)
        e = b - a
        normal = np.column_stack([e[:, 1], -e[:, 0]]) / np.hypot(*e.T)[:, None]
        return np.abs(((self.com[:2] - a) * normal).sum(axis=1))

    def statics(self, g=MODEL_GRAVITY):
        """One joint (the specimen on the table): rocking threshold / g about its weakest
        footprint edge (``ratio`` = tan of the critical angle), its lever (m) and the
        smallest energy (J) that tips it over an edge."""
        d = self._edge_levers()
        h = float(self.com[2])
        return [{"body": 0, "from_block": 0, "ratio": float(d.min() / h),
                 "lever_m": float(d.min()), "barrier_j":
                 float((self.mass * g * (np.hypot(d, h) - h)).min()),
                 "mass_kg": self.mass, "com_m": self.com.tolist()}]

    def critical_angle_deg(self):
        """Smallest angle (deg) it must be tilted about a footprint edge to fall."""
        return math.degrees(math.atan(self.uplift_ratio()))

    def critical_angle_along_deg(self, azimuth_deg):
        """Critical angle (deg) for tipping along a horizontal line (azimuth, deg clockwise
        from North): the smaller of tipping toward it and away from it, about the
        footprint's extreme support lines across it."""
        a = math.radians(azimuth_deg)
        u = np.array([math.sin(a), math.cos(a)])
        along = (self.footprint - self.com[:2]) @ u
        lever = min(along.max(), -along.min())
        return math.degrees(math.atan(lever / self.com[2]))

    def check_rims(self, rim_sphere_radius):
        """Nothing to check: its contact spheres lie on its surface points."""

    def contact_rocking_hz(self, kn, rim_points=16):
        """Frequency (Hz) of the specimen rocking on the contact springs of its footprint
        outline (kn N/m per point), the smaller about the two horizontal axes."""
        pts = perimeter_points(self.footprint, rim_points) - self.com[:2]
        out = []
        for axis, other in ((0, 1), (1, 0)):
            inertia = self.inertia[other, other] + self.mass * self.com[2] ** 2
            out.append(math.sqrt(kn * (pts[:, axis] ** 2).sum() / inertia) / (2 * math.pi))
        return min(out)

    def scene_column(self, spec, rim_points):
        """The :class:`~pipeline.scenario.scene_file.SceneColumn` of this specimen placed as ``spec``
        (:class:`~pipeline.scenario.geometry.ColumnSpec`): one body whose rims are
        explicit points (body frame about the centre of mass) with inward normals."""
        com = self.com
        base = perimeter_points(self.footprint, rim_points) - com[:2]
        base3 = np.column_stack([base, np.full(len(base), -com[2])])
        landing = _spread(self.hull_points, LANDING_POINTS_PER_RIM_POINT * rim_points) - com
        inward = -landing / np.linalg.norm(landing, axis=1)[:, None]
        up = np.tile([0.0, 0.0, 1.0], (len(base3), 1))
        joint = self.statics()[0]
        critical = math.degrees(math.atan(joint["ratio"]))
        _, axes = np.linalg.eigh(self.inertia)
        body = SceneBody(
            name=f"{spec.name}[0]", column=spec.name, index=0, block_name=self.name,
            blocks=[0], shape="mesh", height=self.height, mass=self.mass,
            inertia=self.inertia.tolist(), principal_axes=axes.tolist(),
            centre=[spec.x + com[0], spec.y + com[1], float(com[2])],
            rotation=np.eye(3).tolist(), column_position=[spec.x, spec.y],
            parts=[{"shape": "mesh", "block": 0, "name": self.name,
                    "mesh_sha256": self.mesh_sha256}],
            rims=[{"role": "base", "kind": "points", "points": base3.tolist(),
                   "normals": up.tolist()},
                  {"role": "edge", "kind": "points", "points": landing.tolist(),
                   "normals": inward.tolist()}],
            plate=None, overturn_tilt_deg=critical)
        return SceneColumn(
            name=spec.name, kind=spec.kind, x=spec.x, y=spec.y, description=self.name,
            height=self.height, n_bodies=1, uplift_ratio=joint["ratio"],
            rocking_lever_m=joint["lever_m"], overturning_barrier_j=joint["barrier_j"],
            settles=True, bodies=[body])


def _number(data, key, default, low, high, where):
    if key not in data:
        return default
    return number(data[key], f"{where}: '{key}'", low, high)


def _spread(points, n):
    """At most ``n`` of ``points`` (k, 3), spread over them: farthest-point sampling from
    the lowest point (deterministic)."""
    points = np.asarray(points, float)
    if len(points) <= n:
        return points
    chosen = [int(np.argmin(points[:, 2]))]
    dist = np.linalg.norm(points - points[chosen[0]], axis=1)
    for _ in range(n - 1):
        k = int(np.argmax(dist))
        chosen.append(k)
        dist = np.minimum(dist, np.linalg.norm(points - points[k], axis=1))
    return points[sorted(chosen)]


@functools.lru_cache(maxsize=8)
def _posed(path, digest, scale, rotation_wxyz, rest_pose, heading_deg, tolerance, close_base,
           where):
    """Mass properties (per kg), footprint and hull of the mesh in its rest pose, and what
    was repaired to read it (``close_base`` in metres)."""
    import trimesh
    from scipy.spatial import ConvexHull, QhullError
    from scipy.spatial.transform import Rotation

    name = Path(path).name
    try:
        loaded = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds on a broken file
        raise InputError(f"{where}: mesh {name} unreadable "
                         f"({str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__})") \
            from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) < 4 \
            or not np.isfinite(loaded.vertices).all():
        raise InputError(f"{where}: mesh {name} holds no closed surface")
    if len(loaded.faces) > MAX_FACES:
        raise InputError(f"{where}: mesh {name} has {len(loaded.faces):,} faces, more than "
                         f"{MAX_FACES:,}: decimate it first")
    mesh, repairs = _geometry(loaded, scale)
    size = float(np.ptp(mesh.vertices, axis=0).max()) if len(mesh.faces) else 0.0
    if not SIZE_RANGE_M[0] <= size <= SIZE_RANGE_M[1]:
        raise InputError(f"{where}: mesh {name} is {size:g} m across with units "
                         f"{'m' if scale == 1 else 'cm' if scale == 0.01 else 'mm'}: expected "
                         f"{SIZE_RANGE_M[0]:g}-{SIZE_RANGE_M[1]:g} m (check 'units')")
    w, x, y, z = rotation_wxyz
    mesh.apply_transform(_matrix(Rotation.from_quat([x, y, z, w])))
    if not mesh.is_winding_consistent:
        before = mesh.faces.copy()
        trimesh.repair.fix_winding(mesh)
        flipped = int((mesh.faces != before).any(axis=1).sum())
        if flipped:
            repairs.append(f"{_count(flipped, 'face')} turned to the winding of their "
                           "neighbours")
    cap_area = None
    if mesh.is_watertight and close_base is not None:
        repairs.append("closed already: 'close_base' not used")
    if not mesh.is_watertight and close_base is not None:
        loops = _boundary_loops(mesh)
        if loops:
            try:
                mesh, cap_area = _close_base(mesh, loops, close_base, name)
            except InputError as exc:
                raise InputError(f"{where}: {exc}") from None
            repairs.append(f"open base closed by a planar cap of {cap_area:.4g} m^2")
    if not mesh.is_watertight:
        raise InputError(f"{where}: {_open_text(mesh, _boundary_loops(mesh), name)}")
    if not mesh.is_winding_consistent:
        raise InputError(f"{where}: mesh {name} is not an orientable closed surface")
    if mesh.body_count > 1:
        raise InputError(f"{where}: mesh {name} holds {mesh.body_count} separate bodies: "
                         "one closed body per specimen (give each its own file)")
    with np.errstate(divide="ignore", invalid="ignore"):      # no centre of a flat mesh
        flat = abs(mesh.volume) <= ZERO_VOLUME * size ** 3
    if flat:
        raise InputError(f"{where}: mesh {name} encloses zero volume (a flat surface)")
    if mesh.volume < 0:
        mesh.invert()                      # inward-facing normals (a common scan export)
    hull = mesh.convex_hull
    inside = ((mesh.center_mass - hull.triangles_center) * hull.face_normals).sum(axis=1)
    if not (inside < 0).all():     # the stable-pose search would sample it forever
        raise InputError(f"{where}: mesh {name}: its centre of mass is not inside its convex "
                         "hull (a self-intersecting or flat surface)")
    settle = Rotation.identity()
    if rest_pose == "nearest":
        if len(hull.faces) > MAX_POSE_HULL_FACES:
            settle = _rolled(hull, mesh.center_mass)
            repairs.append(f"rest pose found by rolling on its convex hull of "
                           f"{len(hull.faces):,} faces (the stable poses are sought on "
                           f"at most {MAX_POSE_HULL_FACES:,})")
        else:
            transforms, _ = mesh.compute_stable_poses()
            if not len(transforms):
                raise InputError(f"{where}: mesh {name}: no stable pose found")
            ups = [np.linalg.inv(T[:3, :3]) @ [0.0, 0.0, 1.0] for T in transforms]
            # the stable pose whose up direction is nearest the given orientation's
            up = max(ups, key=lambda u: u[2])
            settle, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [up])
    turn = Rotation.from_euler("z", -heading_deg, degrees=True)
    matrix = _matrix(turn * settle)
    mesh.apply_transform(matrix)
    hull = trimesh.transform_points(hull.vertices, matrix)
    lowest = mesh.vertices[:, 2].min()
    com = mesh.center_mass
    shift = np.array([-com[0], -com[1], -lowest])
    mesh.apply_translation(shift)
    hull = hull + shift
    near = hull[hull[:, 2] <= tolerance + 1e-9]
    com = np.array(mesh.center_mass, float)
    try:
        outline = near[ConvexHull(near[:, :2]).vertices][:, :2] if len(near) >= 3 else None
    except QhullError:                              # the points lie on a line
        outline = None
    if outline is None:
        raise InputError(f"{where}: fewer than 3 hull points within footprint_tolerance_m "
                         f"{tolerance:g} m of the table: it cannot stand (raise the tolerance)")
    from matplotlib.path import Path as Polygon
    if not Polygon(outline).contains_point(com[:2]):
        raise InputError(f"{where}: the centre of mass lies outside the footprint in this "
                         "pose: the specimen cannot stand (use rest_pose \"nearest\")")
    inertia_per_kg = np.array(mesh.moment_inertia, float) / mesh.volume
    moments = np.linalg.eigvalsh(inertia_per_kg)   # a solid's: positive, I3 <= I1 + I2
    if moments[0] <= 0 or moments[2] > (moments[0] + moments[1]) * (1 + 1e-9):
        raise InputError(f"{where}: mesh {name}: its surface crosses itself (its moments of "
                         "inertia are not those of a solid)")
    landing = hull[hull[:, 2] > tolerance + 1e-9]
    return {"volume": float(mesh.volume), "com": com,
            "inertia_per_kg": inertia_per_kg,
            "footprint": outline, "hull_points": landing,
            "extent": tuple(float(e) for e in np.ptp(mesh.vertices, axis=0)),
            "settled_by_deg": float(np.degrees((settle).magnitude())),
            "repairs": tuple(repairs), "cap_area_m2": cap_area}


def _matrix(rotation):
    """The 4 x 4 transform of a scipy Rotation."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation.as_matrix()
    return matrix


def _say(line):
    """Print a note or warning line on stderr, once per process (the process the user
    started: campaign workers load the specimen again and keep quiet)."""
    if line not in _SAID and multiprocessing.parent_process() is None:
        print(line, file=sys.stderr)
    _SAID.add(line)


_SAID = set()


def _declared(data, suffix):
    """Vertices and faces a mesh file declares, counted in its bytes before it is read
    (None where the file does not say)."""
    if suffix == ".obj":
        return tuple(data.count(b"\n" + key) + data.startswith(key) for key in (b"v ", b"f "))
    if suffix == ".ply":
        header = data[:10_000]
        return tuple(int(m.group(1)) if m else None for m in (
            re.search(rb"element vertex (\d+)", header), re.search(rb"element face (\d+)", header)))
    if data[:5].lower() == b"solid" and b"facet" in data[:1000]:
        faces = data.count(b"facet normal")                            # ASCII STL
    else:
        faces = struct.unpack("<I", data[80:84])[0] if len(data) >= 84 else None
    return (None if faces is None else 3 * faces), faces


def _geometry(mesh, scale):
    """The surface of a loaded mesh as its geometry alone (metres): vertices merged by
    position (texture coordinates and normals do not split it) and sorted (their order in
    the file does not matter), degenerate and duplicate faces dropped; with what was
    repaired."""
    import trimesh
    mesh = trimesh.Trimesh(vertices=np.asarray(mesh.vertices, float) * scale,
                           faces=mesh.faces, process=False)
    mesh.remove_unreferenced_vertices()
    repairs = []
    before = len(mesh.vertices)
    mesh.merge_vertices()
    if len(mesh.vertices) < before:
        repairs.append(_count(before - len(mesh.vertices), "vertex", "vertices")
                       + " merged by position")
    for what, keep in (("degenerate", mesh.nondegenerate_faces), ("duplicate",
                                                                   mesh.unique_faces)):
        mask = keep()
        if not mask.all():
            mesh.update_faces(mask)
            repairs.append(f"{_count(int((~mask).sum()), what + ' face')} dropped")
    mesh.remove_unreferenced_vertices()
    order = np.lexsort(mesh.vertices.T[::-1])
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return trimesh.Trimesh(mesh.vertices[order], rank[mesh.faces], process=False), repairs


def _count(n, one, many=None):
    """``n`` things in words: "1 face", "2 faces"."""
    return f"{n:,} {one if n == 1 else many or one + 's'}"


def _boundary_loops(mesh):
    """The open edges of a surface as loops: lists of vertex indices in order (the
    direction of the faces' winding), one list per hole."""
    import trimesh
    edges = mesh.edges[trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1)]
    following = dict(zip(edges[:, 1], edges[:, 0]))   # walk against the faces' edges
    loops = []
    while following:
        start, loop = next(iter(following)), []
        vertex = start
        while vertex in following:
            loop.append(vertex)
            vertex = following.pop(vertex)
        loops.append(loop)
    return loops


def _open_text(mesh, loops, name):
    """Where a surface is open, in one line."""
    if not loops:
        shared = np.unique(mesh.edges_sorted, axis=0, return_counts=True)[1]
        return (f"mesh {name} is not a closed surface: {int((shared > 2).sum())} edges are "
                "shared by more than two faces")
    sizes = [float(np.linalg.norm(np.diff(mesh.vertices[loop + loop[:1]], axis=0),
                                  axis=1).sum()) for loop in loops]
    largest = loops[int(np.argmax(sizes))]
    centre = ", ".join(f"{c:.4g}" for c in mesh.vertices[largest].mean(axis=0))
    return (f"mesh {name} is not closed: {_count(len(loops), 'hole')}, the largest "
            f"{max(sizes):.3g} m around its edge, centred at ({centre}) m (the mesh's axes "
            "in metres): close it, or give \"close_base\" for an open base")


def _close_base(mesh, loops, close_base, name):
    """The surface with its lowest hole closed by a planar cap at the ground plane
    (``close_base``: "fit", a plane fitted to that hole's edge, or the plane's height z
    in metres), and the cap's area (m^2).  The edge is joined to the plane by a skirt."""
    import trimesh
    loop = min(loops, key=lambda lp: mesh.vertices[lp, 2].mean())
    edge = mesh.vertices[loop]
    if close_base == "fit":
        point = edge.mean(axis=0)
        normal = np.linalg.svd(edge - point)[2][2]
        normal = normal if normal[2] > 0 else -normal
    else:
        point, normal = np.array([0.0, 0.0, close_base]), np.array([0.0, 0.0, 1.0])
    height = (edge - point) @ normal
    size = float(np.ptp(mesh.vertices, axis=0).max())
    if np.abs(height).max() > CLOSE_BASE_REACH * size:
        raise InputError(f"mesh {name}: the ground plane of \"close_base\" lies up to "
                         f"{np.abs(height).max():.3g} m from the open base's edge (at most "
                         f"{CLOSE_BASE_REACH:g} of the specimen's size {size:.3g} m)")
    foot = edge - height[:, None] * normal
    centre = foot.mean(axis=0)
    n, k = len(mesh.vertices), len(loop)
    a = np.array(loop)
    b = np.roll(a, -1)
    pa = n + np.arange(k)
    pb = np.roll(pa, -1)
    c = np.full(k, n + k)
    faces = np.vstack([np.column_stack(f) for f in ((a, b, pb), (a, pb, pa), (c, pa, pb))])
    area = 0.5 * abs(float(np.cross(foot - centre, np.roll(foot, -1, axis=0) - centre).sum(
        axis=0) @ normal))
    capped = trimesh.Trimesh(vertices=np.vstack([mesh.vertices, foot, centre]),
                             faces=np.vstack([mesh.faces, faces]), process=False)
    capped, _ = _geometry(capped, 1.0)          # a skirt of no height folds away
    return capped, area


def _rolled(hull, com):
    """The rotation that sets a body down on the table as it rolls there (hull: its convex
    hull, trimesh; com: its centre of mass, (3,)): from the hull face below the centre of
    mass, it tips over the edge of each face the centre of mass lies beyond onto the
    neighbouring face, until the centre of mass lies above the face it stands on."""
    from scipy.spatial.transform import Rotation
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
