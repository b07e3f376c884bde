"""The rocking frame in YADE: the frame colonnade holds the beam mass asked for, and the
frame lifts at g tan(alpha) whatever its beam weighs (Makris & Vassiliou 2013: uplift
starts at the single column's acceleration).  The smallest overturning amplitude
against the rigid frame is the long check (`verify frame`)."""
import math

import numpy as np
import pytest

from pipeline.constants import MODEL_GRAVITY as G
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.verification.frame import frame_colonnade, run_frame

H, B, D = 3.0, 1.0, 1.0          # the frame's columns (m): tan(alpha) = 1/3


@pytest.mark.parametrize("n, gamma", [(2, 0.25), (4, 4.0)])
def test_the_frame_holds_the_beam_mass_asked_for(n, gamma):
    colonnade = frame_colonnade(n, gamma)
    (beam,) = colonnade.epistyles
    column_mass = colonnade.columns[0].mass
    assert column_mass == pytest.approx(H * B * D * colonnade.columns[0].column.density)
    assert beam.mass == pytest.approx(gamma * n * column_mass, rel=1e-12)
    assert colonnade.beam_mass_ratio == pytest.approx(gamma, rel=1e-12)
    assert beam.on == tuple(c.name for c in colonnade.columns)


def test_a_frame_of_one_column_is_refused():
    with pytest.raises(InputError, match="2 columns or more"):
        frame_colonnade(1, 1.0)


def sine(amplitude, hz=2.0, seconds=1.5, dt=0.002):
    """A horizontal sine along East (m/s^2) and the motion that integrates it."""
    t = np.arange(0.0, seconds, dt)
    w = 2 * math.pi * hz
    a, v = amplitude * np.sin(w * t), amplitude / w * (1 - np.cos(w * t))
    d = amplitude / w * (t - np.sin(w * t) / w)
    zero = 0 * t
    return Motion(dt, np.column_stack([a, zero, zero]), np.column_stack([v, zero, zero]),
                  np.column_stack([d, zero, zero]), meta={"record_id": "sine"})


@pytest.mark.yade
@pytest.mark.libm
@pytest.mark.parametrize("gamma", [0.25, 4.0])
def test_the_frame_lifts_at_g_tan_alpha_whatever_its_beam(tmp_path, gamma):
    colonnade = frame_colonnade(2, gamma)
    tilts = []
    for factor in (0.8, 1.5):
        motion = sine(factor * G * B / H)
        outcomes = run_frame(tmp_path / f"f{factor}", colonnade, motion, motion.duration)
        tilts.append(max(o["max_tilt_deg"] for o in outcomes if o["column"] != "B"))
    assert tilts[0] < 0.05           # the contacts' elastic share only
    assert tilts[1] > 0.5


def test_the_campaign_runs_the_frames_and_reports_them():
    from pipeline import verification
    checks = [c for c in verification.campaign_checks("code") if c.kind == "frame"]
    assert sorted((c["n_columns"], c["gamma"]) for c in checks) == sorted(
        (n, g) for n in verification.FRAME_COLUMNS for g in verification.FRAME_GAMMAS)
    result = {"test": "frame", "passed": True, "n_columns": 2, "gamma": 1.0, "period_s": 1.0,
              "integration": {"threshold_g": 0.9}, "single_column_threshold_g": 0.6,
              "yade": {"threshold_g": 0.91}, "yade_rel_error": 0.01 / 0.9}
    out = verification.summarise_campaign([(checks[0], verification.CheckResult(result))])
    (row,) = out["frame"]["frames"]
    assert row["over_single"] == pytest.approx(1.5)
    assert "1/1 frames" in out["lines"][-1] and "1.50 to 1.50" in out["lines"][-1]
