"""Mesh specimens against meshes as they come (Hypothesis): shapes and triangle soups
with vertices split, faces wound at random, dropped, doubled or degenerate, flattened,
jittered, scaled from tiny to huge, a second body beside or inside, in each format and
with any description options.  Whatever the file, the loader returns a valid specimen
or raises one InputError whose message is one line naming the description; never
another exception, never a hang (a generous bound per mesh)."""
import json
import math

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from pipeline.files import InputError
from pipeline.scenario import mesh as mesh_module
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.mesh import MeshSpecimen
from tests.hang import hang_bound

FUZZ = settings(max_examples=80, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.function_scoped_fixture])
SECONDS_PER_MESH = 60          # a hang, not a timing


def shape(kind, rng):
    if kind == "box":
        return trimesh.creation.box(extents=rng.uniform(0.05, 2.0, 3))
    if kind == "sphere":
        return trimesh.creation.icosphere(subdivisions=int(rng.integers(0, 3)),
                                          radius=float(rng.uniform(0.05, 1.0)))
    if kind == "cylinder":
        return trimesh.creation.cylinder(radius=float(rng.uniform(0.05, 0.5)),
                                         height=float(rng.uniform(0.05, 2.0)), sections=12)
    if kind == "tetra":
        return trimesh.Trimesh(rng.normal(size=(4, 3)),
                               [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]], process=False)
    n = int(rng.integers(3, 30))                                       # a triangle soup
    return trimesh.Trimesh(rng.uniform(-1, 1, (n, 3)),
                           rng.integers(0, n, (int(rng.integers(1, 40)), 3)), process=False)


def changed(mesh, change, rng):
    vertices, faces = np.array(mesh.vertices, float), np.array(mesh.faces)
    some = rng.random(len(faces)) < rng.uniform(0.05, 0.6)
    if change == "split":                  # UV seams or per-face normals everywhere
        vertices, faces = vertices[faces].reshape(-1, 3), np.arange(3 * len(faces)).reshape(-1, 3)
    elif change == "wind":
        faces = np.where(some[:, None], faces[:, ::-1], faces)
    elif change == "drop":
        faces = faces[~some] if (~some).any() else faces[:1]
    elif change == "double":
        faces = np.vstack([faces, faces[some]])
    elif change == "degenerate":
        faces = np.vstack([faces, faces[some][:, [0, 0, 1]]])
    elif change == "flatten":
        vertices[:, 2] *= float(rng.choice([0.0, 1e-12, 1e-6]))
    elif change == "jitter":
        vertices += rng.normal(scale=10.0 ** rng.uniform(-12, -3), size=vertices.shape)
    elif change == "scale":
        vertices *= 10.0 ** int(rng.integers(-4, 5))
    elif change == "second body":         # beside it, touching or inside it
        offset = rng.uniform(-1.0, 1.0, 3) * float(rng.choice([0.0, 0.1, 3.0]))
        faces = np.vstack([faces, faces + len(vertices)])
        vertices = np.vstack([vertices, vertices * float(rng.choice([1.0, 0.5])) + offset])
    elif change == "far away":
        vertices += rng.uniform(-1, 1, 3) * 1e5
    return trimesh.Trimesh(vertices, faces, process=False)


OPTIONS = st.fixed_dictionaries({}, optional={
    "close_base": st.sampled_from(["fit", 0.0, -0.5, 1e6, "flat"]),
    "rest_pose": st.sampled_from(["nearest", "given"]),
    "units": st.sampled_from(["m", "mm", "cm"]),
    "mass_kg": st.sampled_from([1e-3, 1.0, 300.0, 1e7]),
    "footprint_tolerance_m": st.sampled_from([0.0, 0.003, 0.05]),
    "rotation_wxyz": st.lists(st.floats(-10, 10), min_size=4, max_size=4),
    "heading_deg": st.floats(-360, 360),
})


def check(path, description):
    """The loader's answer: a valid specimen, or a one-line InputError naming the file."""
    with hang_bound(SECONDS_PER_MESH):
        try:
            rock = ColumnGeometry.load(description)
        except InputError as exc:
            message = str(exc)
            assert message and message.isprintable() and len(message.splitlines()) == 1, message
            assert description.name in message, message
            return message
    assert isinstance(rock, MeshSpecimen)
    assert rock.mass > 0 and rock.volume_m3 > 0 and math.isfinite(rock.mass)
    assert np.isfinite(rock.com).all() and np.isfinite(rock.inertia).all()
    assert np.linalg.eigvalsh(rock.inertia).min() > -1e-9 * np.abs(rock.inertia).max()
    lo, hi = mesh_module.DENSITY_RANGE
    assert lo * (1 - 1e-9) <= rock.density <= hi * (1 + 1e-9)
    assert len(rock.footprint) >= 3 and rock.statics()[0]["ratio"] >= 0
    return "ok"


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@FUZZ
@given(kind=st.sampled_from(["box", "sphere", "cylinder", "tetra", "soup"]),
       changes=st.lists(st.sampled_from(["split", "wind", "drop", "double", "degenerate",
                                         "flatten", "jitter", "scale", "second body",
                                         "far away"]), max_size=3),
       suffix=st.sampled_from([".obj", ".ply", ".stl"]), seed=st.integers(0, 2 ** 32 - 1),
       options=OPTIONS)
# found by this test: the stable-pose search sampled a centre of mass outside the hull
# forever; a surface crossing itself gave a negative moment of inertia; footprint points
# on a line
@example(kind="cylinder", changes=["double", "flatten", "jitter"], suffix=".obj", seed=525746,
         options={"close_base": 0.0})
@example(kind="cylinder", changes=["flatten", "flatten", "jitter"], suffix=".obj",
         seed=525746, options={})
@example(kind="sphere", changes=["wind"], suffix=".obj", seed=3396,
         options={"rest_pose": "given", "rotation_wxyz": [0.0, 0.0, 0.0, 8.656523174366334e-44]})
def test_fuzz_meshes(fuzz_dir, kind, changes, suffix, seed, options):
    rng = np.random.default_rng(seed)
    mesh = shape(kind, rng)
    for change in changes:
        mesh = changed(mesh, change, rng)
    path = fuzz_dir / f"fuzzed{suffix}"
    try:
        mesh.export(path)
    except Exception:            # trimesh cannot write it (no faces, say): nothing to read
        return
    description = fuzz_dir / "fuzzed.json"
    description.write_text(json.dumps({"name": "fuzzed", "mesh": path.name, **options}))
    mesh_module._posed.cache_clear()
    check(path, description)


@FUZZ
@given(content=st.binary(max_size=400), suffix=st.sampled_from([".obj", ".ply", ".stl"]))
def test_fuzz_mesh_bytes(fuzz_dir, content, suffix):
    path = fuzz_dir / f"bytes{suffix}"
    path.write_bytes(content)
    description = fuzz_dir / "bytes.json"
    description.write_text(json.dumps({"mesh": path.name}))
    mesh_module._posed.cache_clear()
    check(path, description)
