"""A mesh read as its geometry: SP1 written as scanners and exporters write it (split
vertices, per-face normals, UV charts, binary STL, faces wound at random) gives the
specimen of the shipped file; open, flat, huge, split and absurd meshes answer in one
line; an open base is closed on request; SP2's model loads as a closed mesh."""
import numpy as np
import pytest
import trimesh

from pipeline import RECORDS_DIR
from pipeline.files import InputError
from pipeline.scenario import ColumnSpec
from pipeline.scenario import mesh as mesh_module
from pipeline.scenario import mesh_pose
from pipeline.scenario.mesh import MeshSpecimen
from tests.hang import hang_bound

SP1 = RECORDS_DIR / "shake_table" / "SP1.obj"
SP1_MASS = 353.802                       # kg, records/shake_table/sp1.json
SP2 = RECORDS_DIR / "shake_table" / "final_sp2_1.obj"
W, D, H = 0.3, 0.4, 1.2                  # m, a box
DENSITY = 2700.0


@pytest.fixture(autouse=True)
def fresh_loader():
    """Every test reads its meshes anew and sees its notes (both are once per process)."""
    mesh_module._posed.cache_clear()
    mesh_module._SAID.clear()


def sp1_as_written():
    """SP1's vertices and faces exactly as the file lists them (nothing merged)."""
    mesh = trimesh.load(SP1, force="mesh", process=False)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces)


def load(path, **options):
    return MeshSpecimen.from_dict({"name": "SP1", "mesh": str(path), **options})


def physics(rock):
    """The scene entry a specimen produces, without the file's own hash."""
    column = ColumnSpec("monolithic", "monolithic", 0.0, 0.0, rock).scene(16)
    for part in column["bodies"][0]["parts"]:
        part.pop("mesh_sha256")
    return column


def write_ply(path, vertices, faces, uv):
    """An ASCII PLY with vertex coordinates at full precision and texture coordinates."""
    lines = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}",
             "property double x", "property double y", "property double z",
             "property float s", "property float t", f"element face {len(faces)}",
             "property list uchar int vertex_indices", "end_header"]
    lines += [f"{x:.17g} {y:.17g} {z:.17g} {s:.6f} {t:.6f}"
              for (x, y, z), (s, t) in zip(vertices, uv)]
    lines += [f"3 {a} {b} {c}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def split(vertices, faces):
    """Every triangle with its own three vertices (as at UV seams or per-face normals)."""
    corners = vertices[faces].reshape(-1, 3)
    return corners, np.arange(len(corners)).reshape(-1, 3)


# ---------------------------------------------------------------- SP1 as exporters write it
def test_sp1_mass_properties_are_those_of_the_file_as_written():
    """The repairs (one duplicate vertex, two zero-area faces) change nothing: volume
    and principal moments as trimesh integrates the file's own triangles (centred first,
    for precision), and the volume the providers' file states (README: 0.12386 m^3)."""
    vertices, faces = sp1_as_written()
    raw = trimesh.Trimesh(vertices - vertices.mean(axis=0), faces, process=False)
    rock = load(SP1, mass_kg=SP1_MASS)
    assert rock.volume_m3 == pytest.approx(abs(raw.volume), rel=1e-9)
    assert rock.volume_m3 == pytest.approx(0.12386, abs=5e-6)
    assert np.linalg.eigvalsh(rock.inertia / rock.mass) == pytest.approx(
        np.linalg.eigvalsh(raw.moment_inertia / raw.volume), rel=1e-9)
    assert rock.mass == SP1_MASS
    assert rock.repairs == ("1 vertex merged by position", "2 degenerate faces dropped")
    assert rock.to_dict()["repairs"] == list(rock.repairs)


@pytest.mark.parametrize("variant", ["obj with per-face normals", "ply with uv charts"])
def test_sp1_as_an_exporter_writes_it_is_the_same_specimen(tmp_path, variant, capsys):
    vertices, faces = sp1_as_written()
    corners, triangles = split(vertices, faces)
    if variant.startswith("obj"):
        path = tmp_path / "sp1_normals.obj"
        mesh = trimesh.Trimesh(corners, triangles, process=False)
        mesh.export(path, include_normals=True)
        assert "vn " in path.read_text()
    else:
        uv = np.random.default_rng(1).random((len(corners), 2))
        path = write_ply(tmp_path / "sp1_uv.ply", corners, triangles, uv)
    rock, shipped = load(path, mass_kg=SP1_MASS), load(SP1, mass_kg=SP1_MASS)
    assert rock.volume_m3 == pytest.approx(shipped.volume_m3, rel=1e-9)
    assert rock.inertia == pytest.approx(shipped.inertia, rel=1e-9)
    assert physics(rock) == physics(shipped)          # the same scene: the same YADE run
    merged = len(corners) - len(np.unique(vertices, axis=0))
    assert rock.repairs[0] == f"{merged:,} vertices merged by position"
    note = capsys.readouterr().err
    assert f"note: specimen description: mesh {path.name} read as its geometry: " \
           f"{merged:,} vertices merged by position" in note


def test_sp1_as_binary_stl_is_the_same_specimen_to_float32(tmp_path):
    """Binary STL stores float32 coordinates (SP1 lies 312 m from the origin: 3e-5 m
    steps): the same specimen as an OBJ of those coordinates, and SP1's to that precision."""
    vertices, faces = sp1_as_written()
    stl = tmp_path / "sp1.stl"
    trimesh.Trimesh(vertices, faces, process=False).export(stl)
    assert stl.read_bytes()[:5] != b"solid"                 # binary
    rounded = trimesh.Trimesh(vertices.astype(np.float32).astype(float), faces, process=False)
    rounded.export(tmp_path / "sp1_float32.obj", digits=16)   # exact
    rock = load(stl, mass_kg=SP1_MASS)
    assert physics(rock) == physics(load(tmp_path / "sp1_float32.obj", mass_kg=SP1_MASS))
    shipped = load(SP1, mass_kg=SP1_MASS)
    assert rock.volume_m3 == pytest.approx(shipped.volume_m3, rel=1e-6)
    assert rock.inertia == pytest.approx(shipped.inertia, rel=1e-5, abs=1e-6)


def test_faces_wound_at_random_give_the_mass_of_the_closed_surface(tmp_path):
    vertices, faces = sp1_as_written()
    flip = np.random.default_rng(7).random(len(faces)) < 0.3
    faces = np.where(flip[:, None], faces[:, ::-1], faces)
    path = tmp_path / "wound.obj"
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    rock, shipped = load(path), load(SP1)
    assert rock.volume_m3 == pytest.approx(shipped.volume_m3, rel=1e-9)
    assert rock.mass == pytest.approx(shipped.mass, rel=1e-9)
    assert rock.inertia == pytest.approx(shipped.inertia, rel=1e-9, abs=1e-12)
    assert any("turned to the winding of their neighbours" in r for r in rock.repairs)


def test_sp2_model_loads_as_a_closed_mesh():
    """The providers' model of the second rock: a Blender OBJ whose vertices are split
    where face normals change; merged by position it is closed, 0.124 m^3."""
    with hang_bound(120):
        rock = MeshSpecimen.load(SP2)
    assert rock.volume_m3 == pytest.approx(0.124, abs=0.001)
    assert "vertices merged by position" in rock.repairs[0]
    assert rock.density == 2650.0


# ---------------------------------------------------------------- one line, in seconds
def box(extents=(W, D, H), at=(5.0, -3.0, 40.0)):
    mesh = trimesh.creation.box(extents=extents)
    mesh.apply_translation(at)
    return mesh


def export(mesh, path):
    mesh.export(path)
    return path


def refused(path, words, **options):
    with hang_bound(120), pytest.raises(InputError, match=words) as info:
        MeshSpecimen.from_dict({"name": "x", "mesh": str(path), **options})
    assert "\n" not in str(info.value)
    return str(info.value)


def test_a_closed_flat_mesh_is_zero_volume(tmp_path):
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.3, 0]]       # four coplanar
    faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]
    flat = trimesh.Trimesh(vertices, faces, process=False)
    assert flat.is_watertight
    refused(export(flat, tmp_path / "flat.obj"), "encloses zero volume")
    refused(export(box(extents=(1.0, 1.0, 0.0)), tmp_path / "slab.stl"), "not closed|zero")


def test_two_bodies_in_one_file_are_refused(tmp_path):
    apart = trimesh.util.concatenate([box(), box(at=(7.0, -3.0, 40.0))])
    refused(export(apart, tmp_path / "two.obj"), "2 separate bodies: one closed body")
    overlapping = trimesh.util.concatenate([box(), box(at=(5.1, -3.0, 40.0))])
    refused(export(overlapping, tmp_path / "overlap.ply"), "2 separate bodies")


def test_an_absurd_mass_is_refused_by_its_density():
    # 1e7 kg / 0.12386 m^3 (the volume the providers' file states)
    message = refused(SP1, "density of 8.074e\\+07 kg/m\\^3: expected 100-25000", mass_kg=1e7)
    assert "'mass_kg' 1e+07" in message


def test_the_density_range_has_one_home():
    from pipeline.scenario import column_format, parameters
    assert mesh_module.DENSITY_RANGE is column_format.DENSITY_RANGE
    for cls in (parameters.Column, parameters.Block):
        meta = cls.__dataclass_fields__["density"].metadata
        assert (meta["low"], meta["high"]) == column_format.DENSITY_RANGE


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl"])
def test_too_many_faces_are_refused_before_the_mesh_is_read(tmp_path, monkeypatch, suffix):
    sphere = trimesh.creation.icosphere(subdivisions=3)              # 1280 faces
    path = export(sphere, tmp_path / f"many{suffix}")
    monkeypatch.setattr(mesh_module, "MAX_FACES", 1000)
    monkeypatch.setattr(mesh_module, "_posed", None)                 # never reached
    refused(path, "has 1,280 faces, more than 1,000: decimate it first")


def test_too_many_vertices_are_refused_before_the_mesh_is_read(tmp_path, monkeypatch):
    path = tmp_path / "cloud.obj"                 # a point cloud with a tetrahedron
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + "v 0.1 0.1 0.1\n" * 3000
                    + "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n")
    monkeypatch.setattr(mesh_module, "MAX_FACES", 1000)
    monkeypatch.setattr(mesh_module, "_posed", None)                 # never reached
    refused(path, "has 3,004 vertices, more than 3,000: decimate it first")


def test_a_huge_hull_rolls_onto_its_rest_pose(tmp_path, monkeypatch):
    """An ellipsoid (semi-axes 0.2, 0.3, 0.4 m; every vertex on its hull) given standing
    on its long axis: past MAX_POSE_HULL_FACES hull faces it rolls from where it stands
    (said) and comes to rest on a face near the bottom of a principal axis (its centre of
    mass at one of the semi-axes' heights), mass and contact points from the full mesh."""
    ellipsoid = trimesh.creation.icosphere(subdivisions=4)          # 5120 faces
    ellipsoid.apply_scale([0.2, 0.3, 0.4])
    ellipsoid.apply_transform(trimesh.transformations.rotation_matrix(0.3, [1, 1, 0]))
    monkeypatch.setattr(mesh_pose, "MAX_POSE_HULL_FACES", 600)
    path = export(ellipsoid, tmp_path / "ellipsoid.obj")
    volume = trimesh.load(path, process=False).volume            # of the file's vertices
    with hang_bound(120):
        rock = MeshSpecimen.load(path)
    assert rock.repairs == ("rest pose found by rolling on its convex hull of 5,120 faces "
                            "(the stable poses are sought on at most 600)",)
    assert rock.volume_m3 == pytest.approx(volume, rel=1e-9)
    assert rock.mass == pytest.approx(2650.0 * volume, rel=1e-9)
    assert min(abs(rock.com[2] - r) for r in (0.2, 0.3)) < 0.01
    assert rock.statics()[0]["ratio"] > 0


def test_any_quaternion_length_is_a_rotation_and_overflow_is_one_line(tmp_path):
    path = export(box(), tmp_path / "box.obj")
    plain = MeshSpecimen.from_dict({"mesh": str(path)})
    for huge in ([1e200, 0, 0, 0], [1e-200, 0, 0, 0], [1e154, 1e154, 0, 0]):
        rock = MeshSpecimen.from_dict({"mesh": str(path), "rotation_wxyz": huge})
        # 90 deg about x (East) for the last: the box lies on its H x W side
        assert rock.height == pytest.approx(plain.height if huge[1] == 0 else D, abs=1e-9)
    refused(path, "beyond a float's range", rotation_wxyz=[10 ** 400, 0, 0, 0])
    refused(path, "not be all zero", rotation_wxyz=[0, 0.0, 0, 0])


def test_upside_down_sp1_settles_onto_a_stable_pose(tmp_path):
    vertices, faces = sp1_as_written()
    turned = trimesh.Trimesh(vertices * [1, -1, -1], faces, process=False)   # 180 deg about x
    with hang_bound(120):
        rock = load(export(turned, tmp_path / "upside_down.obj"))
    assert rock.settled_by_deg > 10
    assert rock.volume_m3 == pytest.approx(load(SP1).volume_m3, rel=1e-9)
    refused(tmp_path / "upside_down.obj", "cannot stand", rest_pose="given")


# ---------------------------------------------------------------- open surfaces
def open_base_box(at=(5.0, -3.0, 40.0)):
    mesh = box(at=at)
    mesh.update_faces(mesh.face_normals[:, 2] > -0.5)                  # no bottom
    return mesh


def test_an_open_base_is_closed_on_request_by_a_cap_at_the_fitted_plane(tmp_path, capsys):
    path = export(open_base_box(), tmp_path / "scan.obj")
    message = refused(path, "not closed: 1 hole")
    assert f"the largest {2 * (W + D):.3g} m around its edge, centred at (5, -3, 39.4)" \
        in message
    rock = MeshSpecimen.from_dict({"mesh": str(path), "density": DENSITY,
                                   "close_base": "fit"})
    assert rock.mass == pytest.approx(DENSITY * W * D * H, rel=1e-9)
    assert sorted(np.abs(rock.footprint).max(axis=0)) == pytest.approx([W / 2, D / 2])
    assert rock.uplift_ratio() == pytest.approx(W / H, rel=1e-9)
    assert f"planar cap of {W * D:.4g} m^2" in rock.repairs[-1]
    assert capsys.readouterr().err.count(f"warning: specimen description: mesh scan.obj "
                                         f"read as its geometry: open base closed by a "
                                         f"planar cap of {W * D:.4g} m^2") == 1
    assert rock.to_dict()["close_base"] == "fit"
    closed = MeshSpecimen.from_dict({"mesh": str(export(box(), tmp_path / "closed.obj")),
                                     "close_base": "fit"})
    assert closed.repairs == ("closed already: 'close_base' not used",)
    assert "note: specimen description: mesh closed.obj read as its geometry: closed " \
        "already: 'close_base' not used" in capsys.readouterr().err


def test_a_given_ground_plane_closes_the_base_where_it_is(tmp_path):
    """The plane 0.1 m below the open edge: a skirt down to it adds W x D x 0.1."""
    path = export(open_base_box(), tmp_path / "scan.obj")
    bottom = 40.0 - H / 2
    rock = MeshSpecimen.from_dict({"mesh": str(path), "density": DENSITY,
                                   "close_base": bottom - 0.1})
    assert rock.volume_m3 == pytest.approx(W * D * (H + 0.1), rel=1e-9)
    assert rock.height == pytest.approx(H + 0.1)
    in_mm = export(open_base_box().apply_scale(1000.0), tmp_path / "scan_mm.obj")
    rock = MeshSpecimen.from_dict({"mesh": str(in_mm), "units": "mm",
                                   "close_base": 1000 * (bottom - 0.1)})
    assert rock.volume_m3 == pytest.approx(W * D * (H + 0.1), rel=1e-9)
    refused(path, "ground plane of \"close_base\" lies up to", close_base=bottom - 5.0)
    refused(path, "'close_base' must be \"fit\" or the ground plane's height",
            close_base="flat")
    refused(path, "'close_base' 1e\\+08 outside", close_base=1e8)


def test_an_open_sp1_base_closed_by_a_cap_stands_on_it(tmp_path):
    """SP1 with its lowest centimetre of faces removed: capped at the fitted plane, its
    footprint is the cap's outline: the points of the cut edge."""
    vertices, faces = sp1_as_written()
    z = vertices[:, 2]
    cut = trimesh.Trimesh(vertices, faces, process=False)
    cut.update_faces(z[faces].min(axis=1) > z.min() + 0.01)
    path = export(cut, tmp_path / "sp1_open.obj")
    refused(path, "not closed")
    rock = load(path, close_base="fit")
    shipped = load(SP1)
    assert rock.volume_m3 == pytest.approx(shipped.volume_m3, rel=0.01)   # 1 cm less
    assert rock.volume_m3 < shipped.volume_m3
    area = float(rock.repairs[-1].split("cap of ")[1].split()[0])
    outline = rock.footprint
    inside = 0.5 * abs(np.dot(outline[:, 0], np.roll(outline[:, 1], -1))
                       - np.dot(outline[:, 1], np.roll(outline[:, 0], -1)))
    assert inside >= area * 0.999      # the outline's hull holds the whole cap


@pytest.mark.yade
def test_sp1_with_uv_charts_gives_the_same_yade_run_to_the_last_bit(tmp_path):
    """The shipped SP1 and SP1 written as PLY with a UV chart per triangle, rocked by the
    same short pulse above SP1's uplift threshold: the same trajectory, bit for bit (two
    paths in the same run)."""
    from pipeline.motion import Motion
    from pipeline.scenario import run_yade, scene_params, write_scenario
    vertices, faces = sp1_as_written()
    corners, triangles = split(vertices, faces)
    uv = np.random.default_rng(2).random((len(corners), 2))
    variant = load(write_ply(tmp_path / "sp1_uv.ply", corners, triangles, uv),
                   mass_kg=SP1_MASS)
    t = np.arange(0.0, 0.6, 0.005)
    a = 1.5 * load(SP1).uplift_ratio() * 9.81 * np.sin(2 * np.pi * 2.5 * t)
    zero = 0 * a
    v = np.cumsum(a) * 0.005
    motion = Motion(0.005, np.column_stack([a, zero, zero]), np.column_stack([v, zero, zero]),
                    np.column_stack([np.cumsum(v) * 0.005, zero, zero]))
    runs = []
    for name, rock in (("shipped", load(SP1, mass_kg=SP1_MASS)), ("uv", variant)):
        params = scene_params(columns=[ColumnSpec("monolithic", "monolithic", 0.0, 0.0, rock)],
                              t_max=0.8)
        write_scenario(tmp_path / name, params, motion)
        runs.append(run_yade(tmp_path / name))
    shipped, uv = runs
    assert np.abs(shipped.quat[:, 0, 1:]).max() > 1e-4          # it moved
    for key in ("t", "pos", "quat", "vel", "angvel"):
        assert np.array_equal(getattr(shipped, key), getattr(uv, key)), key


@pytest.mark.parametrize("tilt_deg, height", [(4.0, H), (30.0, D)])
def test_rolling_sets_a_tilted_box_down_as_statics_says(tmp_path, monkeypatch, tilt_deg,
                                                        height):
    """The rolling rest pose (used past MAX_POSE_HULL_FACES) on a box tilted about East:
    within its critical angle atan(D / H) = 18.4 deg it rolls back onto its base, past it
    onto its long side (height D)."""
    monkeypatch.setattr(mesh_pose, "MAX_POSE_HULL_FACES", 0)
    tilt = trimesh.transformations.rotation_matrix(np.radians(tilt_deg), [1, 0, 0])
    rock = MeshSpecimen.load(export(box().apply_transform(tilt), tmp_path / "tilted.obj"))
    assert rock.repairs[0].startswith("rest pose found by rolling")
    # the OBJ holds the turned box to 1e-8 m
    assert rock.height == pytest.approx(height, abs=1e-7)
    assert rock.settled_by_deg == pytest.approx(tilt_deg if height == H else 90 - tilt_deg,
                                                abs=1e-5)


# ---------------------------------------------------------------- what is wrong, named
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_vertices_are_named(tmp_path, value):
    mesh = box()
    vertices = np.array(mesh.vertices)
    vertices[3, 1] = value
    path = tmp_path / "bad.obj"
    path.write_text("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in vertices)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in mesh.faces))
    refused(path, r"1 vertex with NaN or infinite coordinates \(the first: vertex 4 of 8")


@pytest.mark.parametrize("element, given", [("vertex 8", "vertex 10"), ("vertex 8", "vertex 6"),
                                            ("face 12", "face 14"), ("face 12", "face 11")])
def test_a_ply_whose_counts_disagree_with_its_data_is_malformed(tmp_path, element, given):
    text = trimesh.exchange.ply.export_ply(box(), encoding="ascii").decode()
    assert f"element {element}\n" in text
    path = tmp_path / "box.ply"
    path.write_text(text.replace(f"element {element}\n", f"element {given}\n"))
    refused(path, "is malformed or truncated: its header declares .* the file holds 20 data "
                  "lines")


@pytest.mark.parametrize("size, shown", [(30.0000001, "30.0000001"), (0.0199999, "0.0199999"),
                                         (45.0, "45")])
def test_a_mesh_just_outside_the_sizes_says_its_size_in_enough_digits(tmp_path, size, shown):
    path = export(box(extents=(size, size / 2, size / 2)), tmp_path / "box.obj")
    refused(path, f"is {shown} m across with units m: expected 0.02-30 m")


def sp1_unshared(path, seed, jitter_m):
    """SP1 written to ``path`` (OBJ) with every face's own corners, each coordinate moved
    by up to ``jitter_m`` (m, uniform; generator seeded with ``seed``)."""
    corners, triangles = split(*sp1_as_written())
    corners = corners + np.random.default_rng(seed).uniform(-jitter_m, jitter_m, corners.shape)
    path.write_text("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in corners)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))
    return path


def test_sp1_with_unshared_jittered_corners_is_merged_and_said(tmp_path, capsys):
    """Every face with its own corners, each coordinate moved by up to 2 um (an
    exporter's rounding): the corners within 1e-5 of the size (7.9 um) are merged, and
    said; the specimen is SP1's to the jitter."""
    path = sp1_unshared(tmp_path / "sp1_jittered.obj", 2, 2e-6)
    with hang_bound(120):
        rock, shipped = load(path, mass_kg=SP1_MASS), load(SP1, mass_kg=SP1_MASS)
    assert rock.volume_m3 == pytest.approx(shipped.volume_m3, rel=1e-5)
    assert rock.inertia == pytest.approx(shipped.inertia, rel=1e-4)
    near = [r for r in rock.repairs if "of another merged (1e-05 of the mesh's size)" in r]
    assert len(near) == 1 and "within 7.9e-06 m" in near[0]
    assert near[0] in capsys.readouterr().err


def test_sp1_with_corners_farther_apart_says_they_are_unshared(tmp_path):
    path = sp1_unshared(tmp_path / "sp1_apart.obj", 3, 1e-4)
    refused(path, "its faces share few vertices, none closer than 7.9e-06 m")
