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

The mesh is read as its geometry (:mod:`pipeline.scenario.mesh_surface`): vertices merged by position
(texture coordinates and normals do not split a surface), degenerate and duplicate faces
dropped, the winding made consistent; only then is it judged closed.  What was repaired
is said in one line on stderr and kept as ``repairs`` in :meth:`MeshSpecimen.to_dict`.
Every limit is checked before the heavy work (MAX_FACES, counted in the file's bytes).

In the scene the specimen is one clump: contact spheres along the footprint's outline
(the base rim, ``rim_points`` per full turn of its corners as a column's rim) and on up to
LANDING_POINTS_PER_RIM_POINT x ``rim_points`` hull vertices elsewhere (the faces it can
land on), each sphere one radius inside the surface.
"""
import hashlib
import logging
import math
import multiprocessing
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.constants import MODEL_GRAVITY, RIM_POINTS
from pipeline.files import InputError
from pipeline.scenario.column_format import DENSITY_RANGE
from pipeline.scenario.mesh_pose import MAX_POSE_HULL_FACES, _posed  # noqa: F401
from pipeline.scenario.mesh_surface import MAX_FACES, declared_counts
from pipeline.scenario.outline import perimeter_points
from pipeline.scenario.scene_file import SceneBody, SceneColumn
from pipeline.scenario.specimen import Specimen
from pipeline.userfiles import keys_text, number, read_user_bytes, show

log = logging.getLogger(__name__)

MESH_SUFFIXES = (".obj", ".ply", ".stl")   # the mesh files trimesh reads here

MAX_MESH_BYTES = 200_000_000
CLOSE_BASE_RANGE = (-1e7, 1e7)    # the ground plane's height, in the mesh's units
DEFAULT_DENSITY = 2650.0          # kg/m^3, granite
MASS_RANGE = (1e-3, 1e7)          # kg
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
        name, mesh = _name_and_file(data, where, base)
        if "mass_kg" in data and "density" in data:
            raise InputError(f"{where}: give 'mass_kg' or 'density', not both")
        mass = _number(data, "mass_kg", None, *MASS_RANGE, where)
        density = _number(data, "density", None, *DENSITY_RANGE, where)
        units = data.get("units", "m")
        if units not in UNITS:
            raise InputError(f"{where}: 'units' must be one of {', '.join(UNITS)}, got "
                             f"{show(units)}")
        rotation = _rotation(data, where)
        rest_pose = data.get("rest_pose", "nearest")
        if rest_pose not in REST_POSES:
            raise InputError(f"{where}: 'rest_pose' must be one of {', '.join(REST_POSES)}, "
                             f"got {show(rest_pose)}")
        heading = _number(data, "heading_deg", 0.0, -360.0, 360.0, where)
        tolerance = _number(data, "footprint_tolerance_m", DEFAULT_FOOTPRINT_TOLERANCE_M,
                            *FOOTPRINT_TOLERANCE_RANGE_M, where)
        close_base = _close_base_m(data, units, where)
        for key in ("source", "notes"):
            if data.get(key) is not None and not isinstance(data[key], str):
                raise InputError(f"{where}: '{key}' must be a string")
        digest = _checked_file(mesh, data.get("mesh_sha256"), where)
        options = {k: data[k] for k in ("mass_kg", "density", "units", "rotation_wxyz",
                                         "rest_pose", "heading_deg", "footprint_tolerance_m",
                                         "close_base")
                   if k in data}
        posed = _posed(str(mesh), digest, UNITS[units], tuple(rotation), rest_pose, heading,
                       tolerance, close_base, where)
        mass = _mass(mass, density, posed["volume"], where)
        if posed["repairs"]:
            _say(f"{'note' if posed['cap_area_m2'] is None else 'warning'}: {where}: mesh "
                 f"{mesh.name} read as its geometry: {', '.join(posed['repairs'])}")
        return cls(name.strip(), str(mesh), digest, options, float(mass), posed["volume"],
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

    def contact_rocking_hz(self, kn, rim_points=RIM_POINTS):
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


def _name_and_file(data, where, base):
    """(name, mesh file Path) of a description dict, its keys checked."""
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
    return name, mesh


def _rotation(data, where):
    """The description's ``rotation_wxyz`` as 4 numbers, largest magnitude 1."""
    rotation = data.get("rotation_wxyz", [1.0, 0.0, 0.0, 0.0])
    if not isinstance(rotation, list) or len(rotation) != 4:
        raise InputError(f"{where}: 'rotation_wxyz' must be 4 finite numbers, not all "
                         f"zero (a quaternion w, x, y, z), got {show(rotation)}")
    rotation = [number(q, f"{where}: 'rotation_wxyz'") for q in rotation]
    largest = max(abs(q) for q in rotation)
    if largest == 0:
        raise InputError(f"{where}: 'rotation_wxyz' must not be all zero (a quaternion "
                         "w, x, y, z)")
    return [q / largest for q in rotation]          # any length: a direction


def _close_base_m(data, units, where):
    """The description's ``close_base``: None, "fit" or the ground plane's height (m)."""
    close_base = data.get("close_base")
    if close_base is not None and close_base != "fit":
        if isinstance(close_base, str):
            raise InputError(f"{where}: 'close_base' must be \"fit\" or the ground "
                             f"plane's height (a number), got {show(close_base)}")
        close_base = number(close_base, f"{where}: 'close_base'", *CLOSE_BASE_RANGE)
        close_base *= UNITS[units]
    return close_base


def _checked_file(mesh, sha256, where):
    """The SHA-256 of mesh file ``mesh``, after its size, its described digest
    (``sha256``, None: any) and its declared counts are checked, before it is read."""
    if not mesh.exists():
        raise InputError(f"{where}: mesh file not found: {mesh}")
    if mesh.stat().st_size > MAX_MESH_BYTES:
        raise InputError(f"{where}: mesh {mesh.name} is larger than "
                         f"{MAX_MESH_BYTES // 1_000_000} MB")
    content = read_user_bytes(mesh, f"{where}: mesh", MAX_MESH_BYTES)
    digest = hashlib.sha256(content).hexdigest()
    if sha256 not in (None, digest):
        raise InputError(f"{where}: mesh {mesh.name} is not the file described "
                         "(its SHA-256 differs from 'mesh_sha256')")
    for count, what, most in zip(declared_counts(content, mesh.suffix.lower())[::-1],
                                 ("faces", "vertices"), (MAX_FACES, 3 * MAX_FACES)):
        if count is not None and count > most:
            raise InputError(f"{where}: mesh {mesh.name} has {count:,} {what}, more "
                             f"than {most:,}: decimate it first")
    return digest


def _mass(mass, density, volume, where):
    """The mass (kg): ``mass`` checked against the mesh's ``volume`` (m^3), or the volume
    times ``density`` (default DEFAULT_DENSITY)."""
    if mass is None:
        return (DEFAULT_DENSITY if density is None else density) * volume
    if not DENSITY_RANGE[0] <= mass / volume <= DENSITY_RANGE[1]:
        raise InputError(f"{where}: 'mass_kg' {mass:g} over the mesh's volume "
                         f"{volume:.4g} m^3 is a density of {mass / volume:.4g} kg/m^3: "
                         f"expected {DENSITY_RANGE[0]:g}-{DENSITY_RANGE[1]:g} kg/m^3 "
                         "(check 'mass_kg' and 'units')")
    return mass


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


def _say(line):
    """Print a note or warning line on stderr, once per process (the process the user
    started: campaign workers load the specimen again and keep quiet)."""
    if line not in _SAID and multiprocessing.parent_process() is None:
        log.info(line, extra={"stderr": True})
    _SAID.add(line)


_SAID = set()
