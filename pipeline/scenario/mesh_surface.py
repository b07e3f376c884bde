"""A mesh file read as a closed solid surface (metres, in the table frame's axes): its
declared size counted in its bytes, its geometry alone (vertices merged by position,
those of an open surface also within NEAR_VERTICES of its size,
degenerate and duplicate faces dropped, the winding made consistent), an open base
closed by a planar cap, and one-line errors where it is no solid.  What was repaired is
listed as it is done (:mod:`pipeline.scenario.mesh` says it and keeps it)."""
import io
import re
import struct
from pathlib import Path

import numpy as np

from pipeline.files import InputError
from pipeline.userfiles import read_user_bytes, show
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

MAX_FACES = 1_000_000             # triangles of a mesh (a scan decimated for simulation)
ZERO_VOLUME = 1e-9                # volumes below this fraction of size^3 are flat surfaces
CLOSE_BASE_REACH = 0.25           # the ground plane within this fraction of the size
SIZE_RANGE_M = (0.02, 30.0)       # largest extent of a specimen
# an open surface whose vertices lie this close (a fraction of the mesh's size) merges
# them when that closes edges of it: copies of one corner written apart (a per-face
# export, float rounding); 1e-5 is 7.9 um on SP1, ten times below a scan's precision
# (~0.1 mm) and its 0.1 % shortest edges (89 um; edges shorter still collapse and go)
NEAR_VERTICES = 1e-5


def read_solid(path, scale, rotation, close_base, where):
    """(mesh, repairs, cap area m^2 or None, size m) of the mesh file at ``path`` (units
    ``scale`` m), turned by ``rotation`` (a 4 x 4 transform) into the table frame, its
    open base closed at ``close_base`` (None, "fit" or a height in metres), checked to
    be one closed solid; InputError (one line, prefixed ``where``) otherwise."""
    name = Path(path).name
    mesh, repairs, size = _read(path, scale, name, where)
    mesh.apply_transform(rotation)
    _fix_winding(mesh, repairs)
    mesh, cap_area = _closed(mesh, close_base, name, where, repairs)
    _check_solid(mesh, size, name, where)
    if mesh.volume < 0:
        mesh.invert()                      # inward-facing normals (a common scan export)
    return mesh, repairs, cap_area, size


def _read(path, scale, name, where):
    """The mesh file as its geometry (:func:`_geometry`), its repairs and its size (m)."""
    import trimesh  # lazy: trimesh, only for mesh specimens
    content = read_user_bytes(path, f"{where}: mesh")
    suffix = Path(path).suffix.lower()
    _check_ply_lines(content, suffix, name, where)
    try:
        loaded = trimesh.load(io.BytesIO(content), file_type=suffix.lstrip("."), force="mesh",
                              process=False)
    except Exception as exc:  # trimesh raises many kinds on a broken file
        raise InputError(f"{where}: mesh {name} unreadable "
                         f"({str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__})") \
            from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) < 4:
        raise InputError(f"{where}: mesh {name} holds no closed surface")
    _check_vertices(np.asarray(loaded.vertices), np.asarray(loaded.faces), name, where)
    if len(loaded.faces) > MAX_FACES:
        raise InputError(f"{where}: mesh {name} has {len(loaded.faces):,} faces, more than "
                         f"{MAX_FACES:,}: decimate it first")
    mesh, repairs = _geometry(loaded, scale)
    size = float(np.ptp(mesh.vertices, axis=0).max()) if len(mesh.faces) else 0.0
    if not SIZE_RANGE_M[0] <= size <= SIZE_RANGE_M[1]:
        raise InputError(f"{where}: mesh {name} is {_outside_text(size, SIZE_RANGE_M)} m across "
                         f"with units {'m' if scale == 1 else 'cm' if scale == 0.01 else 'mm'}: "
                         f"expected {SIZE_RANGE_M[0]:g}-{SIZE_RANGE_M[1]:g} m (check 'units')")
    return _merged_near(mesh, size, repairs), repairs, size


def _check_ply_lines(content, suffix, name, where):
    """An ASCII PLY's data lines are as many as its header declares elements (vertices and
    faces); InputError (malformed or truncated) otherwise."""
    head, end, body = content.partition(b"end_header")
    if suffix != ".ply" or not end or b"format ascii" not in head:
        return
    declared = sum(int(n) for n in re.findall(rb"(?m)^element\s+\S+\s+(\d+)", head))
    lines = sum(1 for line in body.splitlines() if line.strip())
    if lines != declared:
        vertices, faces = declared_counts(content, suffix)
        raise InputError(f"{where}: mesh {name} is malformed or truncated: its header declares "
                         f"{vertices or 0:,} vertices and {faces or 0:,} faces ({declared:,} "
                         f"data lines), the file holds {lines:,} data lines")


def _check_vertices(vertices, faces, name, where):
    """InputError for vertices with NaN or infinite coordinates, or faces that name a
    vertex the file does not hold."""
    bad = np.flatnonzero(~np.isfinite(vertices).all(axis=1))
    if bad.size:
        raise InputError(f"{where}: mesh {name} has {_count(bad.size, 'vertex', 'vertices')} "
                         f"with NaN or infinite coordinates (the first: vertex {bad[0] + 1} of "
                         f"{len(vertices):,}, {show(tuple(vertices[bad[0]].tolist()))})")
    if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise InputError(f"{where}: mesh {name} is malformed: a face names vertex "
                         f"{int(faces.max()) + 1}, the file holds {len(vertices):,} vertices")


def _outside_text(value, bounds):
    """``value`` with the fewest digits (at least 4) that show it outside ``bounds``."""
    for digits in range(4, 18):
        text = f"{value:.{digits}g}"
        if not bounds[0] <= float(text) <= bounds[1]:
            return text
    return repr(value)


def _merged_near(mesh, size, repairs):
    """``mesh`` with its vertices closer than NEAR_VERTICES x ``size`` (m) merged, each
    group to its mean, when its surface is open and that closes edges of it (said in
    ``repairs``); else ``mesh`` as it is."""
    import trimesh  # lazy: trimesh, only for mesh specimens
    if mesh.is_watertight:
        return mesh
    tolerance = NEAR_VERTICES * size
    pairs = cKDTree(mesh.vertices).query_pairs(tolerance, output_type="ndarray")
    if not len(pairs):
        return mesh
    n = len(mesh.vertices)
    k, group = connected_components(coo_matrix((np.ones(len(pairs)), pairs.T), shape=(n, n)),
                                    directed=False)
    vertices = np.zeros((k, 3))
    np.add.at(vertices, group, mesh.vertices)
    vertices /= np.bincount(group, minlength=k)[:, None]
    merged, more = _geometry(trimesh.Trimesh(vertices, group[mesh.faces], process=False), 1.0)
    if _open_edges(merged) >= _open_edges(mesh):
        return mesh
    repairs.append(f"{_count(n - k, 'vertex', 'vertices')} within {tolerance:.2g} m of "
                   f"another merged ({NEAR_VERTICES:g} of the mesh's size)")
    repairs.extend(more)
    return merged


def _open_edges(mesh):
    """How many edges of ``mesh`` belong to one face only."""
    import trimesh  # lazy: trimesh, only for mesh specimens
    return len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))


def _fix_winding(mesh, repairs):
    """Faces turned to the winding of their neighbours (said in ``repairs``)."""
    import trimesh  # lazy: trimesh, only for mesh specimens
    if not mesh.is_winding_consistent:
        before = mesh.faces.copy()
        trimesh.repair.fix_winding(mesh)
        flipped = int((mesh.faces != before).any(axis=1).sum())
        if flipped:
            repairs.append(f"{_count(flipped, 'face')} turned to the winding of their "
                           "neighbours")


def _closed(mesh, close_base, name, where, repairs):
    """(mesh, cap area m^2 or None): an open base closed as ``close_base`` asks."""
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
    return mesh, cap_area


def _check_solid(mesh, size, name, where):
    """InputError unless ``mesh`` is one closed orientable body enclosing a volume."""
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


def declared_counts(data, suffix):
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
    import trimesh  # lazy: trimesh, only for mesh specimens
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
    import trimesh  # lazy: trimesh, only for mesh specimens
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
    apart = ""
    if len(loops) > len(mesh.faces) / 4:         # most faces alone: their corners unshared
        tolerance = NEAR_VERTICES * float(np.ptp(mesh.vertices, axis=0).max())
        apart = (f"; its faces share few vertices, none closer than {tolerance:.2g} m "
                 f"({NEAR_VERTICES:g} of its size) to another")
    return (f"mesh {name} is not closed: {_count(len(loops), 'hole')}, the largest "
            f"{max(sizes):.3g} m around its edge, centred at ({centre}) m (the mesh's axes "
            f"in metres){apart}: close it, or give \"close_base\" for an open base")


def _close_base(mesh, loops, close_base, name):
    """The surface with its lowest hole closed by a planar cap at the ground plane
    (``close_base``: "fit", a plane fitted to that hole's edge, or the plane's height z
    in metres), and the cap's area (m^2).  The edge is joined to the plane by a skirt."""
    import trimesh  # lazy: trimesh, only for mesh specimens
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
