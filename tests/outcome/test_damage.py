"""Damage measures against hand-built final states whose answer is known by construction:
a drum shifted and turned by a stated amount, a column leaning as one rigid piece, the
capital's path of a column tilted about its base edge (closed form), the whole scene
turned about the vertical, a column that never moved."""
import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pipeline.files import InputError
from pipeline.outcome import Trajectory
from pipeline.outcome.columns import column_outcomes, summarise
from pipeline.outcome.damage import LEVELS, DamageMeasures, DamageState, JointDislocation
from pipeline.outcome.summary import ColumnOutcome, RunSummary

R, H = 0.4, 1.0              # m: drum radius, drum height
ORIGIN = np.array([1.5, 0.0, 0.0])


def drum(k, n_drums=2):
    face = {"kind": "circle", "radius": R, "centre": [0.0, 0.0]}
    return {"name": f"drums[{k}]", "column": "drums", "index": k, "shape": "cylinder",
            "height": H, "radius": R, "mass": 1000.0,
            "initial_pos": (ORIGIN + [0.0, 0.0, (k + 0.5) * H]).tolist(),
            "initial_rotation": np.eye(3).tolist(),
            "rims": [dict(face, role="base", z=-H / 2, normal=[0.0, 0.0, 1.0]),
                     dict(face, role="edge", z=H / 2, normal=[0.0, 0.0, -1.0])]}


def quat(rotation):
    x, y, z, w = rotation.as_quat()
    return [w, x, y, z]


def tilted(theta_deg, bodies):
    """Poses (pos, quat) of the bodies turned rigidly by theta about the column's base
    edge on its East side (the top moves East)."""
    turn = Rotation.from_rotvec([0.0, math.radians(theta_deg), 0.0])
    pivot = ORIGIN + [R, 0.0, 0.0]
    pos = [pivot + turn.apply(np.array(b["initial_pos"]) - pivot) for b in bodies]
    return np.array(pos), np.array([quat(turn)] * len(bodies))


def trajectory(poses, bodies):
    """A trajectory through the (pos, quat) poses given, one sample each."""
    pos = np.array([p for p, _ in poses])
    q = np.array([q for _, q in poses])
    return Trajectory(t=np.arange(len(poses), dtype=float), pos=pos, quat=q, bodies=bodies)


def at_rest(bodies):
    return (np.array([b["initial_pos"] for b in bodies]),
            np.array([[1.0, 0.0, 0.0, 0.0]] * len(bodies)))


def shifted_top(bodies, shift, twist_deg):
    """The placement with the top drum slid by ``shift`` (m) and turned about its axis."""
    pos, q = at_rest(bodies)
    pos[-1, :2] += shift
    q[-1] = quat(Rotation.from_rotvec([0.0, 0.0, math.radians(twist_deg)]))
    return pos, q


def test_a_drum_slid_and_turned_reports_its_slide_and_twist():
    bodies = [drum(0), drum(1)]
    traj = trajectory([at_rest(bodies), tilted(5.0, bodies),
                       shifted_top(bodies, (0.03, -0.04), 10.0)], bodies)
    (column,) = column_outcomes(traj)
    damage = DamageMeasures.from_dict(column["damage"])
    base, joint = damage.joints
    assert (base.lower, base.upper, joint.lower, joint.upper) == \
        ("pedestal", "drums[0]", "drums[0]", "drums[1]")
    assert base.slide_m == pytest.approx(0.0, abs=1e-12)
    assert base.twist_deg == pytest.approx(0.0, abs=1e-9)
    assert joint.slide_m == pytest.approx(0.05, rel=1e-12)
    assert joint.twist_deg == pytest.approx(10.0, rel=1e-9)
    # the capital (top face centre, 2H up) tilted 5 deg about the base edge moves
    # R (1 - cos) + 2H sin East; later the slide moves it 0.05 m
    theta = math.radians(5.0)
    assert damage.peak_capital_displacement_m == pytest.approx(
        R * (1 - math.cos(theta)) + 2 * H * math.sin(theta), rel=1e-9)
    assert damage.base_width_m == pytest.approx(2 * R, rel=1e-9)
    # alpha: the whole column's, atan(R / H) (centre of mass at H), below the top drum's
    assert damage.critical_angle_deg == pytest.approx(math.degrees(math.atan(R / H)), rel=1e-6)
    assert damage.rotation_ratio == pytest.approx(5.0 / math.degrees(math.atan(R / H)),
                                                  rel=1e-6)
    assert damage.max_residual_slide_m == pytest.approx(0.05)
    assert damage.residual_state == DamageState.MODERATE          # 0.05 / 0.8 = 0.0625
    assert damage.rotation_state == DamageState.SLIGHT            # 5 / 21.8 = 0.23
    assert damage.capital_state == DamageState.SLIGHT             # 0.176 / 0.8 = 0.22
    assert damage.damage_state == DamageState.MODERATE


def test_a_column_leaning_as_one_piece_has_no_dislocation_between_drums():
    bodies = [drum(0), drum(1), drum(2)]
    for k, b in enumerate(bodies):
        b["initial_pos"][2] = (k + 0.5) * H
    damage = DamageMeasures.from_dict(column_outcomes(trajectory(
        [at_rest(bodies), tilted(3.0, bodies)], bodies))[0]["damage"])
    for joint in damage.joints[1:]:
        assert joint.slide_m == pytest.approx(0.0, abs=1e-12)
        assert joint.twist_deg == pytest.approx(0.0, abs=1e-9)
    assert damage.max_rotation_deg == pytest.approx(3.0, rel=1e-9)


@pytest.mark.parametrize("turn_deg", [37.0, 90.0, 211.0])
def test_turning_the_scene_about_the_vertical_keeps_the_measures(turn_deg):
    bodies = [drum(0), drum(1)]
    poses = [at_rest(bodies), tilted(4.0, bodies), shifted_top(bodies, (0.02, 0.01), -7.0)]
    turn = Rotation.from_rotvec([0.0, 0.0, math.radians(turn_deg)])
    turned_bodies = [dict(b, initial_pos=turn.apply(b["initial_pos"]).tolist(),
                          initial_rotation=turn.as_matrix().tolist()) for b in bodies]
    turned = [(turn.apply(p), np.array([quat(turn * Rotation.from_quat(np.roll(q, -1)))
                                        for q in qs])) for p, qs in poses]
    a = DamageMeasures.from_dict(column_outcomes(trajectory(poses, bodies))[0]["damage"])
    b = DamageMeasures.from_dict(column_outcomes(trajectory(turned, turned_bodies))[0]["damage"])
    assert b.peak_capital_displacement_m == pytest.approx(a.peak_capital_displacement_m)
    assert b.max_rotation_deg == pytest.approx(a.max_rotation_deg)
    for ja, jb in zip(a.joints, b.joints):
        assert jb.slide_m == pytest.approx(ja.slide_m, abs=1e-12)
        assert jb.twist_deg == pytest.approx(ja.twist_deg, abs=1e-9)
    assert a.joints[1].twist_deg == pytest.approx(-7.0)


def test_states_follow_the_limits_and_a_toppled_column_collapsed():
    assert DamageState.of(0.0, LEVELS.rotation) == DamageState.NONE
    assert DamageState.of(LEVELS.rotation[0], LEVELS.rotation) == DamageState.SLIGHT
    assert DamageState.of(0.99, LEVELS.rotation) == DamageState.SEVERE
    assert DamageState.of(None, LEVELS.rotation) is None
    fell = DamageMeasures(peak_capital_displacement_m=2.0, base_width_m=0.8,
                          max_rotation_deg=90.0, critical_angle_deg=None, joints=(),
                          toppled=True)
    assert fell.damage_state == DamageState.COLLAPSE and fell.rotation_ratio is None


def test_measures_round_trip_through_summary_json(tmp_path):
    bodies = [drum(0), drum(1)]
    traj = trajectory([at_rest(bodies), shifted_top(bodies, (0.01, 0.0), 2.0)], bodies)
    summary = summarise(traj, "R")
    summary.save(tmp_path / "summary.json")
    data = json.loads((tmp_path / "summary.json").read_text())
    written = data["columns"][0]["damage"]
    assert written["damage_state"] == "slight" and written["residual_state"] == "slight"
    assert written["joints"][1]["slide_m"] == pytest.approx(0.01)
    assert RunSummary.load(tmp_path) == summary


def test_a_column_that_never_moved_has_no_damage():
    bodies = [dict(drum(k), centre=drum(k)["initial_pos"], rotation=np.eye(3).tolist())
              for k in range(3)]
    summary = RunSummary.still("R", [{"name": "drums", "x": 1.5, "y": 0.0, "bodies": bodies}])
    damage = summary.columns[0].damage
    assert damage.peak_capital_displacement_m == 0.0 and damage.max_rotation_deg == 0.0
    assert all(j.slide_m == 0.0 and j.twist_deg == 0.0 for j in damage.joints)
    assert damage.damage_state == DamageState.NONE


@pytest.mark.parametrize("change, message", [
    ({"base_width_m": 0.0}, "base_width_m must be > 0"),
    ({"joints": [{"lower": "a", "upper": "b", "slide_m": -1.0, "twist_deg": 0.0}]}, "slide_m"),
    ({"toppled": True}, "damage measures say toppled"),
    ({"colour": "red"}, "unknown keys colour"),
])
def test_impossible_measures_are_refused(change, message):
    good = DamageMeasures(peak_capital_displacement_m=0.1, base_width_m=0.8,
                          max_rotation_deg=1.0, critical_angle_deg=20.0,
                          joints=(JointDislocation(lower="pedestal", upper="a", slide_m=0.0,
                                                   twist_deg=0.0),), toppled=False)
    with pytest.raises(InputError, match=message):
        ColumnOutcome(column="a", toppled=False, damage={**good.to_dict(), **change})


def test_run_rows_carry_the_measures_and_state():
    from pipeline.campaign.tables import DAMAGE_COLUMNS, damage_columns
    old = damage_columns(None)
    assert old["damage_state"] == "" and all(math.isnan(old[k]) for k in DAMAGE_COLUMNS)
    bodies = [drum(0), drum(1)]
    damage = DamageMeasures.from_dict(column_outcomes(trajectory(
        [at_rest(bodies), shifted_top(bodies, (0.03, 0.04), 0.0)], bodies))[0]["damage"])
    row = damage_columns(damage)
    assert row["max_residual_slide_m"] == pytest.approx(0.05)
    assert row["damage_state"] == "moderate"


def test_a_colonnade_says_how_many_fell_parallel_and_in_sequence():
    from pipeline.outcome.colonnade import ColonnadeOutcome

    def column(name, x, azimuth=None, time=None):
        return ColumnOutcome(column=name, toppled=azimuth is not None,
                             downfall_azimuth_deg=azimuth, impact_time_s=time,
                             position_m=[x, 0.5 * x])
    row = [column("A", 0.0, 88.0, 1.0), column("B", 2.0, 92.0, 1.6),
           column("C", 4.0, 90.0, 2.2), column("D", 6.0)]
    beams = [ColumnOutcome(column="E", toppled=True, downfall_azimuth_deg=10.0),
             ColumnOutcome(column="F", toppled=False)]
    whole = ColonnadeOutcome.of("row", row, beams)
    assert (whole.columns, whole.columns_fallen, whole.beams, whole.beams_fallen) == (4, 3, 2, 1)
    assert whole.fall_azimuth_mean_deg == pytest.approx(90.0, abs=1e-9)
    assert whole.parallel and whole.fall_azimuth_spread_deg < 3.0
    assert whole.fall_order == ("A", "B", "C") and whole.in_sequence
    row[1] = column("B", 2.0, 270.0, 3.0)           # B falls last, the other way
    whole = ColonnadeOutcome.of("row", row, beams)
    assert whole.fall_order == ("A", "C", "B") and not whole.in_sequence
    assert not whole.parallel
