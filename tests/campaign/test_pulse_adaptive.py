"""The adaptive pulse grid of campaign fragility against the full grid of the same cells,
members and directions on cheap models: end to end (the run worker replaced by the 2D
rigid block of a stabler rock than the guide, so that the guide is wrong near its
threshold and the adaptive stages must widen), and its stages on a fine grid of a
threshold model (the runs saved and the contours); and the contour difference
``make bench`` reports, on constructed fragility.json dicts."""
import dataclasses
import json

import numpy as np
import pandas as pd
import pytest

from pipeline.campaign import (CAMPAIGNS, get, pulse_adaptive, pulse_block, pulse_grid,
                               pulse_summary, run_campaign)
from pipeline.campaign.fragility import FragilityOptions, drive
from pipeline.hazard.fragility.file import FragilityFile, read_fragility_file
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.outcome.summary import ColumnOutcome, RunSummary
from pipeline.rocking.sampled import rocking_response_sampled
from pipeline.stats.ensemble import wilson_interval
from tests.campaign.test_pulse_grid import box_description

WIDER = 2.0         # the model's base is this much wider than the guide's: a stabler rock


def stabler_block_worker(spec, run_dir):
    """Worker: the 2D block of the run's height and WIDER x its width under the run's
    pulse, written as the run's summary (the specimen's one column)."""
    height, width = pulse_block.block_of(spec.params, spec.tags.azimuth_deg)
    pulse = one_cosine_pulse(spec.tags.pga_g * pulse_grid.G, spec.tags.pgv_pga_s, 0.0,
                             pulse_grid.PULSE_DT_S, 0.0)
    fell = bool(rocking_response_sampled(height, WIDER * width, pulse.acc[:, 1], pulse.dt,
                                         t_after=30.0, max_step=1e-3)["overturned"][0])
    column = ColumnOutcome(column="box", toppled=fell,
                           downfall_azimuth_deg=spec.tags.azimuth_deg if fell else None)
    RunSummary(record=spec.record_id, columns=[column]).save(run_dir / "summary.json")


def test_the_adaptive_surface_matches_the_full_grid_with_fewer_runs(tmp_path, monkeypatch):
    monkeypatch.setitem(CAMPAIGNS, "fragility", dataclasses.replace(
        get("fragility"), worker=stabler_block_worker))
    (tmp_path / "box.json").write_text(json.dumps(box_description(tmp_path)))
    given = {"column_file": str(tmp_path / "box.json"),
             "pulses": "pga_g=0.1:1.0:10;pgv_pga_s=0.2:0.6:2", "members": 2, "headings": 2,
             "ranges": "kn=1e8:1e8;damping=0.1:0.1;mu_s=0.8:0.8;"
                       "footprint_tolerance_m=0.001:0.004"}
    summaries = {}
    for mode in ("full", "adaptive"):       # as the command line runs them
        out = tmp_path / mode
        options = FragilityOptions(**given, adaptive=mode == "adaptive").kwargs()
        drive(lambda opts, out=out: run_campaign("fragility", jobs=1, campaign_dir=out,
                                                 options=opts), [], out, options)
        summaries[mode] = read_fragility_file(out)
    full, adaptive = (summaries[m].pulse_grid for m in ("full", "adaptive"))
    assert full.runs_finished == full.full_grid_runs == 10 * 2 * 2 * 2
    assert adaptive.runs_finished < full.runs_finished
    # the model is stabler than the guide: somewhere a probe disagreed and a cell the guide
    # called certain was run in full (the driver's widening, not only its first stage)
    guide = {(c.pgv_pga_s, c.pga_g): c.P for c in full.models["block2d"].cells}
    rock = {(c.pgv_pga_s, c.pga_g): c for c in adaptive.models["box"].cells}
    assert any(guide[k] in (0.0, 1.0) and c.n > 1 and c.P != guide[k]
               for k, c in rock.items())
    difference = pulse_summary.contour_difference(summaries["full"], summaries["adaptive"])
    crossing = [r for r in difference["rows"] if r["pga_g_reference"] is not None]
    assert len(crossing) == 2                      # the threshold lies inside the grid
    print(difference, adaptive.runs_finished)
    assert difference["within_band"]
    assert difference["max_abs_diff_g"] == pytest.approx(0.0, abs=1e-9)


def fragility(rows):
    """A fragility file of one specimen model with the given P = 0.5 contour rows
    (pgv_pga_s, pga_g, band lo, band hi)."""
    contour = [{"pgv_pga_s": r, "pga_g": a, "pga_g_band": [lo, hi]} for r, a, lo, hi in rows]
    return FragilityFile.of({"pulse_grid": {"models": {"block2d": {"contours": {"0.5": []}},
                                                       "rock": {"contours": {"0.5": contour}}}}})


def test_contour_difference_on_constructed_contours():
    full = fragility([(0.1, 0.40, 0.35, 0.45), (0.3, 0.25, 0.20, None), (0.5, None, 0.5, None)])
    same = pulse_summary.contour_difference(full, full)
    assert same["max_abs_diff_g"] == 0.0 and same["within_band"] and same["one_sided"] == 0
    other = fragility([(0.1, 0.43, 0, 1), (0.3, 0.19, 0, 1), (0.5, None, 0, 1)])
    d = pulse_summary.contour_difference(full, other)
    assert [r["diff_g"] for r in d["rows"][:2]] == [pytest.approx(0.03), pytest.approx(-0.06)]
    assert d["rows"][2]["diff_g"] is None
    assert d["max_abs_diff_g"] == pytest.approx(0.06)
    assert not d["within_band"]                    # 0.19 g lies below the band 0.20 g - open
    inside = fragility([(0.1, 0.43, 0, 1), (0.3, 0.9, 0, 1), (0.5, None, 0, 1)])
    assert pulse_summary.contour_difference(full, inside)["within_band"]   # an open upper side
    one_sided = fragility([(0.1, 0.43, 0, 1), (0.3, 0.25, 0, 1), (0.5, 0.7, 0, 1)])
    d = pulse_summary.contour_difference(full, one_sided)
    assert d["one_sided"] == 1 and not d["within_band"]
    with pytest.raises(ValueError, match="same pulse grid"):
        pulse_summary.contour_difference(full, fragility([(0.1, 0.4, 0, 1)]))


def threshold_model(pga_g, ratios, members, headings, seed, bias=1.0):
    """A cheap stand-in for the rock: run (cell, member, heading) overturns when the PGA
    reaches a threshold (g) that falls with PGV/PGA, varies with the direction (a rock
    wider one way than the other: +-20 %), with the member (lognormal, 15 %) and run to
    run (5 %); ``bias`` scales the direction-only threshold instead (the guide: a body
    less stable than the rock, as the 2D block may be). Returns cell -> outcomes in
    :func:`pulse_adaptive.run_order`."""
    rng = np.random.default_rng(seed)
    azimuths = pulse_grid.member_azimuths(members, headings, seed)
    member_z, run_z = rng.standard_normal(members), rng.standard_normal(
        (len(ratios), len(pga_g), members, headings))
    order = sorted(((m, h) for m in range(members) for h in range(headings)),
                   key=lambda mh: pulse_adaptive.run_order(*mh, headings))
    outcomes = {}
    for i, ratio in enumerate(ratios):
        base = 0.25 + 0.5 * np.exp(-ratio / 0.15)
        for j, pga in enumerate(pga_g):
            fell = []
            for m, h in order:
                threshold = base * (1 + 0.2 * np.cos(np.radians(2 * azimuths[m, h])))
                threshold *= bias if bias != 1.0 else np.exp(0.15 * member_z[m]
                                                             + 0.05 * run_z[i, j, m, h])
                fell.append(bool(pga >= threshold))
            outcomes[(i, j)] = fell
    return outcomes, order


def model_summary(outcomes, order, runs, pga_g, ratios):
    """A fragility file of the model's first ``runs[cell]`` runs per cell."""
    rows = [{"model": "rock", "pga_g": pga_g[j], "pgv_pga_s": ratios[i], "member": m,
             "toppled": fell[r]}
            for (i, j), fell in outcomes.items() for r, (m, _) in enumerate(order[:runs[(i, j)]])]
    cells = pulse_summary.cell_table(pd.DataFrame(rows), "rock")
    return FragilityFile.of({"pulse_grid": {"models": {"rock": {
        "cells": cells, "contours": pulse_summary.contours(cells)}}}})


def test_the_adaptive_stages_save_five_times_the_runs_on_a_fine_grid_of_a_cheap_model():
    """A 30 x 10 cell grid (PGA 0.05 g apart), 8 members x 4 directions: the adaptive
    stages against the full grid of the same cells, members and directions, on a
    threshold model with a biased guide. Goal: at least 5 times fewer runs, every P = 0.5
    crossing inside the full grid's Monte Carlo band, each cell's side of 0.5 the full
    grid's wherever the full grid itself is sure of it."""
    pga_g, ratios = np.round(np.linspace(0.05, 1.5, 30), 6), np.round(np.linspace(0.1, 1, 10), 6)
    members, headings = 8, 4
    per_cell = members * headings
    outcomes, order = threshold_model(pga_g, ratios, members, headings, seed=3)
    guide, _ = threshold_model(pga_g, ratios, members, headings, seed=3, bias=0.8)
    guide_p = {cell: float(np.mean(fell)) for cell, fell in guide.items()}
    stages = []

    def run_stage(stage, targets):
        stages.append(stage)
        return {cell: fell[:targets[cell]] for cell, fell in outcomes.items()}

    targets, settled = pulse_adaptive.adaptive_sampling(guide_p, per_cell, run_stage)
    assert settled and len(stages) >= 3
    full_runs = len(outcomes) * per_cell
    assert full_runs / sum(targets.values()) >= 5.0
    full = model_summary(outcomes, order, {c: per_cell for c in outcomes}, pga_g, ratios)
    adaptive = model_summary(outcomes, order, targets, pga_g, ratios)
    difference = pulse_summary.contour_difference(full, adaptive)
    assert all(r["pga_g_reference"] is not None for r in difference["rows"])  # inside the grid
    assert difference["within_band"]
    print(f"{full_runs} / {sum(targets.values())} runs, largest 0.5 contour difference "
          f"{difference['max_abs_diff_g']} g")
    # the statistics say what was run: a cell's n is its runs, its interval Wilson's of them
    full_cells = {(list(ratios).index(c.pgv_pga_s), list(pga_g).index(c.pga_g)): c
                  for c in full.pulse_grid.models["rock"].cells}
    top = pulse_adaptive.first_crossings({cell: c.P for cell, c in full_cells.items()})
    for cell in adaptive.pulse_grid.models["rock"].cells:
        i, j = list(ratios).index(cell.pgv_pga_s), list(pga_g).index(cell.pga_g)
        assert cell.n == targets[(i, j)]
        assert cell.ci95 == pytest.approx(wilson_interval(cell.overturned, cell.n))
        # up to the contour (above it cells stop: they do not move it), each cell's side
        # of 0.5 is the full grid's wherever the full grid is sure of it
        sure = full_cells[(i, j)]
        if j <= top[i] and not sure.ci95[0] <= 0.5 <= sure.ci95[1]:
            assert (cell.P >= 0.5) == (sure.P >= 0.5)
