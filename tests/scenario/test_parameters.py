"""Scene parameters and the scene writer, without YADE."""
import ast
import dataclasses
import json
import math

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.scenario import Column, Contact, Numerics, scene_params, write_scenario
from pipeline.scenario.time_step import largest_stable_dt_factor
from pipeline.scenario.writer import SCENE_TEMPLATE


@pytest.mark.parametrize("bad", [dict(hd=0), dict(hd=-6), dict(height=float("nan")),
                                 dict(n_drums=0), dict(n_drums=2.5), dict(kind="pillar"),
                                 dict(hd=1e6), dict(n_drums=1000)])
def test_impossible_column_parameters(bad):
    with pytest.raises(InputError) as info:
        Column(**bad)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("cls, bad", [
    (Contact, dict(mu_s=0.5, mu_k=0.6)), (Contact, dict(kn=-1.0)), (Contact, dict(damping=-0.1)),
    (Contact, dict(damping=5.0)), (Contact, dict(mu_s=0.0)), (Contact, dict(mu_k=float("nan"))),
    (Numerics, dict(drive="teleport")), (Numerics, dict(dt_factor=-1)),
    (Numerics, dict(dt_factor=0)), (Numerics, dict(dt_factor=float("nan"))),
    (Numerics, dict(rim_points=2))])
def test_impossible_scene_parameters(cls, bad):
    with pytest.raises(InputError) as info:
        cls(**bad)
    message = str(info.value)
    assert "\n" not in message
    assert any(key in message or key.replace("_", "-") in message for key in bad)


def test_time_step_factor_limited_by_the_contact_damping():
    # 0.75 x 2 (sqrt(1 + (2.3 zeta)^2) - 2.3 zeta) / 3, by hand: 0.5 undamped,
    # 0.5 (sqrt(6.29) - 2.3) = 0.10399 critical, 0.5 (sqrt(1.685584) - 0.828) = 0.23515
    # at the paper's 0.36
    assert largest_stable_dt_factor(0.0) == pytest.approx(0.5)
    assert largest_stable_dt_factor(1.0) == pytest.approx(0.10399, abs=1e-5)
    assert largest_stable_dt_factor(0.36) == pytest.approx(0.23515, abs=1e-5)
    default = scene_params(columns=Column().specs(), contact=Contact(damping=1.0))
    assert default.dt_factor == pytest.approx(0.10399, abs=1e-5)   # unset: the limit
    assert scene_params(columns=Column().specs(),
                        contact=Contact(damping=0.1)).dt_factor == 0.3   # converged cap
    scene_params(columns=Column().specs(), numerics=Numerics(dt_factor=0.2))  # damping 0.36
    with pytest.raises(InputError) as info:
        scene_params(columns=Column().specs(), contact=Contact(damping=1.0),
                     numerics=Numerics(dt_factor=0.3))
    message = str(info.value)
    assert "\n" not in message and "--dt-factor 0.3" in message and "--damping 1" in message
    assert "<= 0.103" in message


def test_mu_k_follows_mu_s_unless_given():
    assert Contact().mu_k == 0.6                       # the paper's pair 0.7 / 0.6
    assert Contact(mu_s=0.5).mu_k == pytest.approx(0.5 * 0.6 / 0.7, abs=5e-5)   # the paper's ratio
    assert Contact(mu_s=0.5, mu_k=0.3).mu_k == 0.3


def test_twin_model_geometry():
    drums, mono = Column("both", hd=6.0, height=3.5).specs()
    assert (drums.x, mono.x) == (-1.5, 1.5)
    assert {b.solid.bottom_diameter for b in drums.geometry.blocks} == {3.5 / 6}
    assert len(drums.geometry.blocks) == 7 and len(mono.geometry.blocks) == 1
    # paper: monolith 2772 kg for d = 0.58 m (d = H / (h/d) = 0.5833 m here); its
    # "231 kg" per drum is 2772 / 12 and cannot belong to 7 equal drums of that column
    mass = 2960 * math.pi * (3.5 / 6 / 2) ** 2 * 3.5
    assert mass == pytest.approx(2772, rel=0.02)
    (body,) = mono.geometry.bodies()
    assert body.mass == pytest.approx(mass, rel=1e-15)
    (single,) = Column("monolithic").specs()
    assert single.x == 0.0


def test_generated_scene_never_contains_values(tmp_path):
    evil = 'x"; import os; os.system("rm -rf /")  #\n\'\'\''
    params = scene_params(columns=Column("both").specs(), motion_duration=1.0)
    params = dataclasses.replace(params, columns=[dict(params.columns[0], description=evil),
                                                  *params.columns[1:]])
    zeros = np.zeros((101, 3))
    script = write_scenario(tmp_path, params, Motion(0.01, zeros, zeros, zeros,
                                                     meta={"record_id": evil}))
    assert script.read_bytes() == SCENE_TEMPLATE.read_bytes()
    assert json.loads((tmp_path / "params.json").read_text())["columns"][0]["description"] \
        == evil


def test_motion_with_nan_is_rejected_and_nothing_written(tmp_path):
    acc = np.zeros((10, 3))
    acc[3, 1] = np.nan
    with pytest.raises(InputError, match="NaN"):
        Motion(0.01, acc, acc, acc)
    assert not (tmp_path / "run").exists()


def test_the_scene_holds_no_physics_constant():
    """Every number yade_scripts/column_scene.py computes with comes from params.json: its
    code holds only small counts, indices and factors of formulas (0 to 4, 1/2), the bit of its
    'collides with nothing' mask and the interval it polls YADE's loop at."""
    tree = ast.parse(SCENE_TEMPLATE.read_text())
    exempt = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.LShift):
            exempt.add(id(node.right))                          # a mask bit
        if isinstance(node, ast.Call) and ast.unparse(node.func) == "time.sleep":
            exempt.update(id(a) for a in node.args)             # polling, not physics
    constants = sorted({ast.unparse(node) for node in ast.walk(tree)
                        if isinstance(node, ast.Constant) and id(node) not in exempt
                        and isinstance(node.value, (int, float))
                        and not isinstance(node.value, bool)
                        and node.value not in (0, 1, 2, 3, 4, 0.5)})
    assert constants == []


def test_the_scene_file_reads_back_as_written(tmp_path):
    """The one writer and the one reader of params.json: what is written reads back equal,
    with gravity and the lying threshold of the outcome."""
    from pipeline.constants import LIES_TILT_DEG, MODEL_GRAVITY
    from pipeline.scenario.scene_file import SceneFile
    params = scene_params(columns=Column("both", column_file="doric-peristyle").specs(),
                          motion_duration=1.0)
    params.write(tmp_path)
    read = SceneFile.read(tmp_path)
    assert read == SceneFile.from_dict(json.loads(json.dumps(params.to_dict())))
    assert read.to_dict() == json.loads((tmp_path / "params.json").read_text())
    assert read.gravity == MODEL_GRAVITY and read.thresholds.lies_tilt_deg == LIES_TILT_DEG
    assert math.cos(math.radians(read.thresholds.lies_tilt_deg)) == \
        pytest.approx(read.thresholds.lies_axis_z, abs=1e-15)
