"""The motion's quiet parts: where no body at rest can start to move, a run may skip them.

References: rigid-block statics (a body at rest stays at rest while the horizontal
acceleration stays below (g + a_up) tan(alpha) and mu_s (g + a_up)), hand-computed
thresholds, and the same run simulated over the whole motion.
"""
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from pipeline.constants import MODEL_GRAVITY as G
from pipeline.motion import Motion
from pipeline.outcome import Trajectory
from pipeline.scenario import Column, Contact, Numerics, RunParams
from pipeline.simulate import PRECHECK_MARGIN, quiet_window, simulate

DT = 0.005                      # s
MONOLITH = Column("monolithic")  # h/d 6: uplift at g / 6
THRESHOLD = PRECHECK_MARGIN * G / 6.0   # m/s^2, the pre-check's limit for the monolith


def motion_of(acc, dt=DT):
    """Motion from an (n, 3) acceleration (m/s^2), integrated by the trapezoid rule."""
    vel = cumulative_trapezoid(acc, dx=dt, axis=0, initial=0)
    disp = cumulative_trapezoid(vel, dx=dt, axis=0, initial=0)
    return Motion(dt, acc, vel, disp, meta={"record_id": "quiet-test"})


def sine(seconds, amplitude, hz, axis):
    """(n, 3) acceleration: a sine of ``amplitude`` (m/s^2) along axis 0 (E), 1 (N) or 2."""
    t = np.arange(int(round(seconds / DT))) * DT
    acc = np.zeros((len(t), 3))
    acc[:, axis] = amplitude * np.sin(2 * math.pi * hz * t)
    return acc


def one_column(uplift_ratio):
    return [{"uplift_ratio": uplift_ratio}]


# ---------------------------------------------------------------- window, no YADE
def test_window_starts_lead_before_the_first_movable_sample_and_ends_after_the_last():
    acc = np.zeros((1000, 3))                       # 10 s at 0.01 s
    acc[300, 0] = 2.0                               # above 0.9 g / 6 = 1.4715 m/s^2
    acc[500, 1] = -1.6
    acc[700, 0] = 1.4                               # below: quiet
    start, quiet_after = quiet_window(motion_of(acc, 0.01), one_column(1 / 6), Contact(), 1.0)
    assert start == pytest.approx(2.0)              # 3.00 s - 1 s
    assert quiet_after == pytest.approx(5.01)       # one sample after 5.00 s


def test_window_lead_stops_at_the_motion_start_and_sliding_limit_counts():
    acc = np.zeros((1000, 3))
    acc[50, 0] = 0.9 * 0.7 * G                      # the sliding limit of mu_s 0.7 ...
    window = quiet_window(motion_of(acc, 0.01), one_column(2.0), Contact(), 1.0)
    assert window == pytest.approx((0.0, 0.51))     # ... below the uplift limit 2 g
    acc[50, 0] = 0.99 * 0.9 * 0.7 * G
    assert quiet_window(motion_of(acc, 0.01), one_column(2.0), Contact(), 1.0) is None


def test_vertical_acceleration_scales_the_threshold():
    acc = np.zeros((1000, 3))
    acc[400] = (0.0, 1.0, -0.5 * G)                 # limit halves: 0.9 g/12 = 0.74 m/s^2
    window = quiet_window(motion_of(acc, 0.01), one_column(1 / 6), Contact(), 0.5)
    assert window == pytest.approx((3.5, 4.01))
    acc[400] = (0.0, 0.0, -1.01 * G)                # free fall: anything can move
    window = quiet_window(motion_of(acc, 0.01), one_column(1 / 6), Contact(), 0.5)
    assert window == pytest.approx((3.5, 4.01))


def test_turning_the_motion_keeps_the_window():
    rng = np.random.default_rng(5)
    motion = motion_of(rng.normal(0.0, 0.5, (2000, 3)))
    turned = motion.rotate(73.0)
    assert quiet_window(turned, one_column(1 / 6), Contact(), 1.0) == \
        pytest.approx(quiet_window(motion, one_column(1 / 6), Contact(), 1.0))


# ---------------------------------------------------------------- YADE
def run(tmp_path, name, motion, quiet, **numerics):
    return simulate(motion, tmp_path / name, RunParams(
        column=MONOLITH, numerics=Numerics(quiet_motion=quiet, **numerics)))


@pytest.mark.yade
def test_skipped_lead_in_gives_the_same_fall_on_the_motion_clock(tmp_path):
    """6 s of shaking at half the threshold, then a one-sine pulse that topples the
    monolith: skipping the lead-in changes neither the fall nor its time."""
    amplitude = 6.0
    acc = np.vstack([sine(6.0, 0.5 * THRESHOLD, 1.5, 0), sine(1.0, amplitude, 1.0, 1),
                     np.zeros((int(8 / DT), 3))])
    motion = motion_of(acc)
    skip, full = run(tmp_path, "skip", motion, "skip"), run(tmp_path, "full", motion, "simulate")
    (s,), (f,) = skip.columns, full.columns
    assert s.toppled and f.toppled
    assert abs((s.downfall_azimuth_deg - f.downfall_azimuth_deg + 180) % 360 - 180) < 2.0
    assert s.impact_time_s == pytest.approx(f.impact_time_s, abs=0.05)
    # the pulse first reaches the threshold at 6 s + asin(threshold / A) / (2 pi) x 1 s
    first = 6.0 + math.asin(THRESHOLD / amplitude) / (2 * math.pi)
    assert skip.simulated_window_s[0] == pytest.approx(first - 1.0, abs=DT)
    assert full.simulated_window_s[0] == 0.0
    assert skip.simulated_s == pytest.approx(full.simulated_s - (first - 1.0), abs=0.1)
    traj = Trajectory.load(tmp_path / "skip" / "trajectory.npz")
    assert traj.t[0] >= skip.simulated_window_s[0]
    # the pedestal displacement is the motion's, on the motion's clock
    expected = np.column_stack([np.interp(traj.t, motion.dt * np.arange(motion.npts),
                                          motion.disp[:, j]) for j in range(3)])
    assert np.abs(traj.pedestal_disp - expected).max() < 1e-9


@pytest.mark.yade
def test_quiet_tail_ends_the_run_once_the_column_rests_seated(tmp_path):
    """A 40 ms blip just above the threshold, then 20 s of shaking at 0.3 of it: the
    skipping run stops within 2 s after the blip, the full one runs to the
    motion's end; neither column moves."""
    blip = sine(0.04, 1.2 * THRESHOLD / PRECHECK_MARGIN, 12.5, 0)
    acc = np.vstack([np.zeros((int(2 / DT), 3)), blip, sine(20.0, 0.3 * THRESHOLD, 2.0, 1)])
    motion = motion_of(acc)
    skip, full = run(tmp_path, "skip", motion, "skip"), run(tmp_path, "full", motion, "simulate")
    assert skip.quiet_after_s == pytest.approx(2.04, abs=2 * DT)
    assert skip.simulated_window_s[1] < skip.quiet_after_s + 2.0
    assert full.simulated_window_s[1] >= full.motion_end_s
    for summary in (skip, full):
        (c,) = summary.columns
        assert not c.toppled and c.max_tilt_deg < 0.05


@pytest.mark.yade
def test_a_rocking_column_is_not_stopped_by_the_quiet_tail(tmp_path):
    """Rocking set off by a pulse, kept up by sub-threshold shaking: the run goes on to
    the motion's end exactly as the full one."""
    acc = np.vstack([sine(1.0, 1.9, 1.0, 1), sine(12.0, 0.5 * THRESHOLD, 2.0, 1)])
    motion = motion_of(acc)
    skip, full = run(tmp_path, "skip", motion, "skip"), run(tmp_path, "full", motion, "simulate")
    assert skip.quiet_after_s < 1.0 < skip.columns[0].max_tilt_deg
    assert skip.simulated_window_s[1] >= skip.motion_end_s
    assert skip.simulated_window_s[1] == pytest.approx(full.simulated_window_s[1], abs=0.2)


def test_ready_made_motion_is_cut_at_its_signal_end_like_a_record(tmp_path):
    """A 2 s burst at 5 s in 30 s of quiet: the window ends 5 s (SIGNAL_END_MARGIN_S)
    after the burst's 99.5 % Arias point, whatever quiet follows; records are cut by
    their processing instead."""
    from pipeline.campaign.definitions import signal_window
    burst = sine(2.0, 3.0, 2.0, 0) * np.hanning(400)[:, None]
    ends = []
    for quiet_after in (23.0, 43.0):
        acc = np.vstack([np.zeros((1000, 3)), burst, np.zeros((int(quiet_after / DT), 3))])
        path = tmp_path / f"syn_{quiet_after:g}.npz"
        motion_of(acc).save(path)
        ends.append(signal_window(path))
    assert ends[0] == ends[1]
    assert ends[0][0] == 0.0 and 11.5 < ends[0][1] < 12.0       # burst ends at 7 s
    assert signal_window("GM20") is None


def test_a_run_not_simulated_leaves_no_trajectory_of_an_earlier_run(tmp_path):
    """A still motion is not simulated: the directory an earlier run left holds this
    run's summary, not the earlier trajectory and YADE log beside it."""
    for name in ("trajectory.npz", "yade.log"):
        (tmp_path / name).write_text("an earlier run's")
    summary = simulate(motion_of(np.zeros((200, 3))), tmp_path, RunParams(column=MONOLITH))
    assert not summary.simulated
    assert (tmp_path / "summary.json").exists()
    assert not (tmp_path / "trajectory.npz").exists() and not (tmp_path / "yade.log").exists()
