"""The inversion's reach: no candidate beyond the forward table's last ring of a site, and a
hidden source beyond the reach (or between the rings) either held by the 95 % regions or
said to lie beyond.

The toy physics: every fallen column falls away from the source, and the share of columns
that fall is 2.5 km / r (1 at 2.5 km, 1/2 at 5, 1/4 at 10, 1/6.4 at 16 km); the table holds
it at the rings 2.5, 5 and 10 km, the hidden sources' columns follow it at their own
distances."""
import json
import math

import numpy as np
import pytest

from pipeline import cli
from pipeline.files import InputError
from pipeline.inversion import truth_check, workflows
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import parse_observations
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.posterior import EDGE_BAYES_FACTOR, invert
from tests.refusal import refused

RINGS = (2.5, 5.0, 10.0)
MEMBERS = 8


def share_toppled(r_km):
    return min(1.0, 2.5 / r_km)


@pytest.fixture
def table(make_away_table):
    return make_away_table(members=MEMBERS, p_fall=[share_toppled(r) for r in RINGS],
                           distances=RINGS)


def hidden_source(truth, sites, columns=12, share=share_toppled):
    """Observations of ``columns`` columns per site {name: (e, n)} of a source at
    ``truth``: round(columns x share(distance km)) fall away from it, the others stand."""
    out = []
    for name, (e, n) in sites.items():
        r = math.hypot(e - truth[0], n - truth[1])
        away = math.degrees(math.atan2(e - truth[0], n - truth[1])) % 360.0
        fallen = round(columns * share(r))
        out.append({"name": name, "east_km": e, "north_km": n, "columns": [
            {"column": "drums" if k % 2 else "monolithic", "state": "fallen",
             "downfall_azimuth_deg": away, "uncertainty_deg": 10} if k < fallen else
            {"column": "drums" if k % 2 else "monolithic", "state": "standing"}
            for k in range(columns)]})
    return parse_observations({"sites": out})


def check(table, truth, sites, radius_km=30.0):
    """(posterior, summary, truth check) of the hidden source ``truth`` seen at ``sites``
    (truth and sites km East/North; the inversion's frame is the first site's)."""
    e0, n0 = next(iter(sites.values()))
    observations = hidden_source(truth, sites)
    post = invert(ForwardModel(table), observations, CandidateGrid(radius_km=radius_km,
                                                                   step_km=1.0))
    e, n = truth[0] - e0, truth[1] - n0
    summary = post.summary()
    return post, summary, truth_check(post, {
        "epicentre_km": [e, n], "distance_km": math.hypot(e, n),
        "back_azimuth_deg": math.degrees(math.atan2(e, n)) % 360.0,
        "mechanism": "strike-slip", "mw": 6.5}, summary)


def test_no_candidate_lies_beyond_the_last_ring_of_a_site(table):
    sites = {"A": (0.0, 0.0), "B": (8.0, 3.0)}
    post, summary, _ = check(table, (4.0, 12.0), sites)
    for e, n in sites.values():
        assert np.hypot(post.east_km - (e - 0.0), post.north_km - (n - 0.0)).max() <= 10.0
    # the candidates asked for: every cell within 30 km of a site; those beyond 10 km of
    # either site are left out, and their share is said
    asked = CandidateGrid(radius_km=30.0, step_km=1.0).lattice(hidden_source((4.0, 12.0),
                                                                             sites))[0].size
    assert post.info["beyond_table_fraction"] == pytest.approx(1 - post.east_km.size / asked)
    assert summary["reach_km"] == 10.0
    # the edge's mass is the posterior summed over the outermost cells: cells with a
    # lattice neighbour 1 km away (East, West, North or South) that is not a candidate
    cells = {(round(e, 6), round(n, 6)) for e, n in zip(post.east_km, post.north_km)}
    outer = [any((round(e + de, 6), round(n + dn, 6)) not in cells
                 for de, dn in ((1, 0), (-1, 0), (0, 1), (0, -1)))
             for e, n in zip(post.east_km, post.north_km)]
    assert summary["reach_edge_fraction"] == pytest.approx(post.epicentre[outer].sum())


def test_a_source_beyond_the_last_ring_is_said_to_lie_beyond(table):
    """Two sites 14 and 17 km from the source, 4 km apart: the table's rings end at 10 km,
    so no candidate holds the truth; few columns fell, the candidates' posterior piles
    against the reach's edge and the summary says the source may lie farther; the shell
    beyond the reach holds it."""
    truth = (0.0, 0.0)
    sites = {"A": (0.0, 14.0), "B": (8.0, 15.0)}
    post, summary, found = check(table, truth, sites)
    assert not found["within_reach"]
    assert summary["reach_edge_bayes_factor"] > EDGE_BAYES_FACTOR
    assert summary["reach_edge_fraction"] > summary["reach_edge_prior_fraction"]
    assert "may lie farther" in summary["reach_warning"]
    # no direction from the reach's edge: the whole circle, the edge's arc kept apart
    assert not summary["direction_reliable"] and summary["back_azimuth_map_deg"] is None
    assert summary["back_azimuth_ci95_deg"] == [0.0, 360.0] and found["back_azimuth_in_95"]
    assert summary["back_azimuth_within_reach"]["back_azimuth_ci95_width_deg"] < 360.0
    assert found["distance_in_95_or_warned"] and found["epicentre_in_95_or_warned"]
    # no candidate can hold it; the shell beyond the reach does, and says how likely it is
    assert summary["beyond_in_95"] and summary["p_beyond"] > 0.1
    assert found["distance_in_95"] and found["epicentre_in_95"]


def test_a_source_between_the_rings_is_held_by_the_regions(table):
    """Sites 7 and 3.5 km from the source (between the rings 5 and 10, and 2.5 and 5):
    the 95 % regions hold the epicentre and the distance without a warning."""
    truth = (0.0, 0.0)
    sites = {"A": (7.0, 0.0), "B": (-2.0, -3.0), "C": (0.0, 7.0)}
    _, summary, found = check(table, truth, sites)
    assert found["within_reach"]
    assert found["epicentre_in_95"] and found["distance_in_95"]
    assert summary["reach_warning"] is None


def test_sites_too_far_apart_for_the_table_are_one_line(table):
    observations = hidden_source((12.0, 5.0), {"A": (0.0, 0.0), "B": (25.0, 0.0)})
    with pytest.raises(InputError, match="sites A and B lie 25.0 km apart, but the forward "
                                         "table's rings end at 10 km"):
        invert(ForwardModel(table), observations, CandidateGrid(radius_km=30, step_km=1))


def test_invert_warns_when_the_source_may_lie_beyond(table, tmp_path, capsys):
    """The command's outputs: the reach's keys in inversion_summary.json, a warning line
    (the independent likelihood: one site's 12 columns read as 12 draws, sharp enough to
    put the posterior on the edge; the predictive reads them as a few)."""
    path = table.save(tmp_path / "toy.npz")
    observations = tmp_path / "far.json"
    observations.write_text(json.dumps(hidden_source((0.0, 0.0), {"A": (0.0, 16.0)}).as_dict()))
    out = tmp_path / "out"
    assert cli.main(["invert", str(observations), "--table", str(path), "--out", str(out),
                     "--radius", "30", "--step", "1", "--likelihood", "independent"]) == 0
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert summary["reach_km"] == 10.0 and summary["table_last_ring_km"] == 10.0
    assert summary["beyond_table_fraction"] > 0.8          # 10 of 30 km: 1 - 1/9 of the area
    assert summary["reach_edge_bayes_factor"] > EDGE_BAYES_FACTOR
    printed = capsys.readouterr().out
    assert f"warning: {summary['reach_warning']}" in printed
    assert (f"{summary['beyond_table_fraction']:.0%} of the epicentres within --radius 30 km "
            "of a site lie beyond") in printed


def test_a_region_thinner_than_a_cell_is_one_line(table):
    """Sites 19 km apart: the points within 10 km of both form a lens 1 km wide (9 to 10 km
    East of A) and 6.2 km long, between the cell centres of a 3 km grid (1.5, 4.5, 7.5,
    10.5 km East); a 0.5 km grid has cells in it."""
    observations = hidden_source((9.5, 1.0), {"A": (0.0, 0.0), "B": (19.0, 0.0)})
    with pytest.raises(InputError, match=r"no cell of the candidate grid \(--step 3 km, "
                                         r"--radius 30 km\) lies within the forward table's "
                                         r"last ring \(10 km\) of every site"):
        invert(ForwardModel(table), observations, CandidateGrid(radius_km=30, step_km=3))
    finer = invert(ForwardModel(table), observations, CandidateGrid(radius_km=30, step_km=0.5))
    assert finer.east_km.size > 0


def refuses_hidden_truth(table, tmp_path, capsys, sites, words):
    """invert --hidden-truth with ``sites`` ((name, east km, north km, twins)) and a
    toy table: one line holding ``words``, exit 2, nothing written."""
    path = table.save(tmp_path / "toy.npz")
    truth = tmp_path / "truth.json"
    truth.write_text(json.dumps({
        "source": {"mechanism": "strike-slip", "strike_deg": 30, "depth_km": 10, "mw": 6.5,
                   "east_km": 0, "north_km": 0},
        "sites": [{"name": name, "east_km": e, "north_km": n, "twins": twins}
                  for name, e, n, twins in sites]}))
    out = tmp_path / "out"
    refused(capsys, ["invert", "--hidden-truth", truth, "--table", path, "--out", out], words,
            out)


def test_a_hidden_truth_out_of_reach_is_refused_before_any_run(table, tmp_path, capsys):
    """invert --hidden-truth with sites 26 km apart and a table whose rings end at 10 km:
    one line, exit 2, before pyprop8 or YADE, nothing written."""
    refuses_hidden_truth(table, tmp_path, capsys, [("A", -13, 0, 1), ("B", 13, 0, 1)],
                         "sites A and B lie 26.0 km apart")


def test_a_hidden_truth_with_two_sites_at_one_place_is_refused_before_any_run(
        table, tmp_path, capsys, monkeypatch):
    """Two sites of a truth file at one place: one line, exit 2, no campaign run (pyprop8
    or YADE) and nothing written."""
    def no_run(*args, **kwargs):
        raise AssertionError("a campaign ran")
    monkeypatch.setattr(workflows, "run_campaign", no_run)
    refuses_hidden_truth(table, tmp_path, capsys, [("A", 3, 1, 1), ("B", 3, 1, 2)],
                         "sites A and B are at the same place")


def test_edge_bayes_factor_is_a_finite_number_at_the_ends():
    """All the posterior in the outermost cells: a large finite factor (JSON holds it);
    every candidate an outermost cell: the data cannot favour them, factor 1."""

    from pipeline.inversion.posterior import edge_bayes_factor
    assert math.isfinite(edge_bayes_factor(1.0, 0.3))
    assert edge_bayes_factor(1.0, 0.3) > EDGE_BAYES_FACTOR
    assert edge_bayes_factor(1.0, 1.0) == 1.0
    assert edge_bayes_factor(0.5, 0.5) == 1.0
    assert edge_bayes_factor(0.0, 0.3) == 0.0


def test_a_point_on_the_reachs_edge_belongs_to_its_nearest_candidate_cell(table):
    """One site, the reach 10 km, cells of 1 km centred at odd half-kilometres: the point
    (7.05, 7.03) km lies 9.96 km from the site, inside the reach, but its cell's centre
    (7.5, 7.5) lies 10.6 km away and is no candidate; it belongs to the nearest candidate,
    (7.5, 6.5) (9.92 km).
    The point (7.2, 7.2), 10.18 km away, lies beyond the reach: in no candidate cell, but
    in the shell beyond it (10-20 km).  With the whole posterior as the region (level 1)
    both are held; a point 30 km away, beyond the shell too, is not."""
    observations = hidden_source((0.0, 3.0), {"A": (0.0, 0.0)})
    post = invert(ForwardModel(table), observations, CandidateGrid(radius_km=12, step_km=1))
    cells = set(zip(np.round(post.east_km, 3), np.round(post.north_km, 3)))
    assert (7.5, 7.5) not in cells and {(6.5, 7.5), (7.5, 6.5)} <= cells
    assert post.contains(7.05, 7.03, level=1.0)
    k = post.cell_of(7.2, 7.2)
    assert max(abs(post.east_km[k] - 7.2), abs(post.north_km[k] - 7.2)) > 0.5
    assert post.beyond.cell_of(7.2, 7.2) is not None and post.contains(7.2, 7.2, level=1.0)
    assert not post.contains(30.0, 0.0, level=1.0)              # beyond the shell
