"""Damage measures of YADE runs: a stack shaken below its uplift threshold keeps its
joints as placed (no residual dislocation beyond the contacts' elastic share), and
theta_max / alpha of a rocking monolith is the largest tilt its recorded orientations
show over the critical angle of its proportions, atan(d / h).

Each run is a few simulated seconds."""
import math

import numpy as np
import pytest

from pipeline.constants import MODEL_GRAVITY as G
from pipeline.motion import Motion
from pipeline.outcome.columns import column_outcomes
from pipeline.outcome.damage import DamageMeasures, DamageState
from pipeline.scenario import Column, run_yade, scene_params, write_scenario

pytestmark = pytest.mark.yade

DT = 0.005                 # s


def sine_motion(amplitude, hz, seconds, azimuth_deg):
    """A horizontal sine of ``amplitude`` (m/s^2) along ``azimuth_deg``, with the
    velocity and displacement that integrate it."""
    t = np.arange(0.0, seconds, DT)
    w = 2 * math.pi * hz
    a, v, d = amplitude * np.sin(w * t), amplitude / w * (1 - np.cos(w * t)), \
        amplitude / w * (t - np.sin(w * t) / w)
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0])
    return Motion(DT, np.outer(a, u), np.outer(v, u), np.outer(d, u), meta={"record_id": "sine"})


def run(tmp_path, column, motion):
    params = scene_params(columns=column.specs(), motion_duration=motion.duration)
    write_scenario(tmp_path, params, motion)
    return params, run_yade(tmp_path)


@pytest.mark.libm
def test_a_stack_shaken_below_uplift_keeps_its_joints(tmp_path):
    """Drums shaken at 0.4 g tan(alpha) (rigid-block statics: no joint opens, friction
    holds): every joint's residual slide stays within 0.1 mm (the contacts' elastic
    shear is microns) and its twist within 0.01 deg."""
    column = Column("drums", n_drums=3)
    params = scene_params(columns=column.specs(), motion_duration=1.0)
    ratio = params.columns[0]["uplift_ratio"]
    _, traj = run(tmp_path, column, sine_motion(0.4 * G * ratio, 2.0, 2.0, 30.0))
    (outcome,) = column_outcomes(traj)
    damage = DamageMeasures.from_dict(outcome["damage"])
    assert len(damage.joints) == 3
    for joint in damage.joints:
        assert joint.slide_m < 1e-4
        assert abs(joint.twist_deg) < 0.01
    assert damage.rotation_ratio < 0.01
    assert damage.damage_state == DamageState.NONE


@pytest.mark.libm
def test_rotation_ratio_is_the_recorded_tilt_over_the_critical_angle(tmp_path):
    """A monolith of h/d 6 rocked by a 2 Hz sine of 1.5 g tan(alpha) without falling:
    theta_max / alpha is the largest tilt of its recorded quaternions (cos = 1 -
    2 (x^2 + y^2) for a body placed upright) over atan(1/6)."""
    hd = 6.0
    _, traj = run(tmp_path, Column("monolithic", hd=hd), sine_motion(1.5 * G / hd, 2.0, 2.0, 0.0))
    (outcome,) = column_outcomes(traj)
    damage = DamageMeasures.from_dict(outcome["damage"])
    x, y = traj.quat[:, 0, 1], traj.quat[:, 0, 2]
    tilt = np.degrees(np.arccos(np.clip(1.0 - 2.0 * (x ** 2 + y ** 2), -1.0, 1.0)))
    assert not outcome["toppled"] and tilt.max() > 0.5           # it rocked
    alpha = math.degrees(math.atan(1.0 / hd))
    assert damage.critical_angle_deg == pytest.approx(alpha, rel=1e-9)
    assert damage.rotation_ratio == pytest.approx(tilt.max() / alpha, rel=1e-6)
