"""Processing must not depend on how much quiet time surrounds the strong motion."""
import math

import numpy as np
import pytest

from pipeline.motion import Motion
from pipeline.motion.measures import record_parameters
from pipeline.records import build_motion, processing, read_east_north_up, resolve
from tests.records.test_records import wavelet

MEASURES = ("pga_h", "pgv_h", "pgd_h", "arias_h")
AZIMUTHS = ("az_max_acc_deg", "az_max_vel_deg", "az_max_disp_deg")


def raw_record(record_id):
    """(enz acceleration m/s^2, dt) of a shipped record, as read from its file."""
    enz, dt, _, _ = read_east_north_up(resolve(record_id))
    return enz, dt


def measures(enz, dt):
    acc, vel, disp, steps = processing.process(enz, dt)
    return record_parameters(Motion(dt, acc, vel, disp)), steps


def variants(enz, dt):
    rng = np.random.default_rng(7)
    quiet = np.zeros((int(600 / dt), 3))
    noise = 1e-3 * np.abs(enz).max() * rng.standard_normal(quiet.shape)   # -60 dB
    lead = np.zeros((int(30 / dt), 3))
    return {"10 min of zeros appended": np.vstack([enz, quiet]),
            "10 min of low-level noise appended": np.vstack([enz, noise]),
            "30 s of zeros prepended": np.vstack([lead, enz])}


@pytest.mark.parametrize("record_id", ["NF04", "RC-CLC"])
def test_quiet_time_around_a_record_changes_nothing(record_id):
    enz, dt = raw_record(record_id)
    base, _ = measures(enz, dt)
    for name, padded in variants(enz, dt).items():
        other, steps = measures(padded, dt)
        for key in MEASURES:
            assert other[key] == pytest.approx(base[key], rel=0.01), (name, key)
        for key in AZIMUTHS:
            gap = abs((other[key] - base[key] + 180) % 360 - 180)
            assert gap < 0.01 * 360 or math.isclose(gap, 180, abs_tol=3.6), (name, key)
        taper = next(s for s in steps if s["step"] == "taper")
        assert taper["taper_s"] <= 2.0


def test_pulse_five_seconds_into_a_long_file_keeps_its_amplitude():
    """d(t) = D exp(-((t-t0)/w)^2) sin(2 pi f t) at t0 = 5 s in a 900 s file: the
    processed PGV and PGD equal the analytic ones (a 5 % taper of 900 s, 45 s, would
    have erased it)."""
    dt, t0, w = 0.01, 5.0, 1.0
    acc, vel, disp = wavelet(np.arange(0, 900.0, dt), 0.2, t0, w, 1.0)
    enz = np.column_stack([acc, np.zeros_like(acc), 0.3 * acc])
    params, steps = measures(enz, dt)
    assert params["pga_h"] == pytest.approx(np.abs(acc).max(), rel=0.01)
    assert params["pgv_h"] == pytest.approx(np.abs(vel).max(), rel=0.02)
    assert params["pgd_h"] == pytest.approx(np.abs(disp).max(), rel=0.02)
    trim = next(s for s in steps if s["step"] == "trim_to_signal")
    transient = processing.filter_transient_s(processing.BAND["freqmin_hz"],
                                              processing.BAND["corners"])
    assert trim["window_s"][1] < t0 + 3 * w + transient + 1.0   # not the 900 s file


def test_provenance_records_the_taper_length_in_seconds(tmp_path):
    motion = build_motion(resolve("NF04"), key="k")
    steps = {s["step"]: s for s in motion.meta["processing"]["steps"]}
    assert 0 < steps["taper"]["taper_s"] <= 2.0
    assert steps["bandpass"]["freqmin_hz"] >= 0.1
    assert motion.meta["start_in_file_s"] == steps["trim_to_signal"]["window_s"][0]


@pytest.mark.yade
def test_same_column_outcome_with_ten_minutes_of_noise_appended(tmp_path):
    from pipeline.scenario import Column, RunParams
    from pipeline.simulate import simulate
    enz, dt = raw_record("NF04")
    outcomes = []
    for name, data in (("base", enz), ("noise", variants(enz, dt)["10 min of low-level noise appended"])):
        acc, vel, disp, _ = processing.process(data, dt)
        summary = simulate(Motion(dt, acc, vel, disp, meta={"record_id": name}), tmp_path / name,
                           RunParams(column=Column("monolithic")))
        outcomes.append(summary.columns[0])
    base, noisy = outcomes
    assert base.toppled == noisy.toppled
    if base.toppled:
        gap = abs((base.downfall_azimuth_deg - noisy.downfall_azimuth_deg + 180) % 360 - 180)
        assert gap < 2.0
        assert noisy.impact_time_s == pytest.approx(base.impact_time_s, abs=0.05)
