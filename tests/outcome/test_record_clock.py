"""Times a user reads are on the record's clock (s after the record's first sample), not
on the processed motion's (which starts at the record time ``start_in_file_s``): the run
summary, the campaign tables and the REPORT's sweep table, without YADE (the scene's
trajectory is hand-built)."""
import dataclasses

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from pipeline import simulate as simulate_module
from pipeline.campaign.spec import RunSpec
from pipeline.campaign.tables import collect, write_tables
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.pulses import raw_pulse
from pipeline.outcome.columns import summarise
from pipeline.outcome.summary import RunSummary
from pipeline.report.campaigns import sweep_section
from pipeline.scenario import Drive, RunParams
from pipeline.simulate import drive_motion, simulate

MOTION_START_S = -30.0     # record time of the motion's first sample: 30 s of margin
DT = 0.01


def padded_motion(pulse_at_s):
    """A 60 s motion whose first sample is MOTION_START_S on the record's clock, a strong
    cosine pulse ``pulse_at_s`` after that first sample."""
    acc = raw_pulse("cosine", 6.0, 0.75, 0.0, start_s=pulse_at_s, duration=60.0, dt=DT)
    vel = cumulative_trapezoid(acc, dx=DT, axis=0, initial=0.0)
    disp = cumulative_trapezoid(vel, dx=DT, axis=0, initial=0.0)
    return Motion(DT, acc, vel, disp, meta={"record_id": "clock",
                                            "start_in_file_s": MOTION_START_S})


def test_summary_times_are_the_trajectory_times_shifted_and_nothing_else(
        make_lying_trajectory):
    """The same trajectory summarised on its own clock and with a record start of 12.5 s:
    every time moves by exactly 12.5 s, every other value stays."""
    traj = dataclasses.replace(make_lying_trajectory(70.0, n_drums=3), start_s=0.3)
    own = summarise(traj, "R", quiet_after_s=1.5).to_dict()
    shifted = summarise(traj, "R", quiet_after_s=1.5, start_in_file_s=12.5).to_dict()
    assert own["start_in_file_s"] == 0.0 and shifted["start_in_file_s"] == 12.5
    (col,), (moved,) = own["columns"], shifted["columns"]
    assert moved["impact_time_s"] == col["impact_time_s"] + 12.5
    assert col["impact_time_s"] == pytest.approx(1.0)        # the fixture falls at 1 s
    for body, other in zip(col["bodies"], moved["bodies"]):
        assert other["impact_time_s"] == body["impact_time_s"] + 12.5
        assert {k: v for k, v in other.items() if not k.endswith("_s")} == \
            {k: v for k, v in body.items() if not k.endswith("_s")}
    assert shifted["simulated_window_s"] == [0.3 + 12.5, 2.0 + 12.5]
    assert shifted["motion_end_s"] == traj.motion_end + 12.5
    assert shifted["quiet_after_s"] == 1.5 + 12.5
    assert shifted["simulated_s"] == own["simulated_s"]
    times = ("impact_time_s", "bodies", "simulated_window_s", "motion_end_s",
             "quiet_after_s", "start_in_file_s")
    assert {k: v for k, v in moved.items() if k not in times} == \
        {k: v for k, v in col.items() if k not in times}
    assert {k: v for k, v in shifted.items() if k not in times + ("columns",)} == \
        {k: v for k, v in own.items() if k not in times + ("columns",)}


def test_a_window_is_on_the_record_clock():
    """A window given on the record's clock cuts the motion where the record has those
    times; the excerpt's own record start is the window's start."""
    motion = padded_motion(40.0)
    cut = drive_motion(motion, window=(5.0, 20.0))
    assert cut.start_in_file_s == pytest.approx(5.0, abs=1e-9)
    assert cut.duration == pytest.approx(15.0)
    first = int(round((5.0 - MOTION_START_S) / DT))
    assert np.array_equal(cut.acc, motion.acc[first:first + len(cut.acc)])
    with pytest.raises(InputError, match="within the motion"):
        drive_motion(motion, window=(-31.0, 0.0))           # before its first sample


def test_a_run_on_a_padded_motion_reports_record_times_up_to_the_report(
        tmp_path, monkeypatch, make_lying_trajectory):
    """simulate() of a motion starting at -30 s on the record's clock, cut to 5-20 s (the
    record's clock), whose scene (hand-built) fell 1 s after the excerpt began: the summary,
    runs.csv, impacts.csv and the REPORT's sweep table give 6.0 s, the window's start + 1."""
    motion = padded_motion(40.0)                  # the pulse at 10 s on the record's clock
    scene = dataclasses.replace(make_lying_trajectory(70.0), motion_end=15.0)  # its clock
    monkeypatch.setattr(simulate_module, "run_yade", lambda run_dir, timeout_s=None: scene)
    motion_file = motion.save(tmp_path / "clock.npz")
    summary = simulate(motion, tmp_path / "runs" / "r1", RunParams(drive=Drive((5.0, 20.0))))
    (col,) = summary.columns
    assert col.toppled and col.impact_time_s == pytest.approx(6.0, abs=1e-9)
    assert summary.start_in_file_s == pytest.approx(5.0, abs=1e-9)
    assert summary.parameters["window"] == [5.0, 20.0]
    assert summary.motion_end_s == pytest.approx(20.0, abs=1e-9)
    # the quiet tail starts one sample after the pulse ends (10 + 1/0.75 s, record clock)
    assert summary.quiet_after_s == pytest.approx(10.0 + 1 / 0.75, abs=2 * DT)
    assert RunSummary.load(tmp_path / "runs" / "r1") == summary

    specs = [RunSpec("clock", "clock", str(motion_file), RunParams(), "r1")]
    runs, impacts = collect(specs, "slenderness", tmp_path)
    assert runs["impact_time_s"].tolist() == pytest.approx([6.0])
    assert runs["start_in_file_s"].tolist() == pytest.approx([5.0])
    assert impacts["impact_time_s"].tolist() == pytest.approx([6.0])
    write_tables(tmp_path / "slenderness", runs, impacts)
    text = sweep_section(tmp_path, "slenderness", "hd", "")
    header = next(line for line in text.splitlines() if line.startswith("| record"))
    row = next(line for line in text.splitlines() if line.startswith("| clock"))
    cells = dict(zip([c.strip() for c in header.strip("|").split("|")],
                     [c.strip() for c in row.strip("|").split("|")]))
    assert cells["impact times (s after the record's first sample)"] == "6.0-6.0"
    # a table from before its clock was stated is not passed off as the record's
    write_tables(tmp_path / "slenderness", runs.drop(columns="start_in_file_s"), impacts)
    assert "impact times (s, processed motion's clock)" in \
        sweep_section(tmp_path, "slenderness", "hd", "")


def test_a_run_that_cannot_move_ends_on_the_record_clock(tmp_path):
    """A motion too weak to move a body: no scene, the summary's motion end is the record
    time of its last sample."""
    motion = padded_motion(40.0).scale(0.01)
    summary = simulate(motion, tmp_path / "weak")
    assert not summary.simulated
    assert summary.motion_end_s == pytest.approx(MOTION_START_S + motion.duration)
    assert summary.start_in_file_s == MOTION_START_S
