"""A colonnade in the YADE scene: each beam a box body of the file's size and density on
its supports' top plates; a colonnade left alone stands (its beams do not sink through
the capitals: the collision masks let each beam's base meet its supports); the run's
summary per body and per colonnade."""
import math

import numpy as np
import pytest

from pipeline.outcome.columns import summarise
from pipeline.outcome.damage import DamageState
from pipeline.scenario import Column, run_yade, scene_params, write_scenario
from pipeline.scenario.colonnade_file import from_dict, load, to_dict

NAME = "parthenon-north-flank"


@pytest.fixture(scope="module")
def scene():
    return scene_params(colonnade=load(NAME), motion_duration=0.0, t_max=0.5)


def world(body, point):
    return np.asarray(body["centre"]) + np.asarray(body["rotation"]) @ np.asarray(point)


def test_beams_are_boxes_of_the_file_on_their_supports_plates(scene):
    units = {c["name"]: c for c in scene.columns}
    assert [c["kind"] for c in scene.columns] == ["column"] * 4 + ["epistyle"] * 3 + \
        ["frieze"] * 3
    assert units["E2"]["rests_on"] == ["N2", "N3"] and units["F1"]["rests_on"] == ["E1"]
    for name in ("E1", "E2", "E3", "F1", "F2", "F3"):
        (beam,) = units[name]["bodies"]
        assert beam["mass"] == pytest.approx(4.2862 * 1.48 * 1.35 * 2700.0, rel=1e-12)
        bases = [r for r in beam["rims"] if r["role"] == "base"]
        assert len(bases) == len(units[name]["rests_on"])
        for rim, support in zip(bases, units[name]["rests_on"]):
            top = units[support]["bodies"][-1]
            plate = top["plate"]
            assert plate is not None
            level = world(top, plate["centre"])
            half = np.asarray(plate["half_size"])
            for vx, vy in rim["vertices"]:
                point = world(beam, (vx, vy, rim["z"]))
                assert point[2] == pytest.approx(level[2], abs=1e-9)   # on the plate
                local = np.asarray(top["rotation"]).T @ (point - level)
                assert np.all(np.abs(local[:2]) <= half + 1e-9)          # within it
    assert units["F1"]["bodies"][0]["plate"] is None
    assert units["E1"]["bodies"][0]["plate"] is not None


@pytest.mark.parametrize("row_azimuth_deg", [0.0, 30.0, 90.0])
def test_beams_lie_along_the_line_between_their_capitals(row_azimuth_deg):
    """The shipped stretch laid along North, at 30 deg and along East (as shipped): each
    beam's long side runs from the first capital it spans to the last, its width across."""
    data = to_dict(load(NAME))
    along = np.array([math.sin(math.radians(row_azimuth_deg)),
                      math.cos(math.radians(row_azimuth_deg))])
    data["stylobate"]["end"] = (data["stylobate"]["end"][0] * along).tolist()
    for column in data["columns"]:
        column["x"], column["y"] = (column["x"] * along).tolist()
    units = {c["name"]: c for c in scene_params(colonnade=from_dict(data), motion_duration=0.0,
                                                t_max=0.5).columns}
    for name in ("E1", "E2", "E3", "F1", "F2", "F3"):
        (beam,) = units[name]["bodies"]
        (part,) = beam["parts"]
        length, width = part["width"], part["depth"]
        assert length == pytest.approx(4.2862) and width == pytest.approx(1.48)
        corners = np.array([world(beam, (sx * length / 2, sy * width / 2, 0.0))[:2]
                            for sx in (-1, 1) for sy in (-1, 1)])
        span = corners @ along                           # along the row
        across = corners @ np.array([along[1], -along[0]])
        assert np.ptp(span) == pytest.approx(length, abs=1e-9)
        assert np.ptp(across) == pytest.approx(width, abs=1e-9)
        epistyle = name if name.startswith("E") else units[name]["rests_on"][0]
        on = units[epistyle]["rests_on"]                 # the capitals it spans
        first, last = (np.asarray(units[c]["bodies"][-1]["centre"][:2]) for c in (on[0], on[-1]))
        axis = (last - first) / np.linalg.norm(last - first)
        assert axis == pytest.approx(along, abs=1e-9)
        assert (np.asarray(beam["rotation"]) @ [1.0, 0.0, 0.0])[:2] == \
            pytest.approx(axis, abs=1e-12)
    if row_azimuth_deg == 0.0:                           # along North: long in y, narrow in x
        (beam,) = units["E2"]["bodies"]
        corners = np.array([world(beam, (sx * 4.2862 / 2, sy * 1.48 / 2, 0.0))[:2]
                            for sx in (-1, 1) for sy in (-1, 1)])
        assert np.ptp(corners[:, 0]) == pytest.approx(1.48, abs=1e-9)
        assert np.ptp(corners[:, 1]) == pytest.approx(4.2862, abs=1e-9)


def test_a_colonnade_file_in_the_column_option():
    column = Column(column_file=NAME)
    assert column.colonnade.name == NAME and column.specs() == []
    assert Column(column_file="doric-peristyle").colonnade is None


@pytest.mark.yade
def test_a_colonnade_left_alone_stands(tmp_path, scene):
    write_scenario(tmp_path / "still", scene, None)
    traj = run_yade(tmp_path / "still")
    sink = traj.pos[-1, :, 2] - np.array([b["initial_pos"][2] for b in traj.bodies])
    # the contact springs' settling only (a few mm: a column's twelve joints and the
    # beams' corners compress under the weight above them); a beam whose base met no
    # capital would have fallen 1.2 m in the 0.5 s
    assert np.abs(sink).max() < 0.01
    summary = summarise(traj, "still", colonnade=NAME)
    assert summary.colonnade.columns == 4 and summary.colonnade.beams == 6
    assert summary.colonnade.columns_fallen == 0 and summary.colonnade.beams_fallen == 0
    assert [c.column for c in summary.columns] == ["N1", "N2", "N3", "N4", "E1", "E2", "E3",
                                                   "F1", "F2", "F3"]
    for column in summary.columns[:4]:          # the end capitals carry half a beam
        assert column.damage.damage_state == DamageState.NONE      # off their axis
        assert column.damage.max_residual_slide_m < 0.002
    assert all(c.damage is None for c in summary.columns[4:])


def test_a_run_a_yade_never_ran_gives_beams_no_damage(scene):
    from pipeline.outcome.summary import RunSummary
    summary = RunSummary.still("quiet", scene.columns, colonnade=None)
    assert [c.damage is None for c in summary.columns] == [False] * 4 + [True] * 6


@pytest.mark.yade
def test_a_colonnade_run_writes_its_description_and_outcome(tmp_path):
    """simulate() with the colonnade as the column file: summary.json holds the
    description (parameters.colonnade) and the colonnade's outcome."""
    import math

    from pipeline.constants import MODEL_GRAVITY as G
    from pipeline.motion import Motion
    from pipeline.outcome.summary import RunSummary
    from pipeline.scenario import Numerics, RunParams
    from pipeline.simulate import simulate
    dt, hz = 0.005, 2.0
    t = np.arange(0.0, 1.0, dt)
    w = 2 * math.pi * hz
    a = 0.3 * G * np.sin(w * t)          # above the pre-check's 0.9 g tan(alpha), 0.17 g
    zero = 0 * t
    motion = Motion(dt, np.column_stack([a, zero, zero]),
                    np.column_stack([0.3 * G / w * (1 - np.cos(w * t)), zero, zero]),
                    np.column_stack([0.3 * G / w * (t - np.sin(w * t) / w), zero, zero]),
                    meta={"record_id": "sine"})
    run = RunParams(Column(column_file=NAME), numerics=Numerics(tail_s=0.5))
    simulate(motion, tmp_path / "run", run)
    summary = RunSummary.load(tmp_path / "run")
    assert summary.simulated
    assert summary.parameters["colonnade"]["name"] == NAME
    assert summary.colonnade.name == NAME and summary.colonnade.columns == 4
    assert len(summary.columns) == 10


def test_a_campaign_refuses_a_colonnade_in_one_line():
    from pipeline.campaign.column_file import description
    from pipeline.files import InputError
    with pytest.raises(InputError, match="a colonnade; this command takes one column"):
        description(NAME)
    assert description("doric-peristyle")["name"] == "doric-peristyle"
    assert description(NAME, colonnades=True)["name"] == NAME       # records, ensemble, ...
