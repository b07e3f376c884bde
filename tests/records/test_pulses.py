"""Processing keeps what topples a column: near-fault pulses keep their band-passed
acceleration and velocity, and rigid-block theory gives the same outcome on the
processed motion as on the pulse band-passed alone.

The reference is independent of the processing code: a zero-phase 4-pole Butterworth
0.1-25 Hz band-pass (scipy's sosfiltfilt) of the pulse padded with 5 minutes of zeros
each side, integrated by the trapezoid rule."""
import json
import math

import numpy as np
import pytest
from obspy import Stream, Trace
from scipy.integrate import cumulative_trapezoid
from scipy.signal import butter, sosfiltfilt

from pipeline import cli, records
from pipeline.rocking.sampled import rocking_response_sampled
from pipeline.motion import Motion
from pipeline.motion.pulses import raw_pulse
from pipeline.records import processing

DT = 0.01
MONOLITH = {"height": 3.5, "width": 0.583}        # the paper's column, m (alpha 9.46 deg)


def band_passed_alone(enz, dt=DT, band=(0.1, 25.0), pad_s=300.0):
    """(acc, vel) of ``enz`` band-passed alone: the independent reference."""
    pad = int(pad_s / dt)
    sos = butter(4, band, btype="bandpass", fs=1.0 / dt, output="sos")
    acc = sosfiltfilt(sos, np.pad(enz, ((pad, pad), (0, 0))), axis=0)
    return acc, cumulative_trapezoid(acc, dx=dt, axis=0, initial=0.0)


def block_outcomes(*accelerations):
    """pipeline.rocking's (overturned, direction) of the paper's monolith as a rigid
    block under each horizontal acceleration (m/s^2, samples DT apart)."""
    result = []
    for acc in accelerations:
        r = rocking_response_sampled(MONOLITH["height"], MONOLITH["width"], acc, DT)
        result.append((bool(r["overturned"][0]), int(r["overturn_direction"][0])))
    return result


def horizontal_peak(x):
    return float(np.hypot(x[:, 0], x[:, 1]).max())


def along(enz, azimuth_deg):
    """Component of the horizontal motion along ``azimuth_deg`` (positive that way)."""
    a = math.radians(azimuth_deg)
    return enz[:, 0] * math.sin(a) + enz[:, 1] * math.cos(a)


CASES = [(kind, f, place, length) for kind in ("sine", "cosine") for f in (0.5, 1.0, 3.0)
         for place in ("early", "middle", "late") for length in (20.0, 900.0)]


@pytest.mark.parametrize("kind, frequency, place, length", CASES)
def test_pulse_keeps_its_band_passed_pga_and_pgv(kind, frequency, place, length):
    start = {"early": 2.0, "middle": length / 2, "late": length - 1.0 / frequency - 2.0}[place]
    enz = raw_pulse(kind, 6.0, frequency, 117.0, start, length, DT)
    acc, vel, _, _ = processing.process(enz, DT)
    ref_acc, ref_vel = band_passed_alone(enz)
    assert horizontal_peak(acc) == pytest.approx(horizontal_peak(ref_acc), rel=0.03)
    assert horizontal_peak(vel) == pytest.approx(horizontal_peak(ref_vel), rel=0.05)


def test_the_issue_pulse_keeps_its_velocity_and_overturns_the_block_as_band_passed():
    """6 m/s^2 at 0.75 Hz along 117 deg, 8 s into a 30 s file: the band-passed pulse has
    PGA 5.98 m/s^2, PGV 2.20 m/s (the band takes 14 % of the fling's 2.55 m/s) and
    overturns the paper's monolith as a rigid block; so must the processed motion."""
    enz = raw_pulse("sine", 6.0, 0.75, 117.0, 8.0, 30.0, DT)
    acc, vel, disp, _ = processing.process(enz, DT)
    ref_acc, ref_vel = band_passed_alone(enz)
    assert horizontal_peak(ref_vel) == pytest.approx(2.20, abs=0.01)
    assert horizontal_peak(vel) == pytest.approx(2.20, rel=0.05)
    assert np.abs(disp[-1]).max() < 0.01                       # ends at rest
    processed, reference = block_outcomes(along(acc, 117.0), along(ref_acc, 117.0))
    assert processed == reference and processed[0]


@pytest.mark.parametrize("amplitude, overturns", [(1.5, False), (4.0, True)])
def test_rigid_block_outcome_on_processed_equals_band_passed(amplitude, overturns):
    """A one-cosine pulse of 1 Hz (no permanent displacement): below the block's
    overturning amplitude it stands on both motions, above it overturns on both."""
    enz = raw_pulse("cosine", amplitude, 1.0, 30.0, 60.0, 180.0, DT)
    acc, _, _, _ = processing.process(enz, DT)
    ref_acc, _ = band_passed_alone(enz)
    processed, reference = block_outcomes(along(acc, 30.0), along(ref_acc, 30.0))
    assert processed == reference and processed[0] is overturns


def write_pulse_mseed(path, enz):
    Stream([Trace(enz[:, i].copy(), header={"station": "P", "channel": f"HN{c}",
                                            "sampling_rate": 1.0 / DT})
            for i, c in enumerate("ENZ")]).write(str(path), format="MSEED")
    return path


def test_a_pulse_file_read_and_processed_keeps_its_velocity(tmp_path):
    enz = raw_pulse("sine", 6.0, 0.75, 117.0, 8.0, 30.0, DT)
    path = write_pulse_mseed(tmp_path / "pulse.mseed", enz)
    motion, _ = records.processed_motion(path, cache_dir=None)
    assert motion.meta["processing"]["mode"] == "default"
    assert horizontal_peak(motion.vel) == pytest.approx(2.20, rel=0.05)


def test_processing_none_runs_the_acceleration_as_given(tmp_path):
    enz = raw_pulse("sine", 6.0, 0.75, 117.0, 8.0, 30.0, DT)
    path = write_pulse_mseed(tmp_path / "pulse.mseed", enz)
    motion, _ = records.processed_motion(path, cache_dir=None, mode="none")
    assert motion.meta["processing"]["mode"] == "none"
    assert np.allclose(motion.acc, enz, atol=1e-6)             # MiniSEED float32... as given
    assert horizontal_peak(motion.vel) == pytest.approx(2.546, rel=0.01)   # 2 A / (2 pi f)
    assert motion.processing_mode == "none"
    assert Motion(DT, enz, enz, enz, meta={}).processing_mode == "none"


def test_processing_option_is_checked(tmp_path, capsys):
    path = write_pulse_mseed(tmp_path / "pulse.mseed", raw_pulse())
    with pytest.raises(SystemExit):
        cli.main(["run", "--record", str(path), "--processing", "raw", "--out",
                  str(tmp_path / "o")])
    assert not (tmp_path / "o").exists()


@pytest.mark.yade
def test_run_on_a_processed_pulse_stops_after_its_signal_and_says_how_it_was_processed(
        tmp_path, capsys):
    """A pulse that rocks the monolith without toppling it: the run stops once the column
    rests after the signal's end, not after the filter's minute-long transient that the
    processed motion carries; summary.json records the processing mode."""
    enz = raw_pulse("cosine", 2.5, 1.0, 30.0, 8.0, 30.0, DT)
    path = write_pulse_mseed(tmp_path / "rock.mseed", enz)
    for mode in ("default", "none"):
        out = tmp_path / mode
        assert cli.main(["run", "--record", str(path), "--column", "monolithic",
                         "--processing", mode, "--out", str(out)]) == 0
        summary = json.loads((out / "summary.json").read_text())
        assert summary["parameters"]["processing"] == mode
        (column,) = summary["columns"]
        assert not column["toppled"] and column["max_tilt_deg"] > 0.1      # it rocked
        if mode == "default":
            # the motion lasts the signal + the filter transient: over 100 s
            assert summary["motion_end_s"] - summary["start_in_file_s"] > 100.0
            assert summary["simulated_window_s"][1] < summary["motion_end_s"] - 40.0
