"""Ensembles: reproducible sampling, and probabilities on motions with known outcomes."""
import json

import numpy as np
import pytest

from pipeline import cli
from pipeline.campaign.ensemble_members import ENSEMBLE_RANGES, parse_vary, sample_members
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
    assert all(m["mu_k"] == pytest.approx(0.6 / 0.7 * m["mu_s"], abs=5e-5) for m in a)
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
                     "--max-members", "4", "--out", str(out), "--jobs", "2",
                     "--animations", "0"]) == 0
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
def test_sub_threshold_motion_never_topples_and_the_ensemble_grows_to_its_precision(tmp_path):
    """Below the threshold no member can move (the pre-check runs no YADE): P = 0, and the
    campaign itself adds a batch of 3 until the Wilson interval is within +-0.2 (0 of n:
    upper bound 3.84 / (n + 3.84) <= 0.4 needs n >= 6)."""
    record = _motion(tmp_path / "weak.npz", 0.0, 0.3)
    out = tmp_path / "ens"
    assert cli.main(["campaign", "ensemble", "--record", str(record), "--members", "3",
                     "--precision", "0.2", "--out", str(out), "--animations", "0"]) == 0
    summary = json.loads((out / "ensemble_summary.json").read_text())
    for col in summary["columns"]:
        assert col["p_toppled"] == 0.0 and col["mean_downfall_azimuth_deg"] is None
        assert col["p_toppled_ci95"][0] == 0.0 and col["p_toppled_ci95"][1] <= 0.4
    assert summary["members"] == 6 and summary["sizing"]["stopped_by"] == "precision"


def fake_campaign(p_true, tmp_path):
    """A stand-in for run_campaign: per record, k = round(p n) of n members toppled."""
    from pipeline.campaign import sizing
    from pipeline.stats.ensemble import wilson_interval
    calls = []

    def run(options):
        """Writes the summaries where the campaign's outputs write them."""
        calls.append(dict(options["record_members"]))
        summaries = []
        for rec, n in options["record_members"].items():
            k = int(round(p_true[rec] * n))
            summaries.append({"record": rec, "record_input": rec, "columns": [
                {"column": "drums", "members": n, "toppled": k, "p_toppled": k / n,
                 "p_toppled_ci95": wilson_interval(k, n), "mean_azimuth_ci95_deg": None,
                 "resultant_length": None}]})
        sizing.write_summaries(tmp_path, summaries)
        return {"figures": []}
    return sizing, run, calls


def test_members_are_added_until_the_interval_is_narrow_enough(tmp_path):
    """P = 0.5 needs about (1.96 / 0.1)^2 / 4 = 96 members for +-0.1, added in whole batches
    of 16 and in few rounds (as many batches at once as the fraction so far asks for);
    P = 0 is decided within two batches; each record stops by itself and says why."""
    sizing, run, calls = fake_campaign({"A": 0.5, "B": 0.0}, tmp_path)
    options = {"members": 16, "max_members": 256, "precision": 0.1, "arc_deg": 60.0}
    result = sizing.run_sized(run, ["A", "B"], tmp_path, options)
    sized = {s["record"]: s["sizing"] for s in result["summaries"]}
    assert sized["A"]["stopped_by"] == "precision" and 96 <= sized["A"]["members"] <= 112
    assert sized["B"]["stopped_by"] == "precision" and sized["B"]["members"] <= 32
    assert calls[0] == {"A": 16, "B": 16}
    assert all((c["A"] - p["A"]) % 16 == 0 for p, c in zip(calls, calls[1:]))
    assert len(calls) <= 3
    written = json.loads((tmp_path / "A" / "ensemble_summary.json").read_text())
    assert written["sizing"]["stopped_by"] == "precision"


def test_the_member_cap_ends_the_sizing_and_says_so(tmp_path):
    sizing, run, _ = fake_campaign({"A": 0.5}, tmp_path)
    options = {"members": 8, "max_members": 24, "precision": 0.0, "arc_deg": 60.0}
    (summary,) = sizing.run_sized(run, ["A"], tmp_path, options)["summaries"]
    assert summary["sizing"]["members"] == 24 and summary["sizing"]["stopped_by"] == "member cap"
    assert "P(toppled)" in summary["sizing"]["open"]


def test_batches_keep_the_members_that_ran():
    from pipeline.campaign import ensemble_members
    first = ensemble_members.sample_members(6, ensemble_members.DEFAULT_SEED)
    grown = ensemble_members.sample_batches(18, 6, ensemble_members.DEFAULT_SEED)
    assert grown[:6] == first                      # a fixed 6-member ensemble, unchanged
    assert grown[6:12] != first and grown[12:] != grown[6:12]
    assert grown == ensemble_members.sample_batches(18, 6, ensemble_members.DEFAULT_SEED)   # reproducible


def test_mean_direction_error_is_the_circular_standard_error():
    from pipeline.stats.circular import mean_direction_error_deg
    rng = np.random.default_rng(3)
    samples = rng.vonmises(0.0, 8.0, size=(400, 50))         # kappa 8: sigma ~ 20.7 deg
    means = np.degrees(np.angle(np.exp(1j * samples).mean(axis=1)))
    spread = means.std()                                       # the real Monte Carlo error
    predicted = np.median([mean_direction_error_deg(np.degrees(s)) for s in samples])
    assert predicted == pytest.approx(spread, rel=0.15)


def test_members_needed_follows_the_binomial_and_the_arc():
    """Wilson at the fraction so far (P = 0.5 of 16: 96 members for +-0.1), and a mean
    direction's interval shrinking as 1 / sqrt(falls): 120 deg from 16 falls needs 64
    falls for 60 deg; never past the cap, always one batch at least."""
    from pipeline.campaign.sizing import members_needed
    half = {"columns": [{"members": 16, "toppled": 8, "mean_azimuth_ci95_deg": None,
                         "resultant_length": None}]}
    assert members_needed(half, 0.1, 16, 256) == 96
    assert members_needed(half, 0.1, 16, 64) == 64
    fell = {"columns": [{"members": 16, "toppled": 16, "mean_azimuth_ci95_deg": [300.0, 60.0],
                         "resultant_length": 0.8}]}
    assert members_needed(fell, 0.5, 16, 256, arc_deg=60.0) == 64
    assert members_needed(fell, 0.5, 16, 256) == 32          # no arc asked: one batch
