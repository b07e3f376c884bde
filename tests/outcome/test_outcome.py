"""Outcome parsing and the drive motion, without YADE."""
import math

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.motion import Motion, azimuth_deg, rotate_horizontal
from pipeline.outcome.columns import column_outcomes
from pipeline.simulate import drive_motion


@pytest.mark.parametrize("azimuth", [0.0, 45.0, 135.0, 270.0, 359.0])
def test_fallen_monolith_gives_its_direction_and_time(azimuth, make_lying_trajectory):
    (col,) = column_outcomes(make_lying_trajectory(azimuth))
    assert col["toppled"]
    assert col["downfall_azimuth_deg"] == pytest.approx(azimuth, abs=1e-6) or \
        abs(col["downfall_azimuth_deg"] - azimuth) == pytest.approx(360, abs=1e-6)
    assert col["impact_time_s"] == pytest.approx(1.0, abs=0.011)
    # centre of mass lands half the height away from the base
    assert math.hypot(*col["impact_point_m"]) == pytest.approx(1.75, abs=1e-3)
    assert col["max_tilt_deg"] == pytest.approx(90, abs=1e-6)


def test_drum_column_impact_point_is_mass_weighted_mean(make_lying_trajectory):
    (col,) = column_outcomes(make_lying_trajectory(60.0, n_drums=7))
    assert col["toppled"]
    assert col["downfall_azimuth_deg"] == pytest.approx(60.0, abs=1e-6)
    # the bottom drum lies on its side too: its top rim touched, so all 7 struck
    assert sum(b["struck"] for b in col["bodies"]) == 7
    assert math.hypot(*col["impact_point_m"]) == pytest.approx(1.75, abs=1e-3)


def test_standing_column_has_not_toppled(make_lying_trajectory):
    traj = make_lying_trajectory(0.0, fall_at=10.0)
    (col,) = column_outcomes(traj)
    assert not col["toppled"]
    assert col["downfall_azimuth_deg"] is None and col["impact_time_s"] is None


def test_azimuth_convention():
    assert azimuth_deg(0, 1) == 0.0
    assert azimuth_deg(1, 0) == 90.0
    assert azimuth_deg(0, -1) == 180.0
    assert azimuth_deg(-1, 0) == 270.0


def test_rotate_horizontal_turns_azimuth_clockwise():
    north = np.array([[0.0, 1.0, 0.5]])
    turned = rotate_horizontal(north, 90.0)
    assert turned[0] == pytest.approx([1.0, 0.0, 0.5])
    zeros = np.zeros((2, 3))
    motion = Motion(0.01, zeros, zeros, zeros, meta={"back_azimuth_deg": 300.0})
    assert motion.rotate(90.0).back_azimuth == pytest.approx(30.0)
    assert Motion(0.01, zeros, zeros, zeros).rotate(90.0).back_azimuth is None


def test_drive_window_cuts_and_rezeroes_displacement():
    dt = 0.01
    disp = np.column_stack([np.arange(100) * 0.01, np.zeros(100), np.zeros(100)])
    motion = Motion(dt, np.zeros((100, 3)), np.zeros((100, 3)), disp)
    cut = drive_motion(motion, window=(0.5, 0.7))
    assert len(cut.disp) == 21
    assert cut.disp[0, 0] == 0.0 and cut.disp[-1, 0] == pytest.approx(0.2)
    with pytest.raises(InputError):
        drive_motion(motion, window=(2.0, 3.0))


def test_a_body_upside_down_is_never_standing(make_lying_trajectory):
    """A monolith turned upside down in the air (tilt 180 deg, no rim near the pedestal):
    toppled, by its tilt, toward the azimuth its axis had when it passed 90 deg."""
    from scipy.spatial.transform import Rotation
    from pipeline.outcome.columns import column_outcomes
    traj = make_lying_trajectory(0.0)
    n = len(traj.t)
    angle = np.radians(np.linspace(0.0, 180.0, n))                # tips over toward East
    q = Rotation.from_rotvec(np.column_stack([0 * angle, angle, 0 * angle])).as_quat()
    traj.quat[:, 0] = q[:, [3, 0, 1, 2]]
    traj.pos[:, 0] = traj.bodies[0]["initial_pos"] + np.array([0.0, 0.0, 50.0])  # in the air
    (col,) = column_outcomes(traj)
    assert col["toppled"] and col["toppled_by"] == "tilt past 90 deg"
    assert col["downfall_azimuth_deg"] == pytest.approx(90.0, abs=1.0)
    assert col["max_tilt_deg"] == pytest.approx(180.0, abs=0.5)
