"""Posterior: rotational symmetry, concentration on the truth, credible arcs and regions."""
import math

import numpy as np
import pytest

from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import parse_observations
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.credible import arc_width, circular_credible, in_arc
from pipeline.inversion.posterior import invert


def observations_away_from(truth, sites, per_site=3, spread=0.0):
    """Columns at ``sites`` {name: (e, n)} that fell away from the epicentre ``truth``."""
    out = []
    for name, (e, n) in sites.items():
        away = math.degrees(math.atan2(e - truth[0], n - truth[1])) % 360.0
        cols = [{"column": "drums" if k % 2 else "monolithic", "state": "fallen",
                 "downfall_azimuth_deg": (away + spread * (k - 1)) % 360.0,
                 "uncertainty_deg": 10} for k in range(per_site)]
        out.append({"name": name, "east_km": e, "north_km": n, "columns": cols})
    return parse_observations({"sites": out})


def test_turning_everything_by_90_deg_turns_the_posterior(toy_random):
    data = {"sites": [
        {"name": "A", "east_km": 0, "north_km": 0, "columns": [
            {"column": "drums", "state": "fallen", "downfall_azimuth_deg": 240},
            {"column": "monolithic", "state": "standing"}]},
        {"name": "B", "east_km": 6, "north_km": -2, "columns": [
            {"column": "monolithic", "state": "fallen", "downfall_azimuth_deg": 33,
             "uncertainty_deg": 20}]},
        {"name": "C", "east_km": -3, "north_km": 7, "columns": [
            {"column": "drums", "state": "standing"},
            {"column": "drums", "state": "fallen", "downfall_azimuth_deg": 111}]}]}
    obs = parse_observations(data)
    grid = CandidateGrid(radius_km=15, step_km=1.5, strike_step_deg=30)
    model = ForwardModel(toy_random)
    post = invert(model, obs, grid)
    turned = invert(model, obs.turned(90.0), grid)
    assert turned.probability.shape == post.probability.shape
    # cell (E, N) -> (N, -E); strike index + 3 (90 / 30)
    lookup = {(round(e, 6), round(n, 6)): k for k, (e, n) in
              enumerate(zip(turned.east_km, turned.north_km))}
    index = np.array([lookup[(round(n, 6), round(-e, 6))]
                      for e, n in zip(post.east_km, post.north_km)])
    expected = np.roll(post.probability, 3, axis=1)
    np.testing.assert_allclose(turned.probability[:, :, index], expected, rtol=1e-9,
                               atol=1e-15)
    a, b = post.summary(), turned.summary()
    assert b["credible_area_95_km2"] == a["credible_area_95_km2"]
    assert (b["back_azimuth_map_deg"] - a["back_azimuth_map_deg"]) % 360 == \
        pytest.approx(90.0, abs=2.0)
    for x, y in zip(a["back_azimuth_ci95_deg"], b["back_azimuth_ci95_deg"]):
        assert (y - x) % 360 == pytest.approx(90.0, abs=2.0)
    assert b["mechanism_posterior"] == pytest.approx(a["mechanism_posterior"])


def test_falls_away_from_the_source_find_its_back_azimuth(toy_away):
    truth = (-6.0, 8.0)                       # back azimuth from site A: 323.1 deg
    true_baz = math.degrees(math.atan2(*truth)) % 360
    obs = observations_away_from(truth, {"A": (0.0, 0.0)}, per_site=4)
    post = invert(ForwardModel(toy_away), obs, CandidateGrid(radius_km=25, step_km=1))
    s = post.summary()
    assert abs((s["back_azimuth_map_deg"] - true_baz + 180) % 360 - 180) < 6
    assert in_arc(true_baz, s["back_azimuth_ci68_deg"])
    assert s["back_azimuth_ci95_width_deg"] <= 60     # within +-30 deg
    # one site cannot tell the distance: the 95 % interval reaches beyond the reach
    # (the shell beyond it in the region) and is open above
    assert s["beyond_in_95"] and s["distance_ci95_unbounded"]
    assert s["distance_ci95_km"][1] is None and s["distance_ci95_km"][0] < 10


def test_three_sites_locate_the_epicentre(toy_away):
    truth = (-6.0, 8.0)
    obs = observations_away_from(truth, {"A": (0.0, 0.0), "B": (5.0, -3.0),
                                         "C": (-12.0, -2.0)}, per_site=2)
    grid = CandidateGrid(radius_km=25, step_km=1)
    post = invert(ForwardModel(toy_away), obs, grid)
    s = post.summary()
    assert math.hypot(s["map_epicentre_km"][0] - truth[0],
                      s["map_epicentre_km"][1] - truth[1]) < 2.5
    assert post.contains(*truth, level=0.95)
    asked = grid.lattice(obs)[0].size                # cells within the radius of a site
    assert s["credible_area_95_km2"] < 0.15 * asked
    assert post.probability.sum() == pytest.approx(1.0)


def test_standing_columns_alone_say_little(toy_away):
    obs = parse_observations({"sites": [{"name": "A", "east_km": 0, "north_km": 0, "columns": [
        {"column": "drums", "state": "standing"}]}]})
    s = invert(ForwardModel(toy_away), obs, CandidateGrid(radius_km=20, step_km=2)).summary()
    assert s["back_azimuth_ci95_width_deg"] > 300


def test_mechanism_prior_and_candidate_subset(toy_away):
    obs = observations_away_from((3.0, 4.0), {"A": (0.0, 0.0)})
    grid = CandidateGrid(radius_km=10, step_km=2, mechanism_prior={"strike-slip": 3,
                                                                    "thrust": 1})
    s = invert(ForwardModel(toy_away), obs, grid).summary()
    # the toy's mechanisms explain the falls equally: the posterior is the prior
    assert s["mechanism_posterior"]["strike-slip"] == pytest.approx(0.75, abs=1e-6)
    only = invert(ForwardModel(toy_away), obs, CandidateGrid(radius_km=10, step_km=2,
                                                               mechanisms=("thrust",)))
    assert only.summary()["mechanism_posterior"] == {"thrust": pytest.approx(1.0)}


def test_circular_credible_wraps_and_splits():
    bins = np.zeros(180)                    # 2 deg bins
    bins[[178, 179, 0, 1]] = [0.2, 0.3, 0.3, 0.2]
    arc, arcs = circular_credible(bins, 2.0, 0.95)
    assert arc == [356.0, 4.0] and arcs == [[356.0, 4.0]]
    assert arc_width(arc) == 8.0 and in_arc(359.0, arc) and not in_arc(10.0, arc)
    two = np.zeros(180)
    two[[10, 100]] = [0.5, 0.5]             # toward and away: two modes 180 deg apart
    arc, arcs = circular_credible(two, 2.0, 0.95)
    assert arcs == [[20.0, 22.0], [200.0, 202.0]]
    assert arc_width(arc) == pytest.approx(182.0)
    assert circular_credible(np.ones(180), 2.0, 0.999)[0] == [0.0, 360.0]


def test_distance_interval_is_the_shortest_holding_the_level():
    """Mass piled toward the candidates' last distance: the 95 % interval reaches it (equal
    tails would stop short), holds 95 % and no shorter interval does (checked against every
    interval between the sub-grid's distances)."""
    from pipeline.inversion.posterior import SUBGRID, Posterior
    east = np.arange(0.5, 10.0, 1.0)
    loglike = np.log(east ** 3)[None, None, :]
    post = Posterior([{"mechanism": "m", "mw": 6.0, "depth_km": 10.0, "dip_deg": 90.0,
                       "rake_deg": 0.0}], np.array([0.0]), east, np.zeros_like(east), 1.0,
                     np.zeros(loglike.shape), loglike)
    lo, hi = post.distance_interval(0.95)
    offsets = (np.arange(SUBGRID) + 0.5) / SUBGRID - 0.5
    ox, oy = np.meshgrid(offsets, offsets)
    dist = np.hypot(east[:, None] + ox.ravel()[None, :], oy.ravel()[None, :]).ravel()
    mass = np.repeat(east ** 3 / (east ** 3).sum() / SUBGRID ** 2, SUBGRID ** 2)

    def held(a, b):
        return mass[(dist >= a - 1e-12) & (dist <= b + 1e-12)].sum()

    assert hi == pytest.approx(dist.max())
    assert held(lo, hi) >= 0.95 - 1e-9
    values = np.unique(dist)
    best = min(b - a for a in values for b in values[values >= a]
               if held(a, b) >= 0.95 - 1e-9)
    assert hi - lo == pytest.approx(best)
