"""Mesh specimens (scanned rocks): mass properties and rest pose against closed forms, the
loader's one-line errors, and a box given as a mesh rocking as the same box given as a
column file (two paths in the same run)."""
import json
import math

import numpy as np
import pytest
import trimesh

from pipeline.constants import MODEL_GRAVITY as G
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.outcome.columns import column_outcomes
from pipeline.scenario import ColumnGeometry, ColumnSpec, run_yade, scene_params, write_scenario
from pipeline.scenario.mesh import MeshSpecimen

W, D, H = 0.3, 0.4, 1.2          # m: a slender box, alpha = atan(W / H) about North
DENSITY = 2700.0


def box_mesh(tmp_path, name="box.obj", transform=None, scale=1.0):
    mesh = trimesh.creation.box(extents=(W * scale, D * scale, H * scale))
    mesh.apply_translation([5.0, -3.0, 40.0])       # anywhere: the loader places it
    if transform is not None:
        mesh.apply_transform(transform)
    path = tmp_path / name
    mesh.export(path)
    return path


def box_file():
    return ColumnGeometry.from_dict({"name": "box", "density": DENSITY, "blocks": [
        {"shape": "box", "height": H, "width": W, "depth": D}]})


def test_mass_properties_and_statics_of_a_box_mesh_are_the_closed_forms(tmp_path):
    rock = MeshSpecimen.from_dict({"name": "box", "mesh": str(box_mesh(tmp_path)),
                                   "density": DENSITY})
    m = DENSITY * W * D * H
    assert rock.mass == pytest.approx(m, rel=1e-9)
    assert rock.com == pytest.approx([0.0, 0.0, H / 2], abs=1e-9)
    assert np.diag(rock.inertia) == pytest.approx(
        [m * (D * D + H * H) / 12, m * (W * W + H * H) / 12, m * (W * W + D * D) / 12],
        rel=1e-9)
    assert rock.uplift_ratio() == pytest.approx(W / H, rel=1e-9)
    assert rock.uplift_ratio() == pytest.approx(box_file().uplift_ratio(), rel=1e-9)
    # the barrier a scene is given (the lowest over the stacks, as scene_column writes it)
    assert min(j["barrier_j"] for j in rock.statics()) == pytest.approx(
        min(j["barrier_j"] for j in box_file().statics()), rel=1e-9)
    assert rock.height == pytest.approx(H)
    assert sorted(np.abs(rock.footprint).max(axis=0)) == pytest.approx([W / 2, D / 2])


def test_a_tilted_mesh_settles_onto_its_face_and_mass_kg_wins(tmp_path):
    tilt = trimesh.transformations.rotation_matrix(math.radians(4.0), [1, 1, 0])
    path = box_mesh(tmp_path, transform=tilt)
    rock = MeshSpecimen.from_dict({"mesh": str(path), "mass_kg": 123.0})
    assert rock.settled_by_deg == pytest.approx(4.0, abs=1e-6)
    assert rock.height == pytest.approx(H, abs=1e-9)
    assert rock.mass == 123.0
    with pytest.raises(InputError, match="cannot stand"):   # kept tilted: on one corner
        MeshSpecimen.from_dict({"mesh": str(path), "rest_pose": "given"})


def test_units_heading_and_json_description(tmp_path):
    path = box_mesh(tmp_path, scale=1000.0)             # the same box in millimetres
    spec = tmp_path / "rock.json"
    spec.write_text(json.dumps({"name": "mm box", "mesh": path.name, "units": "mm",
                                "density": DENSITY, "heading_deg": 90.0}))
    rock = ColumnGeometry.load(spec)                    # one loader for both kinds of file
    assert isinstance(rock, MeshSpecimen)
    assert rock.mass == pytest.approx(DENSITY * W * D * H, rel=1e-9)
    # turned clockwise by 90 deg: the box's width now lies along North
    assert np.abs(rock.footprint).max(axis=0) == pytest.approx([D / 2, W / 2])
    assert MeshSpecimen.from_dict(rock.to_dict()).mass == rock.mass


@pytest.mark.parametrize("change, words", [
    ({"mesh": "nowhere.obj"}, "not found"),
    ({"mesh": "box.txt"}, "not a mesh file"),
    ({"mass_kg": 10.0, "density": 2000.0}, "not both"),
    ({"mass_kg": -1.0}, "mass_kg"),
    ({"units": "inch"}, "units"),
    ({"rest_pose": "upside"}, "rest_pose"),
    ({"rotation_wxyz": [0, 0, 0, 0]}, "rotation_wxyz"),
    ({"footprint_tolerance_m": 0.5}, "footprint_tolerance_m"),
    ({"colour": "grey"}, "unknown key"),
    ({"units": "mm"}, "check 'units'"),
])
def test_bad_descriptions_are_one_line_errors(tmp_path, change, words):
    path = box_mesh(tmp_path)
    data = {"name": "box", "mesh": str(path), **change}
    if change.get("mesh"):
        data["mesh"] = str(tmp_path / change["mesh"])
    with pytest.raises(InputError, match=words) as info:
        MeshSpecimen.from_dict(data)
    assert "\n" not in str(info.value)


def test_an_open_mesh_is_refused(tmp_path):
    mesh = trimesh.creation.box(extents=(W, D, H))
    mesh.update_faces(np.arange(len(mesh.faces)) > 0)        # a hole
    path = tmp_path / "open.obj"
    mesh.export(path)
    with pytest.raises(InputError, match="not closed: 1 hole") as info:
        MeshSpecimen.from_dict({"mesh": str(path)})
    # where: the removed triangle's edge (two box edges and a diagonal) and its centre
    corners = mesh.vertices[trimesh.creation.box(extents=(W, D, H)).faces[0]]
    around = sum(np.linalg.norm(corners - np.roll(corners, 1, axis=0), axis=1))
    assert f"the largest {around:.3g} m around" in str(info.value)
    assert "centred at (" + ", ".join(f"{c:.4g}" for c in corners.mean(axis=0)) \
        in str(info.value)


def sine(factor, ratio, freq=2.0, seconds=3.0, dt=0.005):
    t = np.arange(0, seconds, dt)
    a = factor * ratio * G * np.sin(2 * math.pi * freq * t) * np.minimum(1.0, t / 0.5)
    z = 0 * a
    v = np.cumsum(a) * dt
    return Motion(dt, np.column_stack([a, z, z]), np.column_stack([v, z, z]),
                  np.column_stack([np.cumsum(v) * dt, z, z]))


@pytest.mark.yade
def test_a_box_mesh_rocks_as_the_same_box_from_a_column_file(tmp_path):
    """Below the uplift threshold neither rocks; above it both rock alike (the mesh's
    footprint points are the box's corners: same mass, inertia and base), and a strong
    pulse topples both toward the same side."""
    rock = MeshSpecimen.from_dict({"name": "box", "mesh": str(box_mesh(tmp_path)),
                                   "density": DENSITY})
    ratio = W / H
    tilts = {}
    for factor in (0.8, 1.3, 3.0):
        motion = sine(factor, ratio)
        outcome = {}
        for kind, geometry in (("mesh", rock), ("file", box_file())):
            params = scene_params(columns=[ColumnSpec("monolithic", "monolithic", 0.0, 0.0,
                                                      geometry)],
                                  t_max=motion.duration + 3.0)
            directory = tmp_path / f"{kind}{factor}"
            write_scenario(directory, params, motion)
            (outcome[kind],) = column_outcomes(run_yade(directory))
        tilts[factor] = {k: o["max_tilt_deg"] for k, o in outcome.items()}
        if factor == 0.8:
            assert all(t < 0.05 for t in tilts[factor].values())
        elif factor == 1.3:
            assert not outcome["mesh"]["toppled"] and not outcome["file"]["toppled"]
            assert tilts[factor]["mesh"] > 0.5
            assert tilts[factor]["mesh"] == pytest.approx(tilts[factor]["file"], rel=0.1)
        else:
            assert outcome["mesh"]["toppled"] and outcome["file"]["toppled"]
            east = [math.sin(math.radians(o["downfall_azimuth_deg"])) for o in outcome.values()]
            assert east[0] * east[1] > 0 and min(abs(e) for e in east) > 0.9
    print(f"max tilt (deg) per factor of the uplift threshold: {tilts}")


@pytest.mark.parametrize("suffix", [".stl", ".ply"])
def test_stl_and_ply_give_the_same_specimen_as_obj(tmp_path, suffix):
    obj = MeshSpecimen.load(box_mesh(tmp_path))
    other = MeshSpecimen.load(box_mesh(tmp_path, name=f"box{suffix}"))
    # STL and PLY store float32 vertices (the box sits 40 m up): 1e-5 is their precision
    assert other.mass == pytest.approx(obj.mass, rel=1e-5)       # bare mesh: granite
    assert obj.density == pytest.approx(2650.0)
    assert other.uplift_ratio() == pytest.approx(obj.uplift_ratio(), rel=1e-5)


def test_campaigns_that_scale_blocks_refuse_a_mesh_in_one_line(tmp_path):
    from pipeline.campaign.column_file import description
    data = {"name": "box", "mesh": str(box_mesh(tmp_path)), "density": DENSITY}
    assert description(data, meshes=True)["mesh_sha256"]
    with pytest.raises(InputError, match="a mesh specimen") as info:
        description(data)
    assert "\n" not in str(info.value)
