"""Fragility: the logistic surface and the lognormal fit recover known curves, the 2D rigid
block topples never below g tan(alpha) and always under a huge pulse, and a tiny YADE
campaign writes fragility.json with its documented keys."""
import json
import math
import sys

import numpy as np
import pytest

from pipeline import cli
from pipeline.rocking.housner import block_constants
from pipeline.rocking.pulse import sine_pulse, sine_pulse_response
from pipeline.rocking.sampled import rocking_response_sampled
from pipeline.campaign import fragility as fr
from pipeline.campaign import fragility_block
from pipeline.campaign.fragility_tables import MODELS_2D, level_table
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.measures import horizontal_peak
from pipeline.motion.pulses import one_sine_pulse
from pipeline.stats.fragility import (binned_fractions, fragility_fit, logistic_probability,
                                      logistic_surface)
from pipeline.stats.regression import separated

G = 9.81
TRUE = {"b0": 1.0, "b1": 3.0, "b2": 2.0}


def _logistic_samples(n=3000, seed=3):
    rng = np.random.default_rng(seed)
    pga = np.exp(rng.uniform(math.log(0.5), math.log(10.0), n))
    ratio = np.exp(rng.uniform(math.log(0.05), math.log(0.5), n))
    toppled = rng.random(n) < logistic_probability(TRUE, pga, ratio)
    return pga, ratio, toppled


def _check_recovered(fit):
    assert fit["separated"] is False and fit["converged"]
    for name, value in TRUE.items():
        lo, hi = fit["ci95"][name]
        assert lo < value < hi, (name, fit["coefficients"][name], lo, hi)
        assert fit["coefficients"][name] == pytest.approx(value, abs=4 * fit["se"][name])


def test_logistic_surface_recovers_a_known_surface(monkeypatch):
    pga, ratio, toppled = _logistic_samples()
    monkeypatch.setitem(sys.modules, "statsmodels.api", None)     # the scipy.optimize path
    fit = logistic_surface(pga, ratio, toppled, alpha=0.165, p=2.0)
    assert "scipy" in fit["method"] and "maximum likelihood" in fit["method"]
    _check_recovered(fit)
    assert fit["n"] == 3000 and fit["toppled"] == int(toppled.sum())
    # the dimensionless form is the same surface
    d = fit["dimensionless"]
    pga0, ratio0 = 2.0, 0.2
    eta = d["c0"] + d["b1"] * math.log(pga0 / (G * math.tan(0.165))) + d["b2"] * math.log(
        2.0 * ratio0)
    assert 1 / (1 + math.exp(-eta)) == pytest.approx(
        logistic_probability(fit["coefficients"], pga0, ratio0), rel=1e-9)


def test_logistic_surface_statsmodels_and_scipy_agree(monkeypatch):
    pytest.importorskip("statsmodels")
    pga, ratio, toppled = _logistic_samples(seed=4)
    with_statsmodels = logistic_surface(pga, ratio, toppled)
    assert "statsmodels" in with_statsmodels["method"]
    _check_recovered(with_statsmodels)
    monkeypatch.setitem(sys.modules, "statsmodels.api", None)
    with_scipy = logistic_surface(pga, ratio, toppled)
    for name in TRUE:
        assert with_scipy["coefficients"][name] == pytest.approx(
            with_statsmodels["coefficients"][name], abs=1e-6)


def test_separated_outcomes_get_a_finite_firth_estimate():
    im = np.array([1.0, 1.5, 2.0, 3.0, 4.0, 6.0])
    fell = im > 2.5
    X = np.column_stack([np.ones(im.size), np.log(im)])
    assert separated(X, fell)
    assert not separated(X, np.array([0, 1, 0, 1, 1, 1], bool))
    fit = fragility_fit(im, fell)
    assert fit["separated"] and "Firth" in fit["method"]
    assert 2.0 < fit["median"] < 3.0 and fit["beta"] > 0
    assert fit["median_ci95"][0] < fit["median"] < fit["median_ci95"][1]
    surface = logistic_surface(im, np.full(im.size, 0.2), fell)
    assert surface["separated"] and surface["coefficients"]["b1"] > 0
    # not identified: one outcome, or too few distinct IM values
    assert fragility_fit(im, np.zeros(im.size, bool))["median"] is None
    assert fragility_fit([1, 1, 2, 2], [0, 1, 1, 1])["note"].startswith("2 distinct")


def test_binned_fractions_one_bin_per_level_with_wilson_intervals():
    im = np.repeat([0.5, 1.0, 2.0], 4)
    fell = np.array([0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1], bool)
    bins = binned_fractions(im, fell)
    assert [b["n"] for b in bins] == [4, 4, 4]
    assert [b["fraction"] for b in bins] == [0.0, 0.5, 1.0]
    assert bins[0]["ci95"][0] == 0.0 and bins[2]["ci95"][1] == 1.0
    assert bins[1]["ci95"][0] < 0.5 < bins[1]["ci95"][1]


def _pulse_record(path, amplitude=5.0, period=1.0, duration=4.0, azimuth=30.0):
    m = one_sine_pulse(azimuth, amplitude, period=period, duration=duration)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": path.stem,
                                            "back_azimuth_deg": 120.0}).save(path)
    return path


def test_block_never_topples_below_g_tan_alpha_and_always_under_a_huge_pulse(tmp_path,
                                                                           monkeypatch):
    # the paper's column: h = 3.5 m, h/d = 6, so g tan(alpha) = 9.81 / 6 = 1.635 m/s^2
    assert block_constants(3.5, 3.5 / 6)["uplift_acc"] == pytest.approx(G / 6)
    record = _pulse_record(tmp_path / "pulse.npz", period=0.5)
    specs = fr.fragility_specs([str(record)], tmp_path / "campaign", levels="1.6,60",
                               members=3, column="monolithic", azimuths=6)
    assert len(specs) == 6
    # the scale gives the scaled motion the target PGA
    motion = Motion.load(specs[0].motion_file)
    for spec in specs:
        pga = horizontal_peak(motion.scale(spec.params.drive.scale).acc)[0]
        assert pga == pytest.approx(spec.tags.level_m_s2, rel=1e-5)
    table, cost = fragility_block.block_runs(specs)
    assert cost["block2d_cases"] == 6 * 6
    levels = level_table(table).set_index(["record_id", "level_m_s2"])
    for block in MODELS_2D:
        assert levels.loc[("pulse", 1.6), f"p_{block}"] == 0.0
        assert levels.loc[("pulse", 60.0), f"p_{block}"] == 1.0
    low = table[table["level_m_s2"] == 1.6]
    assert (low["max_tilt_deg"] == 0.0).all()       # below uplift: the block never moves
    high = table[(table["level_m_s2"] == 60.0) & (table["column"] == "block2d")]
    # a pulse toward 30 deg pushes the block over toward 210 deg at its first half cycle
    assert np.allclose(high["downfall_azimuth_deg"], 210.0)
    # integrated in small batches (memory bound): the same table
    monkeypatch.setattr(fragility_block, "BLOCK_CHUNK_SAMPLES", 1)
    chunked, _ = fragility_block.block_runs(specs)
    assert chunked.equals(table)


def test_sampled_block_agrees_with_the_event_driven_integration():
    """One-sine pulses across the three modes of Zhang & Makris: same outcome, overturning
    times within 0.1 s."""
    height, width = 3.113, 0.795
    c = block_constants(height, width)
    cases = [(3.0, 2.0), (3.0, 5.0), (5.0, 5.0), (5.0, 9.0), (8.0, 4.0), (8.0, 9.0)]
    for omega_ratio, amplitude_ratio in cases:
        ref = sine_pulse_response(height, width, amplitude_ratio, omega_ratio,
                                          dt_out=None)
        acc_func, t_pulse = sine_pulse(ref["amplitude"], ref["omega"], ref["psi"])
        t = np.arange(0.0, t_pulse + 0.001, 0.001)
        out = rocking_response_sampled(height, width, [acc_func(x) for x in t], 0.001)
        assert bool(out["overturned"][0]) == ref["overturned"], (omega_ratio, amplitude_ratio)
        assert out["decided"][0]
        if ref["overturned"]:
            assert out["overturn_time"][0] == pytest.approx(ref["overturn_time"], abs=0.1)
            assert out["overturn_direction"][0] == ref["overturn_direction"]
    assert c["uplift_acc"] == pytest.approx(G * width / height)


def test_levels_are_checked():
    assert fr.parse_levels("2,0.5,1,1") == (0.5, 1.0, 2.0)
    for bad in ("", "a,b", "-1,2", "0", "1,inf"):
        with pytest.raises(InputError):
            fr.parse_levels(bad)


@pytest.mark.yade
def test_tiny_yade_fragility_campaign_writes_the_documented_keys(tmp_path):
    """1 record, 2 levels (below the uplift threshold: YADE skipped; far above: every
    member falls), 2 members, the monolith."""
    record = _pulse_record(tmp_path / "pulse.npz")
    out = tmp_path / "fragility"
    assert cli.main(["campaign", "fragility", "--records", str(record), "--levels", "1,8",
                     "--members", "2", "--column", "monolithic", "--out", str(out),
                     "--jobs", "2", "--animations", "0", "--azimuths", "4"]) == 0
    summary = json.loads((out / "fragility.json").read_text())
    for key in ("records", "levels_m_s2", "members", "seed", "column", "azimuths",
                "intensity_measures", "columns", "comparison", "levels", "block2d", "cost"):
        assert key in summary, key
    assert summary["records"] == ["pulse"] and summary["levels_m_s2"] == [1.0, 8.0]
    assert set(summary["columns"]) == {"monolithic", "block2d", "block2d_worst"}
    for name, entry in summary["columns"].items():
        assert entry["runs"] == 4 and entry["toppled"] == 2, name
        assert entry["all_stood_up_to_m_s2"] == 1.0 and entry["all_toppled_from_m_s2"] == 8.0
        for im in ("PGA", "PGV", "PGV/PGA"):
            fit = entry[im]
            for key in ("median", "beta", "median_ci95", "beta_ci95", "n", "toppled",
                        "n_distinct", "method", "separated", "note", "unit", "bins"):
                assert key in fit, (name, im, key)
        assert {"form", "coefficients", "se", "ci95", "n", "method", "separated"} <= set(
            entry["logistic"])
    assert summary["cost"]["yade_runs"] == 2 and summary["cost"]["runs_not_simulated"] == 2
    # the damage states of the 3D column (none for the 2D block): collapse is toppling,
    # and a run that toppled reached every milder state
    assert set(summary["damage_states"]) == {"monolithic"}
    states = summary["damage_states"]["monolithic"]["states"]
    assert list(states) == ["slight", "moderate", "severe", "collapse"]
    assert all(s["runs"] == 4 and s["reached"] >= 2 for s in states.values())
    assert states["collapse"]["reached"] == 2
    for name in ("fragility_runs.csv", "fragility_levels.csv", "fragility_curves.png",
                 "fragility_2d_vs_3d.png", "fragility_surface.png",
                 "fragility_damage_states.png"):
        assert (out / name).exists(), name
