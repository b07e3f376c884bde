"""Outcome parsing and scenario generation, without YADE."""
import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pipeline import outcome, scenario
from pipeline.files import InputError
from pipeline.run import back_azimuth_of, drive_motion, rotate_horizontal


def lying_trajectory(azimuth_deg, n_drums=1, radius=0.29, height=3.5, fall_at=1.0):
    """Hand-built trajectory: a column standing at (1.5, 0) that lies flat toward
    azimuth_deg from fall_at on (bodies along the fall line, centres at height r)."""
    t = np.linspace(0, 2, 201)
    h = height / n_drums
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0])
    tilt_axis = np.cross([0, 0, 1], u)
    down = Rotation.from_rotvec(tilt_axis * math.pi / 2)
    pos = np.zeros((len(t), n_drums, 3))
    quat = np.zeros((len(t), n_drums, 4))
    origin = np.array([1.5, 0.0, 0.0])
    for k in range(n_drums):
        standing = origin + [0, 0, (k + 0.5) * h]
        lying = origin + u * (k + 0.5) * h + [0, 0, radius]
        fallen = t >= fall_at
        pos[:, k] = np.where(fallen[:, None], lying, standing)
        q = down.as_quat()  # x, y, z, w
        quat[:, k] = np.where(fallen[:, None], [q[3], q[0], q[1], q[2]], [1, 0, 0, 0])
    bodies = [{"shape": "cylinder", "column": "drums" if n_drums > 1 else "monolithic",
               "index": k, "height": h, "radius": radius, "mass": 100.0,
               "initial_pos": list(origin + [0, 0, (k + 0.5) * h])} for k in range(n_drums)]
    return {"t": t, "pos": pos, "quat": quat, "bodies": bodies, "vel": np.zeros_like(pos),
            "angvel": np.zeros_like(pos), "dt": 1e-4, "motion_end": 1.0, "stopped_early": True}


@pytest.mark.parametrize("azimuth", [0.0, 45.0, 135.0, 270.0, 359.0])
def test_fallen_monolith_gives_its_direction_and_time(azimuth):
    (col,) = outcome.column_outcomes(lying_trajectory(azimuth))
    assert col["toppled"]
    assert col["downfall_azimuth_deg"] == pytest.approx(azimuth, abs=1e-6) or \
        abs(col["downfall_azimuth_deg"] - azimuth) == pytest.approx(360, abs=1e-6)
    assert col["impact_time_s"] == pytest.approx(1.0, abs=0.011)
    # centre of mass lands half the height away from the base
    assert math.hypot(*col["impact_point_m"]) == pytest.approx(1.75, abs=1e-3)
    assert col["max_tilt_deg"] == pytest.approx(90, abs=1e-6)


def test_drum_column_impact_point_is_mass_weighted_mean():
    (col,) = outcome.column_outcomes(lying_trajectory(60.0, n_drums=7))
    assert col["toppled"]
    assert col["downfall_azimuth_deg"] == pytest.approx(60.0, abs=1e-6)
    # the bottom drum lies on its side too: its top rim touched, so all 7 struck
    assert sum(b["struck"] for b in col["bodies"]) == 7
    assert math.hypot(*col["impact_point_m"]) == pytest.approx(1.75, abs=1e-3)


def test_standing_column_has_not_toppled():
    traj = lying_trajectory(0.0, fall_at=10.0)
    (col,) = outcome.column_outcomes(traj)
    assert not col["toppled"]
    assert col["downfall_azimuth_deg"] is None and col["impact_time_s"] is None


def test_azimuth_convention():
    assert outcome.azimuth_deg(0, 1) == 0.0
    assert outcome.azimuth_deg(1, 0) == 90.0
    assert outcome.azimuth_deg(0, -1) == 180.0
    assert outcome.azimuth_deg(-1, 0) == 270.0


def test_rotate_horizontal_turns_azimuth_clockwise():
    north = np.array([[0.0, 1.0, 0.5]])
    turned = rotate_horizontal(north, 90.0)
    assert turned[0] == pytest.approx([1.0, 0.0, 0.5])
    assert back_azimuth_of({"back_azimuth_deg": 300.0}, rotate_deg=90.0) == pytest.approx(30.0)
    assert back_azimuth_of({"back_azimuth_deg": None}) is None


def test_drive_window_cuts_and_rezeroes_displacement():
    dt = 0.01
    disp = np.column_stack([np.arange(100) * 0.01, np.zeros(100), np.zeros(100)])
    motion = {"dt": dt, "acc": np.zeros((100, 3)), "disp": disp}
    cut = drive_motion(motion, window=(0.5, 0.7))
    assert len(cut["disp"]) == 21
    assert cut["disp"][0, 0] == 0.0 and cut["disp"][-1, 0] == pytest.approx(0.2)
    with pytest.raises(InputError):
        drive_motion(motion, window=(2.0, 3.0))


@pytest.mark.parametrize("bad", [dict(hd=0), dict(hd=-6), dict(height=float("nan")),
                                 dict(n_drums=0), dict(n_drums=2.5), dict(column="pillar")])
def test_impossible_column_parameters(bad):
    with pytest.raises(InputError):
        scenario.column_specs(**bad)


@pytest.mark.parametrize("bad", [dict(mu_s=0.5, mu_k=0.6), dict(kn=-1.0), dict(damping=-0.1),
                                 dict(mu_s=0.0), dict(drive="teleport"), dict(bogus=1)])
def test_impossible_scene_parameters(bad):
    with pytest.raises(InputError):
        scenario.scene_params(columns=scenario.column_specs("both"), motion_duration=1, **bad)


def test_twin_model_geometry():
    drums, mono = scenario.column_specs("both", hd=6.0, height=3.5)
    assert (drums["x"], mono["x"]) == (-1.5, 1.5)
    assert drums["diameter"] == pytest.approx(3.5 / 6)
    # paper: monolith 2772 kg for d = 0.58 m (d = H / (h/d) = 0.5833 m here); its
    # "231 kg" per drum is 2772 / 12 and cannot belong to 7 equal drums of that column
    mass = 2960 * math.pi * (drums["diameter"] / 2) ** 2 * 3.5
    assert mass == pytest.approx(2772, rel=0.02)
    (single,) = scenario.column_specs("monolithic")
    assert single["x"] == 0.0


def test_generated_scene_never_contains_values(tmp_path):
    evil = 'x"; import os; os.system("rm -rf /")  #\n\'\'\''
    params = scenario.scene_params(columns=scenario.column_specs("both"), motion_duration=1.0)
    params["record_name"] = evil
    motion = {"dt": 0.01, "acc": np.zeros((101, 3)), "disp": np.zeros((101, 3))}
    script = scenario.write_scenario(tmp_path, params, motion)
    assert script.read_bytes() == scenario.SCENE_TEMPLATE.read_bytes()
    assert json.loads((tmp_path / "params.json").read_text())["record_name"] == evil


def test_motion_with_nan_is_rejected_and_nothing_written(tmp_path):
    acc = np.zeros((10, 3))
    acc[3, 1] = np.nan
    params = scenario.scene_params(columns=scenario.column_specs("both"), motion_duration=1.0)
    with pytest.raises(InputError, match="NaN"):
        scenario.write_scenario(tmp_path / "run", params, {"dt": 0.01, "acc": acc, "disp": acc})
    assert not (tmp_path / "run" / "params.json").exists()
