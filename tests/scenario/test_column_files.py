"""Column files through YADE: the paper's columns unchanged, Housner's block through the
new path, the uplift threshold of a stack with a wide capital, real columns at rest.

Each test runs YADE for a few simulated seconds."""
import json
import math

import numpy as np
import pytest

from pipeline import cli, paper
from pipeline.rocking.response import housner_free_rocking
from pipeline.constants import MODEL_GRAVITY as G
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse
from pipeline.outcome.columns import body_axes, column_outcomes, rotation_from_start_deg
from pipeline.scenario import (
    Column,
    ColumnGeometry,
    ColumnSpec,
    Contact,
    Numerics,
    run_yade,
    scene_params,
    write_scenario,
)
from pipeline.verification.checks import MARBLE_BLOCK, MARBLE_CONTACT, impacts_and_peaks

pytestmark = pytest.mark.yade

def run(tmp_path, name, specs, motion=None, **options):
    duration = 0.0 if motion is None else motion.duration
    params = scene_params(columns=specs, motion_duration=duration, **options)
    write_scenario(tmp_path / name, params, motion)
    return params, run_yade(tmp_path / name)


@pytest.mark.libm
def test_paper_columns_from_files_give_the_outcomes_of_before(tmp_path):
    """The paper's columns described in files and built in give the same scene and, run
    side by side in this test under one_sine_pulse(0, 8), the same trajectory to the last
    bit (both paths run on this machine's libm; no number recorded elsewhere)."""
    files = [ColumnSpec("drums", "drums", -1.5, 0.0, ColumnGeometry.load("hinzen2009-drums")),
             ColumnSpec("monolithic", "monolithic", 1.5, 0.0,
                        ColumnGeometry.load("hinzen2009-monolith"))]
    pulse = one_sine_pulse(0, 8)
    params, traj = run(tmp_path, "files", files, pulse)
    default, built_in = run(tmp_path, "built-in", Column("both").specs(), pulse)
    for ours, theirs in zip(params.columns, default.columns):
        assert ours["bodies"] == theirs["bodies"]
    assert np.array_equal(traj.quat, built_in.quat)
    assert np.array_equal(traj.pos, built_in.pos)
    for ours, theirs in zip(column_outcomes(traj), column_outcomes(built_in)):
        assert ours == theirs
        assert ours["toppled"]                      # a strong pulse: both columns fall
        gap = (ours["downfall_azimuth_deg"] - 180.0 + 180.0) % 360.0 - 180.0
        assert abs(gap) < 5.0                       # opposite the pulse's first push (0 deg)


def test_a_box_from_a_file_rocks_as_housner_says(tmp_path):
    """Free rocking of the marble block described in a file, released from 0.5 alpha on
    its East edge, against Housner's equation (critically damped contacts)."""
    h, w, d = MARBLE_BLOCK["height"], MARBLE_BLOCK["width"], MARBLE_BLOCK["depth"]
    alpha = math.atan(w / h)
    geometry = ColumnGeometry.from_dict({"name": "marble block", "density": 2960.0, "blocks": [
        {"shape": "box", "height": h, "width": w, "depth": d, "tilt_deg":
         math.degrees(0.5 * alpha), "tilt_azimuth_deg": 90.0, "tilt_mode": "edge"}]})
    ref = housner_free_rocking(h, w, 0.5 * alpha, n_impacts=4)
    contact = {k: v for k, v in MARBLE_CONTACT.items() if k != "rim_sphere_radius"}
    _, traj = run(tmp_path, "box", [ColumnSpec("block", "block", 0.0, 0.0, geometry)],
                  contact=Contact(**{**contact, "damping": 1.0}),
                  numerics=Numerics(rim_sphere_radius=MARBLE_CONTACT["rim_sphere_radius"],
                                    record_hz=1000.0),
                  t_max=float(ref["peak_times"][4]) + 0.05)
    axis = body_axes(traj.quat)[:, 0]
    theta = np.arctan2(axis[:, 0], axis[:, 2])
    times, peaks = impacts_and_peaks(traj.t, theta)
    assert times[:4] == pytest.approx(ref["impact_times"][:4], rel=0.02)
    assert peaks[1:5] / alpha == pytest.approx(ref["peak_ratio"][1:5], rel=0.02)


def test_wide_capital_stack_rocks_at_its_statics_threshold_and_not_below(tmp_path):
    """A shaft with a heavy capital twice its width on top (two bodies): rigid-body
    statics puts the uplift at g x (base radius) / (height of the combined centre of
    mass), below g d/h; a 2 Hz sine at 0.8 of it must not lift the stack, 1.5 x must."""
    geometry = ColumnGeometry.from_dict({"name": "capital stack", "density": 2700.0, "blocks": [
        {"shape": "frustum", "height": 3.0, "bottom_diameter": 0.5, "top_diameter": 0.45},
        {"shape": "box", "height": 0.35, "width": 0.9, "depth": 0.9, "name": "capital"}]})
    ratio = geometry.uplift_ratio()
    assert ratio < 0.9 * 0.5 / 3.35         # the capital's weight, high up, lowers it
    tilts = {}
    for factor in (0.8, 1.5):
        t = np.arange(0, 3.0, 0.005)
        a = factor * ratio * G * np.sin(2 * math.pi * 2.0 * t)
        v = np.cumsum(a) * 0.005
        dsp = -a / (2 * math.pi * 2.0) ** 2
        z = 0 * a
        motion = Motion(0.005, np.column_stack([a, z, z]), np.column_stack([v, z, z]),
                        np.column_stack([dsp, z, z]))
        _, traj = run(tmp_path, f"f{factor}", Column("drums", column_file=geometry.to_dict())
                      .specs(), motion)
        (col,) = column_outcomes(traj)
        tilts[factor] = col["max_tilt_deg"]
        assert not col["toppled"]
    print(f"uplift ratio {ratio:.4f} (d/h {0.5 / 3.35:.4f}); max tilt {tilts} deg")
    assert tilts[0.8] < 0.05              # elastic contact compression only
    assert tilts[1.5] > 0.5


@pytest.mark.libm
@pytest.mark.parametrize("name", ["doric-peristyle", "roman-granite"])
def test_real_columns_stand_still_on_a_still_pedestal(tmp_path, name):
    """Out of plumb on wedge joints, capitals and bases of joined blocks, corner-supported
    plinths: every body stays where it was put."""
    _, traj = run(tmp_path, name, Column("both", column_file=name).specs(), t_max=0.5)
    assert rotation_from_start_deg(traj) < 0.01
    drift = np.hypot(*(traj.pos[-1, :, :2] - traj.pos[0, :, :2]).T)
    assert drift.max() < 1e-3
    for col in column_outcomes(traj):
        assert not col["toppled"]


def test_run_with_a_column_file(tmp_path, capsys):
    record = one_sine_pulse(30.0, 6.0, duration=3.0).save(tmp_path / "pulse.npz")
    out = tmp_path / "run"
    assert cli.main(["run", "--record", str(record), "--column-file", "hinzen2009-drums",
                     "--column", "both", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "first to strike" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["parameters"]["column_file"] == "hinzen2009-drums"
    assert summary["parameters"]["geometry"]["name"] == "hinzen2009-drums"
    cols = {c["column"]: c for c in summary["columns"]}
    assert cols["drums"]["position_m"] == [-paper.TWIN_OFFSET_M, 0.0]
    assert cols["monolithic"]["position_m"] == [paper.TWIN_OFFSET_M, 0.0]
    assert len(cols["drums"]["bodies"]) == 7 and len(cols["monolithic"]["bodies"]) == 1


@pytest.mark.parametrize("args, words", [
    (["--column-file", "no-such-column"], "no such file or shipped example"),
    (["--column-file", "doric-peristyle", "--hd", "7"], "drop --hd"),
])
def test_run_column_file_errors_are_one_line(tmp_path, capsys, args, words):
    record = one_sine_pulse(30.0, 6.0, duration=2.0).save(tmp_path / "pulse.npz")
    code = cli.main(["run", "--record", str(record), *args, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and words in err
    assert not (tmp_path / "o").exists()


def test_columns_campaign_compares_descriptions_on_the_same_record(tmp_path, capsys):
    import pandas as pd
    record = one_sine_pulse(30.0, 6.0, duration=3.0).save(tmp_path / "pulse.npz")
    mine = tmp_path / "capital.json"
    mine.write_text(json.dumps({"name": "capital stack", "density": 2700.0, "blocks": [
        {"shape": "frustum", "height": 3.0, "bottom_diameter": 0.5, "top_diameter": 0.45},
        {"shape": "box", "height": 0.35, "width": 0.9, "depth": 0.9, "name": "capital"}]}))
    out = tmp_path / "campaign"
    assert cli.main(["campaign", "columns", "--records", str(record), "--column-file",
                     f"hinzen2009-drums,{mine}", "--out", str(out), "--jobs", "1",
                     "--animations", "0"]) == 0
    table = pd.read_csv(out / "columns.csv")
    assert sorted(zip(table["description"], table["column"])) == [
        ("capital stack", "drums"), ("capital stack", "monolithic"),
        ("hinzen2009-drums", "drums"), ("hinzen2009-drums", "monolithic")]
    assert set(table["record_id"]) == {"pulse"}
    paper_drums = table[(table["description"] == "hinzen2009-drums")
                        & (table["column"] == "drums")].iloc[0]
    assert paper_drums["toppled"] and paper_drums["first_to_strike"].startswith("body")
    assert paper_drums["kn"] == paper.COLUMN_KN_N_M and paper_drums["bodies"] == 7
    stack = table[table["description"] == "capital stack"]
    assert (stack["uplift_ratio"] < 0.9 * 0.5 / 3.35).all()
    for _, row in table[table["toppled"]].iterrows():
        assert isinstance(row["first_to_strike"], str)
    runs = pd.read_csv(out / "runs.csv")
    assert set(runs["description"]) == {"hinzen2009-drums", "capital stack"}
    assert "first_to_strike" in (out / "columns.md").read_text()
