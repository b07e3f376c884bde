"""The pulse grid of campaign fragility: the one-cosine pulse against its closed form,
bad grid options refused in one line, the sampled shaking directions turning with the
specimen, and (YADE) a slender box mesh against the 2D rigid block of the same critical
angle and pivot distance, in cells clearly below and above the block's threshold."""
import json
import math
import subprocess
import sys

import numpy as np
import pytest
import trimesh

from pipeline.campaign import pulse_adaptive, pulse_grid, pulse_summary
from pipeline.campaign.pulse_check import scores
from pipeline.files import InputError
from pipeline.motion.measures import horizontal_peak
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.rocking.housner import block_constants
from pipeline.rocking.sampled import rocking_response_sampled


@pytest.mark.parametrize("pga, ratio, azimuth", [(0.2 * 9.80665, 0.1, 0.0), (5.0, 0.37, 30.0),
                                                 (1.1 * 9.80665, 1.0, 271.0)])
def test_one_cosine_pulse_has_the_requested_peaks_and_ends_at_rest(pga, ratio, azimuth):
    motion = one_cosine_pulse(pga, ratio, azimuth, dt=0.005, tail_s=2.0)
    assert horizontal_peak(motion.acc)[0] == pytest.approx(pga, rel=1e-9)
    assert horizontal_peak(motion.vel)[0] == pytest.approx(pga * ratio, rel=1e-9)
    amplitude = pga * ratio ** 2                      # A = PGA / (2 pi F)^2
    assert np.hypot(motion.disp[:, 0], motion.disp[:, 1]).max() == pytest.approx(
        2 * amplitude, rel=1e-9)                      # d peaks at 2A, half a cycle in
    assert np.abs(motion.disp[-1]).max() < 1e-12 and np.abs(motion.vel[-1]).max() < 1e-12
    # horizontal along the azimuth: East = sin, North = cos; the vertical is still
    k = np.argmax(np.abs(motion.acc[:, 0]) + np.abs(motion.acc[:, 1]))
    assert math.degrees(math.atan2(motion.acc[k, 0], motion.acc[k, 1])) % 360 == \
        pytest.approx(azimuth % 360, abs=1e-9)
    assert not motion.acc[:, 2].any()
    # the acceleration's double integral is the displacement (trapezoid, fine sampling)
    fine = one_cosine_pulse(pga, ratio, azimuth, dt=0.0005, tail_s=0.0)
    v = np.concatenate([[0], np.cumsum((fine.acc[1:, 0] + fine.acc[:-1, 0]) / 2)]) * fine.dt
    assert np.abs(v - fine.vel[:, 0]).max() < 1e-3 * pga * ratio


def test_vsr_preset_is_the_published_grid():
    grid = pulse_grid.parse_pulses("vsr")
    assert grid["pga_g"][0] == 0.2 and grid["pga_g"][-1] == 1.1 and len(grid["pga_g"]) == 10
    assert grid["pgv_pga_s"][0] == 0.1 and grid["pgv_pga_s"][-1] == 1.0
    assert len(grid["pgv_pga_s"]) == 10


@pytest.mark.parametrize("text, words", [
    ("pga_g=0.2:1.1:10", "lacks pgv_pga_s"),
    ("pga_g=0.2:1.1:10;pgv_pga_s=0.1:1:0", "N must be"),
    ("pga_g=1.1:0.2:10;pgv_pga_s=0.1:1:3", "LO <= HI"),
    ("pga_g=0.2:1.1;pgv_pga_s=0.1:1:3", "LO:HI:N"),
    ("pga_g=0.2:1.1:2.5;pgv_pga_s=0.1:1:3", "LO:HI:N"),
    ("pgv=0.2:1.1:2;pgv_pga_s=0.1:1:3", "unknown axis"),
    ("pga_g=0.2:0.3:1;pgv_pga_s=0.1:1:3", "1 exactly when LO = HI"),
    ("pga_g=nan:1:3;pgv_pga_s=0.1:1:3", "LO <= HI"),
    ("pga_g=0.2:1:3;pga_g=0.2:1:3;pgv_pga_s=0.1:1:3", "twice"),
])
def test_bad_pulse_grids_are_refused_in_one_line(text, words):
    with pytest.raises(InputError, match=words) as error:
        pulse_grid.parse_pulses(text)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("text, mesh, words", [
    ("damping=0.1:2", True, "LO <= HI"), ("friction=0.5:0.6", True, "unknown parameter"),
    ("kn=1e8", True, "LO:HI"), ("footprint_tolerance_m=0.001:0.002", False, "only a mesh"),
    ("damping=0.1:0.2;damping=0.1:0.2", False, "twice"),
    ("yaw_deg=-200:0", True, "LO <= HI"),
])
def test_bad_member_ranges_are_refused_in_one_line(text, mesh, words):
    with pytest.raises(InputError, match=words) as error:
        pulse_grid.parse_ranges(text, mesh)
    assert "\n" not in str(error.value)


def test_the_command_line_refuses_a_bad_grid_in_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "frag"
    done = subprocess.run([sys.executable, "-m", "pipeline", "campaign", "fragility",
                           "--pulses", "pga_g=0.2:1.1:10;pgv_pga_s=0.1:1.0:0", "--out", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode != 0
    assert len(done.stderr.strip().splitlines()) == 1 and "--pulses" in done.stderr
    assert not out.exists()


def test_members_draw_within_their_ranges_and_mu_k_follows_mu_s():
    ranges = pulse_grid.parse_ranges("kn=1e7:1e9;mu_s=0.5:0.5")
    sets = pulse_grid.sample_sets(8, 3, ranges)
    kn = np.log10([s["kn"] for s in sets])
    assert kn.min() >= 7 and kn.max() <= 9
    assert len({int(v) for v in kn}) == 2         # a Latin hypercube: both decades drawn
    assert all(s["mu_s"] == 0.5 and s["mu_k"] <= s["mu_s"] for s in sets)


def box_description(tmp_path, heading=0.0, width=0.2, height=0.8):
    mesh = trimesh.creation.box(extents=(width, width, height))
    path = tmp_path / "box.obj"
    mesh.export(path)
    return {"name": "box", "mesh": str(path), "density": 2700.0, "heading_deg": heading}


def test_sampled_directions_turn_with_the_specimen(tmp_path):
    """The field default draws directions relative to the specimen: a specimen turned by
    37 deg is shaken from directions turned by 37 deg, everything else the same."""
    runs = {}
    for heading in (0.0, 37.0):
        data = box_description(tmp_path, heading)
        _, _, azimuths, run = pulse_grid.pulse_runs(
            data, "monolithic", "pga_g=0.3:0.6:2;pgv_pga_s=0.2:0.2:1", 3, 4, None, 7, None)
        runs[heading] = (azimuths, run)
    a0, a37 = runs[0.0][0], runs[37.0][0]
    assert np.allclose((a37 - a0 - 37.0 + 180.0) % 360.0 - 180.0, 0.0, atol=1e-6)
    # stratified: each member's directions cover the circle, one per quarter
    quarter = np.floor(a0 / 90.0)
    assert all(sorted(q) == [0, 1, 2, 3] for q in quarter)
    for (_, _, p0, t0), (_, _, p37, t37) in zip(runs[0.0][1], runs[37.0][1]):
        assert {k: v for k, v in p0.items() if k not in ("rotate_deg", "column_file")} == \
            {k: v for k, v in p37.items() if k not in ("rotate_deg", "column_file")}


def test_a_members_yaw_turns_the_directions_it_is_shaken_from(tmp_path):
    """A member turned clockwise by its yaw is shaken from the azimuth minus the yaw: a
    fixed --azimuth spreads over the members' yaws; sampled directions stay one per
    quarter relative to each member's turned specimen."""
    data = box_description(tmp_path)
    pulses = "pga_g=0.3:0.3:1;pgv_pga_s=0.2:0.2:1"
    sets, fixed, _ = pulse_grid.pulse_runs(data, "monolithic", pulses, 6, 1, 90.0, 7,
                                           "yaw_deg=-30:30")[1:]
    yaw = np.array([p["yaw_deg"] for p in sets])
    assert np.ptp(yaw) > 30.0                           # drawn over the range
    assert np.allclose(fixed[:, 0], (90.0 - yaw) % 360.0, atol=1e-6)
    sets, sampled, runs = pulse_grid.pulse_runs(data, "monolithic", pulses, 6, 4, None, 7,
                                                "yaw_deg=-30:30")[1:]
    unturned = pulse_grid.member_azimuths(6, 4, 7)
    assert np.allclose((sampled - (unturned - yaw[:, None]) + 180.0) % 360.0 - 180.0, 0.0,
                       atol=1e-6)
    quarter = np.floor(((sampled + yaw[:, None]) % 360.0) / 90.0)
    assert all(sorted(q) == [0, 1, 2, 3] for q in quarter)
    assert {run[2]["rotate_deg"] for run in runs} == set(sampled.ravel())


def test_scores_of_certain_and_even_predictions():
    y = np.array([1, 0, 1, 0])
    assert scores(y, y)["brier"] == 0.0
    assert scores(y, np.full(4, 0.5))["brier"] == 0.25
    assert scores(y, np.full(4, 0.5))["log_likelihood_per_test"] == pytest.approx(math.log(0.5))


@pytest.mark.yade
def test_a_box_mesh_fragility_matches_the_2d_block_away_from_its_threshold(tmp_path):
    """A slender box (0.2 x 0.2 x 0.8 m: alpha = 14.0 deg, uplift at 0.25 g) shaken along
    East by one pulse of PGV/PGA 0.5 s at 0.15 g (below uplift: the block stands) and
    1.0 g (four times uplift: the block overturns), stiff contact, one member: the 3D
    mesh and the 2D block agree in both cells (tolerance: the outcome itself, since the
    cells are far from the threshold)."""
    from pipeline.campaign import run_campaign
    data = box_description(tmp_path)
    (tmp_path / "box.json").write_text(json.dumps(data))
    block = block_constants(0.8, 0.2)
    cells = {0.15: None, 1.0: None}
    for pga_g in cells:
        pulse = one_cosine_pulse(pga_g * 9.80665, 0.5, 0.0, tail_s=0.0)
        cells[pga_g] = bool(rocking_response_sampled(0.8, 0.2, pulse.acc[:, 1], pulse.dt)
                            ["overturned"][0])
    assert cells == {0.15: False, 1.0: True}          # the reference is decisive here
    assert math.tan(block["alpha"]) == pytest.approx(0.25)
    run_campaign("fragility", jobs=2, campaign_dir=tmp_path / "frag", options={
        "column_file": str(tmp_path / "box.json"), "pulses": "pga_g=0.15:1.0:2;pgv_pga_s=0.5:0.5:1",
        "members": 1, "azimuth": 90.0, "headings": 1,
        "ranges": "kn=1.2e8:1.2e8;damping=0.1:0.1;mu_s=0.8:0.8;footprint_tolerance_m=0.001:0.001;"
                  "yaw_deg=0:0"})
    summary = json.loads((tmp_path / "frag" / "fragility.json").read_text())
    section = summary["pulse_grid"]
    assert section["block2d"]["alpha_rad"] == pytest.approx(block["alpha"], rel=1e-3)
    assert section["block2d"]["R_m"] == pytest.approx(block["R"], rel=1e-3)
    # one footprint, one direction: the smallest uplift is the block's g tan(alpha) = 0.25 g
    assert section["block2d"]["uplift_g_smallest"] == pytest.approx(0.25, rel=1e-3)
    for model in ("monolithic", "block2d"):
        p = {c["pga_g"]: c["P"] for c in section["models"][model]["cells"]}
        assert p == {0.15: 0.0, 1.0: 1.0}, model


@pytest.mark.yade
def test_turning_a_field_rock_turns_nothing_in_its_fragility(tmp_path):
    """A box wider one way than the other (0.15 m East x 0.3 m North x 0.6 m: tipping
    across its thin side at 14.0 deg, across its wide side at 26.6 deg), in the field
    default (directions sampled relative to the specimen), as scanned and turned by
    90 deg: run for run the same outcome, its fall turned by 90 deg, so the same P per
    cell. At 0.45 g (the two sides' uplift: 0.25 g and 0.5 g) the 2D block of the same
    runs falls in some directions and not in others, so a direction not turned with the
    specimen would show; at 0.85 g it falls in all, so the falls' directions compare."""
    import pandas as pd

    from pipeline.campaign import run_campaign
    path = tmp_path / "slab.obj"
    trimesh.creation.box(extents=(0.15, 0.3, 0.6)).export(path)
    options = {"pulses": "pga_g=0.45:0.85:2;pgv_pga_s=0.5:0.5:1", "members": 1, "headings": 4,
               "ranges": "kn=1.2e8:1.2e8;damping=0.1:0.1;mu_s=0.8:0.8;"
                         "footprint_tolerance_m=0.001:0.001"}
    runs = {}
    for heading in (0.0, 90.0):
        (tmp_path / f"slab{heading:g}.json").write_text(json.dumps(
            {"name": "slab", "mesh": str(path), "density": 2700.0, "heading_deg": heading}))
        out = tmp_path / f"frag{heading:g}"
        run_campaign("fragility", jobs=2, campaign_dir=out, options={
            **options, "column_file": str(tmp_path / f"slab{heading:g}.json")})
        table = pd.read_csv(out / "fragility_runs.csv")
        runs[heading] = table.set_index(["model", "pga_g", "member", "heading"]).sort_index()
    turned, scanned = runs[90.0], runs[0.0]
    assert np.allclose((turned["azimuth_deg"] - scanned["azimuth_deg"]) % 360.0, 90.0)
    block = scanned.loc["block2d"]
    assert block.loc[0.45, "toppled"].nunique() == 2       # the direction matters here
    assert block.loc[0.85, "toppled"].all()
    rock = "monolithic"
    assert (turned.loc[rock, "toppled"] == scanned.loc[rock, "toppled"]).all()
    fell = scanned.loc[rock, "toppled"].astype(bool)
    assert fell.any()
    turn = (turned.loc[rock, "downfall_azimuth_deg"][fell]
            - scanned.loc[rock, "downfall_azimuth_deg"][fell] - 90.0 + 180.0) % 360.0 - 180.0
    assert np.abs(turn).max() < 5.0


def test_the_long_run_gate_counts_each_pulse_run_by_its_length(tmp_path, monkeypatch):
    """Before any run: refused in one line with the number of runs, nothing left behind."""
    from pipeline import files
    from pipeline.campaign import run_campaign
    monkeypatch.setattr(files, "LONG_RUN_S", 1.0)
    out = tmp_path / "frag"
    with pytest.raises(InputError, match=r"campaign fragility \(8 runs") as error:
        run_campaign("fragility", jobs=1, campaign_dir=out, allow_long=False, options={
            "pulses": "pga_g=0.2:0.4:2;pgv_pga_s=0.1:1.0:2", "members": 2, "headings": 1,
            "column": "monolithic"})
    assert "\n" not in str(error.value)
    # the estimate is each run's own: pulse and tail at the per-second cost, plus a start
    per_run = [pulse_grid.run_core_s(r) for r in (0.1, 1.0)]
    assert per_run[1] - per_run[0] == pytest.approx(
        2 * math.pi * 0.9 * pulse_grid.RUN_CORE_S_PER_MOTION_S)
    assert f"{sum(per_run) * 4 / 8:.3g} core-s each" in str(error.value)
    assert not out.exists()


def test_report_section_says_not_run_yet_then_quotes_the_file(tmp_path):
    from pipeline.report import rock_fragility_section
    assert "Not run yet" in rock_fragility_section(tmp_path)
    cells = [{"pga_g": a, "pgv_pga_s": 0.5, "n": 4, "overturned": k, "P": k / 4,
              "ci95": [0.0, 1.0], "P_per_set": [k / 4], "set_sd": 0.0, "set_spread_sd": None}
             for a, k in ((0.2, 0), (0.4, 2), (0.6, 4))]
    model = {"cells": cells, "contours": pulse_summary.contours(cells),
             "logistic": {"coefficients": None}, "runs": 12, "overturned": 6}
    section = {"pga_g": [0.2, 0.4, 0.6], "pgv_pga_s": [0.5], "members": 1, "headings": 4,
               "ranges": "kn=1e8:1e8", "direction": "sampled", "runs_finished": 12, "runs": 12,
               "block2d": {"alpha_rad": 0.2, "R_m": 0.3}, "models": {"monolithic": model}}
    (tmp_path / "rock-fragility").mkdir()
    (tmp_path / "rock-fragility" / "fragility.json").write_text(json.dumps(
        {"mode": "pulses", "specimen": "box", "pulse_grid": section}))
    text = rock_fragility_section(tmp_path)
    assert text.startswith("## Scanned rock fragility") and "box:" in text
    assert "0.40 [" in text            # P = 0.5 half-way between 0.2 g (0/4) and 0.6 g (4/4)


def test_contours_interpolate_between_cells_and_say_none_beyond_the_grid():
    cells = [{"pga_g": a, "pgv_pga_s": 0.3, "P": p, "ci95": [max(p - 0.2, 0), min(p + 0.2, 1)]}
             for a, p in ((0.2, 0.0), (0.4, 0.25), (0.6, 0.75), (0.8, 1.0))]
    (row,) = pulse_summary.contours(cells, levels=(0.5,))["0.5"]
    assert row["pga_g"] == pytest.approx(0.5)
    lo, hi = row["pga_g_band"]
    assert lo < 0.5 < hi
    (row,) = pulse_summary.contours([dict(c, P=0.0, ci95=[0, 0.1]) for c in cells], (0.5,))["0.5"]
    assert row["pga_g"] is None


def test_a_column_draws_nothing_unless_told_and_a_mesh_draws_the_calibrated_ranges():
    assert pulse_grid.parse_ranges(None, mesh=False) == {}
    assert pulse_grid.parse_ranges("damping=0.1:0.2", mesh=False) == {"damping": (0.1, 0.2)}
    rock = pulse_grid.parse_ranges(None, mesh=True)
    assert set(rock) == {"kn", "damping", "mu_s", "footprint_tolerance_m", "yaw_deg"}
    assert pulse_grid.parse_ranges("damping=0.2:0.2", mesh=True)["damping"] == (0.2, 0.2)
    with pytest.raises(InputError, match="would repeat one run"):
        pulse_grid.pulse_runs(None, "monolithic", "pga_g=0.2:0.2:1;pgv_pga_s=0.5:0.5:1", 2, 1,
                              0.0, 1, None)


def test_adaptive_stages_run_cells_until_their_side_of_one_half_is_decided():
    # one PGV/PGA row of 8 PGA cells: the guide certain below cell 3 and above cell 4
    guide = {(0, j): p for j, p in enumerate((0.0, 0.0, 0.0, 0.3, 0.8, 1.0, 1.0, 1.0))}
    # uncertain cells, the certain ones next to them (a step) and one beyond
    assert pulse_adaptive.guide_cells(guide) == {(0, j) for j in range(1, 7)}
    # the first counts near it, up to one cell above where the guide reaches 0.5
    first = pulse_adaptive.first_targets(guide, per_cell=16)
    assert [first[(0, j)] for j in range(8)] == [1, 4, 4, 4, 4, 4, 1, 1]
    F, T = False, True
    seen = {(0, 0): [F], (0, 1): [F] * 4, (0, 2): [F] * 4, (0, 3): [F, T, F, F],
            (0, 4): [T, T, T, F], (0, 5): [T] * 4, (0, 6): [T], (0, 7): [T]}
    after = pulse_adaptive.next_targets(guide, seen, first, per_cell=16)
    # the contour lies between cells 3 (1 of 4) and 4 (3 of 4): both run in full; 0 of 4
    # or 4 of 4 elsewhere: the Wilson interval excludes 0.5 (upper 0.49): decided; probes
    # that agree with the guide and their neighbours stay probes
    assert [after[(0, j)] for j in range(8)] == [1, 4, 4, 16, 16, 4, 1, 1]
    # a probe that overturns where the guide is certain it stands: the first count
    assert pulse_adaptive.next_targets(guide, {**seen, (0, 0): [T]}, first, 16)[(0, 0)] == 4
    # below the contour a mixed cell doubles until its interval excludes 0.5; above it a
    # cell does not move the contour and stops; no cell passes the full grid's count
    seen = {**seen, (0, 2): [F, T, F, F], (0, 3): [F] * 4, (0, 4): [F, T, T, F]}
    after = pulse_adaptive.next_targets(guide, seen, first, per_cell=10)
    assert [after[(0, j)] for j in range(2, 6)] == [8, 10, 10, 4]
    seen = {**seen, (0, 2): [F, T] + [F] * 6}         # 1 of 8: [0.02, 0.47], decided
    assert pulse_adaptive.next_targets(guide, seen, after, per_cell=10)[(0, 2)] == 8
    # a probe that agrees with the guide but not with its neighbour: both to the first
    # count (the specimen's threshold beyond the guide's)
    guide = {(0, j): p for j, p in enumerate((0.0, 0.0, 0.0, 0.0, 1.0, 1.0))}
    assert pulse_adaptive.guide_cells(guide) == {(0, 2), (0, 3), (0, 4), (0, 5)}
    first = pulse_adaptive.first_targets(guide, per_cell=16)
    seen = {(0, 0): [F], (0, 1): [T], (0, 2): [T] * 4, (0, 3): [T] * 4, (0, 4): [T] * 4,
            (0, 5): [T] * 4}
    after = pulse_adaptive.next_targets(guide, seen, first, per_cell=16)
    assert [after[(0, j)] for j in range(6)] == [4, 4, 4, 4, 4, 4]
    # the first runs of a cell are distinct members from distinct direction sectors
    order = sorted(((m, h) for m in range(4) for h in range(4)),
                   key=lambda mh: pulse_adaptive.run_order(*mh, headings=4))
    assert order[:4] == [(0, 0), (1, 1), (2, 2), (3, 3)]


def test_adaptive_belongs_to_the_pulse_grid():
    from pipeline.campaign.fragility import FragilityOptions
    with pytest.raises(InputError, match="--adaptive belongs to the pulse grid"):
        FragilityOptions(adaptive=True)


def test_contours_per_parameter_set_show_the_members_spread():
    # set 0 crosses P = 0.5 at 0.3 g, set 1 at 0.5 g; pooled half-way
    cells = [{"pga_g": a, "pgv_pga_s": 0.3, "P": (p0 + p1) / 2, "ci95": [0, 1],
              "P_per_set": [p0, p1], "sets": [0, 1]}
             for a, p0, p1 in ((0.2, 0.0, 0.0), (0.4, 1.0, 0.0), (0.6, 1.0, 1.0))]
    (row,) = pulse_summary.contours(cells, levels=(0.5,))["0.5"]
    assert row["pga_g_per_set"] == {"0": pytest.approx(0.3), "1": pytest.approx(0.5)}
    assert row["pga_g"] == pytest.approx(0.4)


def test_a_contour_that_leaves_the_grid_is_said_on_its_side_with_its_rows():
    """A synthetic grid (PGA 0.2-0.8 g): at PGV/PGA 0.1 s P never reaches 0.5 (the contour
    lies above the grid), at 0.3 s it crosses half-way between 0.4 and 0.6 g, at 0.5 and
    0.7 s P is already 0.75 at 0.2 g (below the grid)."""
    rows = {0.1: (0.0, 0.0, 0.25, 0.25), 0.3: (0.0, 0.25, 0.75, 1.0),
            0.5: (0.75, 1.0, 1.0, 1.0), 0.7: (0.75, 0.75, 1.0, 1.0)}
    cells = [{"pga_g": a, "pgv_pga_s": ratio, "P": p, "ci95": [max(p - 0.3, 0), min(p + 0.3, 1)]}
             for ratio, ps in rows.items() for a, p in zip((0.2, 0.4, 0.6, 0.8), ps)]
    contour = pulse_summary.contours(cells, levels=(0.5,))["0.5"]
    assert [r["outside_grid"] for r in contour] == ["above", None, "below", "below"]
    assert [r["pga_g"] for r in contour] == [None, pytest.approx(0.5), None, None]
    warnings = pulse_summary.contour_warnings({"monolithic": {"contours": {"0.5": contour}}},
                                           [0.2, 0.4, 0.6, 0.8])
    assert len(warnings) == 2
    below, above = warnings
    assert below.startswith("monolithic: the P = 0.5 contour lies below the grid's lowest "
                            "PGA (0.2 g) for PGV/PGA 0.5, 0.7 s")
    assert above.startswith("monolithic: the P = 0.5 contour lies above the grid's highest "
                            "PGA (0.8 g) for PGV/PGA 0.1 s")
    inside = [dict(c, P=min(1.0, (c["pga_g"] - 0.2) / 0.6)) for c in cells]
    held = pulse_summary.contours(inside, levels=(0.16, 0.5, 0.84))
    assert pulse_summary.contour_warnings({"m": {"contours": held}}, [0.2, 0.4, 0.6, 0.8]) == []
    (one,) = pulse_summary.contours([c for c in cells if c["pgv_pga_s"] == 0.5
                                  and c["pga_g"] == 0.2], levels=(0.5,))["0.5"]
    assert one["outside_grid"] is None        # a single PGA has no contour to leave


def test_members_span_the_calibration_grid():
    """The fragility's default member ranges are the one declaration's, and they sit in the
    shake-table calibration's neighbourhood: damping spans the grid's two values, the
    footprint starts at the calibration's 1 mm and stays within the grid's span, mu_s
    lies about the calibration's choice of 0.7, the yaw about the stated orientation."""
    from pipeline.campaign import member_ranges, shake_table_experiments
    points = shake_table_experiments.parse_grid(shake_table_experiments.DEFAULT_GRID)
    ranges = pulse_grid.parse_ranges("")
    assert ranges == member_ranges.by_name()
    assert len(points) == 2 ** 4
    tried = sorted({p["damping"] for p in points})
    assert (tried[0], tried[-1]) == ranges["damping"]
    footprints = sorted({p["footprint_tolerance_m"] for p in points})
    assert ranges["footprint_tolerance_m"][0] == footprints[0]
    assert ranges["footprint_tolerance_m"][1] <= footprints[-1]
    assert sorted({p["mu_s"] for p in points}) == [0.3, 0.7]
    assert ranges["mu_s"][0] < 0.7 < ranges["mu_s"][1]
    assert sorted({p["rotate_deg"] for p in points}) == [0.0, 180.0]
    assert ranges["yaw_deg"][0] == -ranges["yaw_deg"][1] < 0
