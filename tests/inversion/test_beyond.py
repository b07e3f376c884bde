"""The test of the sources beyond the reach: the table's decay with distance carried past
its last ring in closed form, a source beyond the reach warned about (with no direction),
a source well within it not, and nothing of the test in the posterior.

The toy physics of tests/inversion/test_reach.py: every fallen column falls away from the
source, a share 2.5 km / r of the columns falls; the table holds it at 2.5, 5 and 10 km."""
import math

import numpy as np
import pytest
from scipy.special import expit, logit

from pipeline.inversion.beyond import BEYOND_BAYES_FACTOR, PRIOR_BEYOND, SHELL_FACTOR, SHELL_STEP, shell_lattice
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.posterior import invert
from tests.inversion.test_reach import MEMBERS, RINGS, check, hidden_source, share_toppled


@pytest.fixture
def table(make_away_table):
    return make_away_table(members=MEMBERS, p_fall=[share_toppled(r) for r in RINGS],
                           distances=RINGS)


def test_p_beyond_the_last_ring_carries_on_the_log_odds_slope_of_the_last_two(table):
    """At 16 and 40 km: P of the 10 km ring (k = 2 of 8: (2 + 1/2) / 9) carried on along
    the log-odds slope from the 5 km ring (k = 4: 1/2) in ln r; at the ring itself P."""
    model = ForwardModel(table)
    p5, p10 = 4.5 / 9, 2.5 / 9
    slope = (logit(p10) - logit(p5)) / math.log(2.0)
    for r in (10.0, 16.0, 40.0):
        factor = model.decay(0, np.array([math.log(r / 10.0)]))
        expected = expit(logit(p10) + slope * math.log(r / 10.0))
        assert factor * p10 == pytest.approx(np.full(factor.shape, expected), rel=1e-12)
    # the toy's own share at 20 km is 1/8: the carried-on P comes near it
    assert model.decay(0, np.array([math.log(2.0)]))[0, 0, 0] * p10 == pytest.approx(
        share_toppled(20.0), abs=0.01)


def test_p_never_rises_beyond_the_last_ring(make_away_table):
    """A table whose P rises from the 5 to the 10 km ring keeps the 10 km ring's P beyond."""
    rising = make_away_table(members=MEMBERS, p_fall=[1.0, 0.25, 0.5], distances=RINGS)
    factor = ForwardModel(rising).decay(0, np.array([0.0, math.log(3.0)]))
    assert factor == pytest.approx(np.ones(factor.shape))


def test_a_source_beyond_the_reach_is_warned_about_by_the_shell(table):
    """Sites 14 and 17 km from the source (beyond the 10 km ring, within the shell of 10 to
    20 km): the falls are likelier from the shell than from the candidates, the summary
    warns and gives no direction."""
    _, summary, found = check(table, (0.0, 0.0), {"A": (0.0, 14.0), "B": (8.0, 15.0)})
    assert not found["within_reach"]
    assert summary["beyond_shell_km"] == [10.0, SHELL_FACTOR * 10.0]
    assert summary["beyond_bayes_factor"] > BEYOND_BAYES_FACTOR and summary["beyond_warning"]
    assert "likely from a source beyond the reach" in summary["reach_warning"]
    assert not summary["direction_reliable"] and summary["back_azimuth_map_deg"] is None


def test_a_source_well_within_the_reach_is_not(table):
    """Sites 7, 3.6 and 7 km from the source: the shell explains the falls worse than the
    candidates; no warning, and the posterior is what the candidates alone give."""
    sites = {"A": (7.0, 0.0), "B": (-2.0, -3.0), "C": (0.0, 7.0)}
    post, summary, found = check(table, (0.0, 0.0), sites)
    assert found["within_reach"]
    assert summary["beyond_bayes_factor"] < BEYOND_BAYES_FACTOR
    assert not summary["beyond_warning"] and summary["reach_warning"] is None
    model = ForwardModel(table)
    alone = model.log_likelihood(hidden_source((0.0, 0.0), sites), post.east_km,
                                 post.north_km, post.strikes_deg)
    assert post.log_likelihood == pytest.approx(alone, abs=0)


def test_the_shell_lies_beyond_the_last_ring_of_some_site_and_within_twice_it(table):
    observations = hidden_source((3.0, 4.0), {"A": (0.0, 0.0), "B": (6.0, 0.0)})
    east, north, step = shell_lattice(observations, CandidateGrid(radius_km=30, step_km=1),
                                      10.0)
    assert step == 2.0
    farthest = np.maximum(np.hypot(east, north), np.hypot(east - 6.0, north))
    assert east.size and (farthest > 10.0).all() and (farthest <= 20.0 + 1e-9).all()


def test_a_table_of_one_ring_has_no_decay_to_carry_and_no_test(make_away_table):
    one = make_away_table(members=MEMBERS, p_fall=[0.5], distances=(10.0,))
    observations = hidden_source((0.0, 0.0), {"A": (0.0, 14.0)})
    summary = invert(ForwardModel(one), observations,
                     CandidateGrid(radius_km=30, step_km=1)).summary()
    assert summary["beyond_bayes_factor"] is None and not summary["beyond_warning"]


def test_one_site_says_in_a_note_that_it_cannot_tell_and_keeps_its_direction(table):
    """One site 6 km from the source: the shell about the site and the disk inside it
    explain its falls alike; no warning, a note, and the direction (the candidates are a
    disk about the site, they do not turn it) stays."""
    _, summary, found = check(table, (0.0, 0.0), {"A": (6.0, 0.0)})
    assert summary["reach_note"].startswith("one site: its falls cannot tell")
    assert summary["direction_reliable"] and found["back_azimuth_in_95"]
    _, two, _ = check(table, (0.0, 0.0), {"A": (6.0, 0.0), "B": (0.0, 6.0)})
    assert two["reach_note"] is None


def test_invert_prints_the_one_site_note_and_writes_the_tests_keys(table, tmp_path, capsys):
    import json

    from pipeline import cli
    path = table.save(tmp_path / "toy.npz")
    observations = tmp_path / "one.json"
    observations.write_text(json.dumps(hidden_source((0.0, 0.0), {"A": (6.0, 0.0)}).as_dict()))
    out = tmp_path / "out"
    assert cli.main(["invert", str(observations), "--table", str(path), "--out", str(out),
                     "--radius", "30", "--step", "1"]) == 0
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert f"note: {summary['reach_note']}" in capsys.readouterr().out
    assert summary["beyond_shell_km"] == [10.0, 20.0] and summary["beyond_warning"] is False
    assert 0 < summary["beyond_bayes_factor"] < BEYOND_BAYES_FACTOR


# ---------------------------------------------------------------- the shell in the posterior
REACH_KM = {6.0: 2.5, 7.0: 5.0}     # the toy's share that falls: min(1, R(Mw) / r)


def magnitudes_table(members=16):
    """Two magnitudes of one mechanism: a share min(1, R / r) of the columns falls away
    from the source, R 2.5 km at Mw 6 and 5 km at Mw 7 (the larger reaches twice as far:
    its falls at 2 r are the smaller one's at r); rings 2.5, 5 and 10 km."""
    from pipeline.inversion.table import ForwardTable
    slices = [("strike-slip", 90.0, 180.0, 10.0, mw) for mw in REACH_KM]
    azimuths = tuple(np.arange(0.0, 360.0, 30.0))
    falls = [[[[[theta if k < round(members * min(1.0, REACH_KM[mw] / r)) else None
                 for k in range(members)] for _ in range(2)] for theta in azimuths]
              for r in RINGS] for *_, mw in slices]
    return ForwardTable.toy(slices, RINGS, azimuths, falls)


def magnitude_source(truth, sites, mw, columns=12):
    """Observations of ``columns`` columns a site of a source of ``mw`` at ``truth``."""
    return hidden_source(truth, sites, columns, lambda r: min(1.0, REACH_KM[mw] / r))


def posterior_of(table, truth, sites, mw):
    from pipeline.inversion import truth_check
    observations = magnitude_source(truth, sites, mw)
    post = invert(ForwardModel(table), observations, CandidateGrid(radius_km=30, step_km=1))
    e0, n0 = next(iter(sites.values()))
    e, n = truth[0] - e0, truth[1] - n0
    summary = post.summary()
    return post, summary, truth_check(post, {
        "epicentre_km": [e, n], "distance_km": math.hypot(e, n),
        "back_azimuth_deg": math.degrees(math.atan2(e, n)) % 360.0,
        "mechanism": "strike-slip", "mw": mw}, summary)


def test_a_larger_source_beyond_the_reach_is_held_by_the_shell_and_its_magnitudes():
    """An Mw 7 source 12.7-13 km from three sites (every site beyond the 10 km ring; its
    falls those of an Mw 6 at 6-7 km, inside the reach): most of the posterior lies
    beyond, and the 95 % regions hold the source: its cell, its distance (open above) and
    its magnitude (the table's largest, or more)."""
    sites = {"A": (0.0, 13.0), "B": (9.0, 9.0), "C": (-9.0, 9.0)}
    post, summary, found = posterior_of(magnitudes_table(), (0.0, 0.0), sites, 7.0)
    assert not found["within_reach"]
    assert summary["p_beyond"] > 0.3 and summary["beyond_in_95"]
    assert summary["reach_warning"].startswith(f"P(beyond the reach) {summary['p_beyond']:.2f}")
    assert found["epicentre_in_95"] and found["distance_in_95"] and found["mw_in_95"]
    assert summary["distance_ci95_km"][1] is None and summary["distance_ci95_unbounded"]
    assert summary["magnitude_ci95"][1] == 7.0 and summary["magnitude_ci95_open_above"]
    assert summary["beyond_extrapolated"] and summary["beyond_prior"] == PRIOR_BEYOND
    # P(beyond) is the test's Bayes factor B times the prior odds, as odds
    odds = summary["beyond_bayes_factor"] * PRIOR_BEYOND / (1.0 - PRIOR_BEYOND)
    assert summary["p_beyond"] == pytest.approx(odds / (1.0 + odds), rel=1e-12)


def test_a_source_well_within_the_reach_keeps_its_regions():
    """An Mw 6 source 3-5 km from three sites: almost nothing beyond, and the regions, the
    intervals and the magnitudes are those of the candidates alone (a posterior built
    without the shell)."""
    from pipeline.inversion.posterior import Posterior
    sites = {"A": (4.0, 0.0), "B": (-2.0, -3.0), "C": (0.0, 5.0)}
    post, summary, found = posterior_of(magnitudes_table(), (0.0, 0.0), sites, 6.0)
    assert found["within_reach"] and summary["p_beyond"] < 1e-3
    assert not summary["beyond_in_95"] and summary["reach_warning"] is None
    alone = Posterior(post.slices, post.strikes_deg, post.east_km, post.north_km,
                      post.step_km, post.log_prior, post.log_likelihood, info=post.info,
                      edge=post.edge)
    expected = alone.summary()
    for key in ("credible_area_95_km2", "credible_area_68_km2", "magnitude_ci95",
                "back_azimuth_ci95_deg", "map_epicentre_km"):
        assert summary[key] == expected[key]
    assert summary["distance_ci95_km"] == pytest.approx(expected["distance_ci95_km"], abs=0.05)
    assert (post.epicentre_region(0.95)[0] == alone.epicentre_region(0.95)[0]).all()
    assert found["epicentre_in_95"] and found["distance_in_95"] and found["mw_in_95"]


def test_the_mass_beyond_adds_up_in_the_frame_and_the_region():
    """posterior.csv's rows sum to 1, the shell's to P(beyond); the 95 % region holds 95 %
    of the whole, and its area is its candidate cells' and its shell cells' (the shell's
    cells SHELL_STEP times the candidates' step)."""
    sites = {"A": (0.0, 14.0), "B": (8.0, 15.0)}
    post, summary, _ = posterior_of(magnitudes_table(), (0.0, 0.0), sites, 7.0)
    frame = post.frame()
    assert frame["posterior"].sum() == pytest.approx(1.0, abs=1e-9)
    shell = frame[frame["beyond_reach"]]
    assert shell["posterior"].sum() == pytest.approx(summary["p_beyond"], abs=1e-9)
    assert len(shell) == summary["beyond_cells"] * len(post.slices) * len(post.strikes_deg)
    mask, _ = post.region(0.95)
    _, _, area, mass, in_shell = post.cells()
    assert mass.sum() == pytest.approx(1.0) and mass[mask].sum() >= 0.95 - 1e-9
    # the cells of highest density: without its least dense cell the region holds < 95 %
    # (the shell's cells are larger, so that cell need not be the one of least mass)
    least = np.argmin(mass[mask] / area[mask])
    assert mass[mask].sum() - mass[mask][least] < 0.95
    n = post.east_km.size
    assert summary["credible_area_95_km2"] == pytest.approx(
        mask[:n].sum() * 1.0 + mask[n:].sum() * (SHELL_STEP * 1.0) ** 2)
    assert mass[in_shell].sum() == pytest.approx(summary["p_beyond"])
    assert sum(summary["magnitude_posterior"].values()) == pytest.approx(1.0)


def test_the_shells_result_checks_itself_on_construction():
    """A shell's posterior that does not sum to 1, or a Bayes factor without shell cells,
    is refused when built."""
    from pipeline.inversion.beyond import Beyond
    cells = {"shell_km": (10.0, 20.0), "sites_km": ((0.0, 0.0),), "radius_km": 30.0,
             "step_km": 2.0, "east_km": np.array([11.0]), "north_km": np.array([1.0])}
    with pytest.raises(ValueError, match="does not sum to 1"):
        Beyond(**cells, probability=np.full((1, 1, 1), 0.5), log_bayes_factor=0.0)
    with pytest.raises(ValueError, match="needs shell cells"):
        Beyond(**{**cells, "east_km": np.zeros(0), "north_km": np.zeros(0)},
               probability=np.zeros((1, 1, 0)), log_bayes_factor=0.0)
    even = math.log((1.0 - PRIOR_BEYOND) / PRIOR_BEYOND)   # the Bayes factor of even odds
    shell = Beyond(**cells, probability=np.ones((1, 1, 1)), log_bayes_factor=even)
    assert shell.p_beyond == pytest.approx(0.5)
    assert shell.warning == (math.exp(even) > BEYOND_BAYES_FACTOR)
    assert shell.cell_of(11.5, 0.2) == 0 and shell.cell_of(25.0, 0.0) is None
