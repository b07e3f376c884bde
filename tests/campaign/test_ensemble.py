"""Ensembles: reproducible sampling, and probabilities on motions with known outcomes."""
import json

import numpy as np
import pytest

from pipeline import cli
from pipeline.campaign.ensemble import ENSEMBLE_RANGES, parse_vary, sample_members
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse


def test_same_seed_same_members_and_ranges_respected():
    a, b = sample_members(32, seed=7), sample_members(32, seed=7)
    assert a == b
    assert a != sample_members(32, seed=8)
    mu = np.array([m["mu_s"] for m in a])
    assert (mu >= 0.55).all() and (mu <= 0.85).all()
    # Latin hypercube: one member in each of the 32 strata of every range
    strata = np.floor((mu - 0.55) / 0.30 * 32).clip(0, 31)
    assert len(set(strata)) == 32
    assert all(m["mu_k"] == pytest.approx(0.84 * m["mu_s"], abs=1e-6) for m in a)
    phases = [m["rim_phase_deg"] for m in a]
    assert 0 <= min(phases) and max(phases) <= ENSEMBLE_RANGES["rim_phase_deg"][1]


def test_vary_parses_and_refuses_nonsense():
    assert parse_vary(["mu_s=0.4,0.6"]) == {"mu_s": (0.4, 0.6, "uniform")}
    for bad in (["mu_s=0.6"], ["bogus=1,2"], ["kn_factor=0,2"], ["damping=0.5,0.1"]):
        with pytest.raises(InputError):
            parse_vary(bad)


def _motion(path, azimuth, amplitude):
    m = one_sine_pulse(azimuth, amplitude, duration=6.0)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": path.stem,
                                            "back_azimuth_deg": 120.0}).save(path)
    return path


@pytest.mark.yade
def test_strong_pulse_topples_every_member_away_from_the_push(tmp_path, capsys):
    """A one-sine pulse along 30 deg well above threshold throws both columns without an
    impact toward 210 deg (the ground moves toward 30 deg first)."""
    record = _motion(tmp_path / "pulse.npz", 30.0, 8.0)
    out = tmp_path / "ens"
    assert cli.main(["campaign", "ensemble", "--record", str(record), "--members", "4",
                     "--out", str(out), "--jobs", "2", "--animations", "0"]) == 0
    summary = json.loads((out / "ensemble_summary.json").read_text())
    assert summary["members"] == 4 and summary["back_azimuth_deg"] == 120.0
    for col in summary["columns"]:
        assert col["p_toppled"] == 1.0 and col["p_toppled_ci95"][1] == 1.0
        gap = abs((col["mean_downfall_azimuth_deg"] - 210.0 + 180) % 360 - 180)
        assert gap < 15.0, col
        assert col["nominal_toppled"] is True
        # relative to the back azimuth 120: falls at ~210 are transverse
        assert col["fraction_transverse"] == 1.0
    assert (out / "rose.png").exists() and (out / "members.csv").exists()


@pytest.mark.yade
def test_sub_threshold_motion_never_topples(tmp_path):
    record = _motion(tmp_path / "weak.npz", 0.0, 0.3)
    out = tmp_path / "ens"
    assert cli.main(["campaign", "ensemble", "--record", str(record), "--members", "3",
                     "--out", str(out), "--animations", "0"]) == 0
    summary = json.loads((out / "ensemble_summary.json").read_text())
    for col in summary["columns"]:
        assert col["p_toppled"] == 0.0 and col["mean_downfall_azimuth_deg"] is None
        assert col["p_toppled_ci95"][0] == 0.0
