"""The contact-stiffness table (make contact-convergence): its summaries on small
synthetic inputs, the restitution measured from a free-rocking trajectory against
Housner's, and one short YADE check that a stiffer contact keeps the block's restitution."""
import math
import re

import numpy as np
import pandas as pd
import pytest

from pipeline.rocking.housner import SHAPES
from pipeline.rocking.response import housner_free_rocking
from pipeline.campaign import contact_convergence as cc
from pipeline.files import InputError
from pipeline.verification import stiffness


def members(factor, toppled, azimuths, time_step, wall):
    return pd.DataFrame({"factor": factor, "member": [-1] + list(range(len(toppled))),
                         "column": "monolithic", "toppled": [True] + toppled,
                         "downfall_azimuth_deg": [0.0] + azimuths,
                         "time_step_s": time_step, "wall_s": wall})


def test_twin_summary_pairs_members_across_factors():
    nan = math.nan
    table = pd.concat([
        members(1.0, [True, True, False, False], [350.0, 90.0, nan, nan], 1e-4, 10.0),
        members(10.0, [True, True, True, False], [10.0, 90.0, 180.0, nan], 1e-4 / 10 ** 0.5,
                30.0)])
    out = cc.twin_summary(table, "R")
    x1, x10 = out["factors"]["x1"], out["factors"]["x10"]
    assert x1["members"] == 4 and x1["columns"]["monolithic"]["toppled"] == 2  # nominal left out
    col = x10["columns"]["monolithic"]
    assert col["p_toppled"] == 0.75 and col["same_outcome_as_x1"] == 3
    lo, hi = col["p_toppled_ci95"]
    assert lo < 0.75 < hi
    # member 0 fell at 350 deg at x1 and 10 deg at x10: 20 deg across North, member 1 0
    assert col["fell_at_both"] == 2 and col["max_turn_vs_x1_deg"] == pytest.approx(20.0)
    assert col["median_turn_vs_x1_deg"] == pytest.approx(10.0)
    # one member changed (stood at x1, fell at x10): McNemar's exact p = 2 * 0.5^1 = 1
    assert (col["toppled_only_here"], col["toppled_only_at_x1"]) == (1, 0)
    assert col["p_value_vs_x1"] == pytest.approx(1.0)
    assert x1["columns"]["monolithic"]["p_value_vs_x1"] == 1.0
    # 10, 90, 180 deg: the mean direction of three unit vectors
    east, north = np.sin(np.radians([10, 90, 180])).sum(), np.cos(np.radians([10, 90, 180])).sum()
    assert col["mean_downfall_azimuth_deg"] == pytest.approx(
        math.degrees(math.atan2(east, north)) % 360)
    assert col["resultant_length"] == pytest.approx(math.hypot(east, north) / 3)
    assert x10["time_step_vs_x1"] == pytest.approx(10 ** -0.5)
    assert x10["wall_vs_x1"] == pytest.approx(3.0) and x10["wall_s_total"] == pytest.approx(120)
    with pytest.raises(InputError, match="x1"):
        cc.twin_summary(table[table["factor"] == 10.0])


def test_nothing_to_summarise_is_one_error_and_missing_parts_are_said(tmp_path):
    said = []
    with pytest.raises(InputError, match="nothing to summarise"):
        cc.summarise_all(tmp_path, log=said.append)
    assert len(said) == 3 and all("not run" in line for line in said)
    assert cc.main([str(tmp_path)]) == 1 and not (tmp_path / "convergence.json").exists()
    assert cc.main([]) == 2


def housner_run(shape, height, width, restitution=None):
    c = SHAPES[shape](height, width)
    free = housner_free_rocking(height, width, 0.5 * c["alpha"], n_impacts=6,
                                        restitution=restitution, shape=shape)
    return c, free


@pytest.mark.parametrize("shape", ["block", "cylinder"])
def test_restitution_measured_from_a_rigid_bodys_decay(shape):
    """Housner's equation integrated with a stated restitution: the measure recovers it
    at every impact, and the impact times the integration's events give."""
    c, free = housner_run(shape, 3.5, 3.5 / 6, restitution=0.95)
    # sampled as a sensor would: not at the impacts' own instants (theta exactly 0)
    keep = free["theta"] != 0
    out = stiffness.measure(free["t"][keep], free["theta"][keep], c["alpha"])
    assert len(out["restitution_per_impact"]) == 5
    assert np.allclose(out["restitution_per_impact"], 0.95, atol=2e-4)
    assert np.allclose(out["impact_times_s"], free["impact_times"][:5], atol=1e-3)


def test_free_rocking_summary_against_housner_and_x1():
    body = stiffness.BODIES["block"]
    constants, free = stiffness.reference(body)
    times = free["impact_times"][:5]
    eta = constants["restitution"]
    runs = {1: {"kn": 1.2e7, "impact_times_s": list(times), "restitution_per_impact": [eta] * 5,
                "restitution": eta, "time_step_s": 2e-5, "wall_s": 2.0, "simulated_s": 2.0},
            10: {"kn": 1.2e8, "impact_times_s": list(times * 1.01),
                 "restitution_per_impact": [eta + 0.001] * 5, "restitution": eta + 0.001,
                 "time_step_s": 2e-5 / 10 ** 0.5, "wall_s": 5.0, "simulated_s": 2.0}}
    out = stiffness.summarise("block", runs)
    assert out["housner_restitution"] == pytest.approx(1 - 1.5 / 26)   # h/b 5: sin^2 = 1/26
    x1, x10 = out["factors"]["x1"], out["factors"]["x10"]
    assert x1["max_abs_restitution_minus_housner"] == pytest.approx(0, abs=1e-12)
    assert x10["max_abs_restitution_minus_x1"] == pytest.approx(0.001)
    assert x10["max_rel_error_impact_times_housner"] == pytest.approx(0.01)
    assert x10["max_abs_impact_time_minus_x1_s"] == pytest.approx(0.01 * times[-1])
    assert x10["time_step_vs_x1"] == pytest.approx(10 ** -0.5) and x10["wall_vs_x1"] == 2.5
    with pytest.raises(InputError, match="factors"):
        stiffness.check_factors((3, 10))
    other = stiffness.other_damping(runs)
    assert other["x10"]["max_abs_restitution_minus_x1"] == pytest.approx(0.001)
    assert other["x1"]["restitution"] == eta and "impact_times_s" not in other["x1"]


@pytest.mark.yade
def test_a_stiffer_contact_keeps_the_blocks_restitution(tmp_path):
    """The paper's marble block at kn x1 and x3, damping and friction fixed: the same
    restitution within 0.002 (of a 0.058 loss per impact), both within 0.002 of Housner's
    perfectly inelastic impact, and a time step 1 / sqrt(3) as long."""
    x1 = stiffness.run_body("block", 1, tmp_path / "x1", impacts=3)
    x3 = stiffness.run_body("block", 3, tmp_path / "x3", impacts=3)
    housner = 1 - 1.5 / 26
    assert len(x1["restitution_per_impact"]) == len(x3["restitution_per_impact"]) == 3
    assert np.allclose(x1["restitution_per_impact"], x3["restitution_per_impact"], atol=2e-3)
    assert np.allclose(x3["restitution_per_impact"], housner, atol=2e-3)
    assert x3["time_step_s"] / x1["time_step_s"] == pytest.approx(3 ** -0.5, rel=1e-6)


def test_mcnemar_p_of_members_that_all_changed_one_way():
    """Six members standing at x1 all fall at x3: exact two-sided p = 2 * 0.5^6."""
    table = pd.concat([members(1.0, [False] * 6, [math.nan] * 6, 1e-4, 1.0),
                       members(3.0, [True] * 6, [0.0] * 6, 1e-4, 1.0)])
    col = cc.twin_summary(table)["factors"]["x3"]["columns"]["monolithic"]
    assert col["p_value_vs_x1"] == pytest.approx(2 * 0.5 ** 6)


def test_report_section_from_the_file(tmp_path):
    from pipeline.report import contact_stiffness_section
    assert "Not run yet" in contact_stiffness_section(tmp_path)
    nan = math.nan
    twin = cc.twin_summary(pd.concat([
        members(1.0, [True, False], [90.0, nan], 1e-4, 10.0),
        members(3.0, [True, True], [100.0, 200.0], 6e-5, 15.0)]), "R")
    (tmp_path / "contact-convergence").mkdir()
    (tmp_path / "contact-convergence" / "convergence.json").write_text(
        __import__("json").dumps({"twin": twin}))
    text = contact_stiffness_section(tmp_path)
    # x3: both members fell, one of them stood at x1
    assert re.search(r"\| x3 +\| monolithic +\| 2 +\| 1\.00 \[[^|]*\| 150, [^|]*\| 1/2 ", text)


def fake_ensemble(directory, record, toppled, time_step, wall):
    """An ensemble campaign's members.csv and its runs' summary.json (no YADE)."""
    from pipeline.outcome.summary import RunSummary
    rows = []
    for member, fell in enumerate(toppled):
        run_dir = f"runs/m{member}"
        RunSummary(record=record, time_step_s=time_step, wall_s=wall).save(
            directory / run_dir / "summary.json")
        rows.append({"run_id": f"m{member}", "member": member, "record_id": record,
                     "column": "drums", "toppled": fell,
                     "downfall_azimuth_deg": 45.0 if fell else math.nan, "run_dir": run_dir})
    pd.DataFrame(rows).to_csv(directory / "members.csv", index=False)


def test_twin_ensembles_read_from_their_campaign_directories(tmp_path):
    fake_ensemble(tmp_path / "twin-x1", "R", [True, False], 1e-4, 4.0)
    fake_ensemble(tmp_path / "twin-x10", "R", [True, True], 1e-4 / 10 ** 0.5, 12.0)
    said = []
    out = cc.summarise_all(tmp_path, log=said.append)
    assert set(out) == {"twin"} and len(said) == 2          # rock and free rocking: said
    x10 = out["twin"]["factors"]["x10"]
    assert out["twin"]["record"] == "R" and x10["columns"]["drums"]["same_outcome_as_x1"] == 1
    assert x10["time_step_s"] == pytest.approx(1e-4 / 10 ** 0.5) and x10["wall_vs_x1"] == 3.0
    fake_ensemble(tmp_path / "twin-x3", "Q", [True, True], 1e-4, 4.0)
    with pytest.raises(InputError, match="different records"):
        cc.summarise_all(tmp_path, log=said.append)


def test_rock_restitution_runs_the_rock_parts_point(monkeypatch):
    """The rock's free rocking takes the shake-table part's footprint, damping and
    friction, each factor's kn, and every damping of ROCK_DAMPINGS with its own at x1;
    Housner's block value is 1 - 1.5 sin^2 of the critical angle toward the azimuth."""
    from pipeline.scenario import ColumnGeometry
    from pipeline.verification import contact_map
    calls = []

    def measure(geometry, kn, azimuth_deg, **options):
        calls.append((geometry.to_dict()["footprint_tolerance_m"], kn, azimuth_deg, options))
        return (lambda damping: 0.9 + 0.01 * damping + kn * 1e-12), (lambda: 0)  # (measured, runs)
    monkeypatch.setattr(contact_map, "specimen_measure", measure)
    rock = {"grid_point": "footprint_tolerance_m=0.002, damping=0.07, mu_s=0.3, "
                          "rotate_deg=180, kn=1e+08",
            "factors": {"x1": {"kn": 1e8}, "x3": {"kn": 3e8}}}
    out = cc.rock_restitution(rock, log=lambda line: None)
    assert {c[0] for c in calls} == {0.002} and {c[2] for c in calls} == {90.0}
    assert all(c[3] == {"mu_s": 0.3} for c in calls)
    assert out["factors"]["x3"]["restitution"] == pytest.approx(0.9 + 0.0007 + 3e-4)
    assert [r["damping"] for r in out["by_damping"]] == sorted({*cc.ROCK_DAMPINGS, 0.07})
    from pipeline.campaign.shake_table_experiments import SPECIMEN
    geometry = ColumnGeometry.load(SPECIMEN).to_dict()
    geometry["footprint_tolerance_m"] = 0.002
    alpha = math.radians(ColumnGeometry.from_dict(geometry).critical_angle_along_deg(90.0))
    assert out["housner_block_restitution"] == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2)
    assert 0 < alpha < math.radians(45)
