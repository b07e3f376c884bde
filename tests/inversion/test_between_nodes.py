"""The inversion between its table's nodes, on small tables whose truths are known by
construction: a magnitude halfway between two slices, a source between spokes, a source
well inside the reach (no warning) and one beyond it (the warning, and no direction)."""
import dataclasses
import math

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.inversion import truth_check
from pipeline.inversion.likelihood import ForwardModel, magnitude_sources
from pipeline.inversion.observations import parse_observations
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.credible import magnitude_interval
from pipeline.inversion.posterior import invert
from pipeline.inversion.table import ForwardTable

AZIMUTHS = (0.0, 90.0, 180.0, 270.0)
RINGS = (2.5, 5.0, 10.0)
MEMBERS = 20


def magnitude_table(p_low=0.2, p_high=0.8):
    """Two slices, Mw 6 and 7, alike at every node but for the share of members that fall
    (``p_low``, ``p_high``); every fall away from the source (strike frame: the node
    azimuth), so the direction says where the source is and the falls how strong it was."""
    falls = [[[[[theta if k < n_fall else None for k in range(MEMBERS)] for _ in range(2)]
               for theta in AZIMUTHS] for _ in RINGS]
             for n_fall in (round(p_low * MEMBERS), round(p_high * MEMBERS))]
    slices = [("strike-slip", 90.0, 180.0, 10.0, 6.0), ("strike-slip", 90.0, 180.0, 10.0, 7.0)]
    return ForwardTable.toy(slices, RINGS, AZIMUTHS, falls)


def observed(sites, truth, fallen_share, columns=40, spread_deg=0.0, seed=1):
    """Observations at ``sites`` {name: (e, n)} of a source at ``truth``: a share
    ``fallen_share`` of ``columns`` falls away from it (plus a normal error of
    ``spread_deg``), the rest stand."""
    rng = np.random.default_rng(seed)
    out = []
    for name, (e, n) in sites.items():
        away = math.degrees(math.atan2(e - truth[0], n - truth[1])) % 360.0
        fallen = round(columns * fallen_share)
        out.append({"name": name, "east_km": e, "north_km": n, "columns": [
            {"column": "drums" if k % 2 else "monolithic", "state": "fallen",
             "downfall_azimuth_deg": float((away + rng.normal(0, spread_deg)) % 360.0),
             "uncertainty_deg": 10} if k < fallen else
            {"column": "drums" if k % 2 else "monolithic", "state": "standing"}
            for k in range(columns)]})
    return parse_observations({"sites": out})


def checked(table, observations, truth, grid, first_site, likelihood="predictive"):
    """(summary, truth check) of ``truth`` (east, north km, Mw) in the frame where the
    first site lies at ``first_site`` (the inversion's frame is the first site's)."""
    post = invert(ForwardModel(table, likelihood=likelihood), observations, grid)
    e, n = truth[0] - first_site[0], truth[1] - first_site[1]
    summary = post.summary()
    return summary, truth_check(post, {
        "epicentre_km": [e, n], "distance_km": math.hypot(e, n),
        "back_azimuth_deg": math.degrees(math.atan2(e, n)) % 360.0,
        "mechanism": "strike-slip", "mw": truth[2]}, summary)


def test_magnitude_candidates_every_tenth_between_slices():
    """Mw 6 and 7 of one mechanism and depth: 6.0, 6.1, ..., 7.0, each the mixture of its
    neighbours with weights linear in Mw; another depth keeps its own slice alone."""
    slices = [{"mechanism": "s", "dip_deg": 90.0, "rake_deg": 180.0, "depth_km": 10.0,
               "mw": m} for m in (6.0, 7.0)]
    slices.append(dict(slices[0], depth_km=5.0))
    sources, mix = magnitude_sources(slices, 0.1)
    mws = [s["mw"] for s in sources if s["depth_km"] == 10.0]
    assert mws == pytest.approx(np.arange(6.0, 7.05, 0.1))
    assert np.allclose(mix.sum(axis=1), 1.0)
    k = mws.index(pytest.approx(6.3))
    assert mix[k, :2] == pytest.approx([0.7, 0.3])
    assert [s["mw"] for s in sources if s["depth_km"] == 5.0] == [6.0]


def test_a_magnitude_halfway_between_slices_is_not_answered_with_a_slice():
    """Half the columns fall at three sites: halfway between the slices (P 0.2 at Mw 6,
    0.8 at Mw 7), so the mixture's P is 0.5 at Mw 6.5.  The posterior puts substantial
    mass below and above 6.5, none of the slices takes it all, and the 95 % interval holds
    6.5."""
    truth = (0.0, 0.0, 6.5)
    sites = {"A": (4.0, 0.0), "B": (-2.0, 3.0), "C": (0.0, -4.5)}
    summary, found = checked(magnitude_table(), observed(sites, truth, 0.5), truth,
                             CandidateGrid(radius_km=12, step_km=1.0, strike_step_deg=90),
                             sites["A"])
    post = {float(k): v for k, v in summary["magnitude_posterior"].items()}
    below = sum(v for m, v in post.items() if m < 6.45)
    above = sum(v for m, v in post.items() if m > 6.55)
    assert below > 0.1 and above > 0.1
    assert max(post[6.0], post[7.0]) < 0.05
    lo, hi = summary["magnitude_ci95"]
    assert lo < 6.5 < hi and (lo, hi) != (6.0, 7.0)
    assert found["mw_in_95"] and found["mw_in_table_range"] and not found["mw_in_table"]


def test_the_magnitude_interval_spans_its_cells():
    """The fewest consecutive magnitudes holding 95 %, each for the span halfway to its
    neighbours, and the range's ends where the table's magnitudes end."""
    post = {6.0: 0.01, 6.1: 0.02, 6.2: 0.47, 6.3: 0.48, 6.4: 0.02}
    assert magnitude_interval(post) == pytest.approx([6.15, 6.35])
    assert magnitude_interval({6.0: 0.97, 6.1: 0.03}) == pytest.approx([6.0, 6.05])


def test_a_source_between_spokes_gets_an_arc_that_covers_it():
    """Spokes 90 deg apart, every fall fixed in the strike frame (toward strike + 90): sites
    45 deg off the spokes (45, 135 and 315 deg from the strike) see falls that neither
    neighbouring spoke's site-frame reading holds (45 deg off either way).  Every 95 %
    arc holds the true back azimuth and gives a direction (narrower than the circle)."""
    falls = [[[[[90.0] * MEMBERS] * 2 for _ in AZIMUTHS] for _ in RINGS]]
    table = ForwardTable.toy([("strike-slip", 90.0, 180.0, 10.0, 6.5)], RINGS, AZIMUTHS,
                             falls)
    for strike in (0.0, 90.0, 180.0, 270.0):
        rng = np.random.default_rng(int(strike))
        sites = {}
        for name, r, az in (("A", 4.0, 45.0), ("B", 6.0, 135.0), ("C", 5.0, 315.0)):
            a = math.radians(az + strike)
            sites[name] = (r * math.sin(a), r * math.cos(a))
        out = [{"name": name, "east_km": e, "north_km": n, "columns": [
            {"column": "drums", "state": "fallen", "uncertainty_deg": 10,
             "downfall_azimuth_deg": float((strike + 90.0 + rng.normal(0, 5)) % 360.0)}
            for _ in range(6)]} for name, (e, n) in sites.items()]
        summary, found = checked(table, parse_observations({"sites": out}), (0.0, 0.0, 6.5),
                                 CandidateGrid(radius_km=12, step_km=1.0, strike_step_deg=90),
                                 sites["A"])
        assert found["back_azimuth_in_95"]
        assert summary["back_azimuth_ci95_width_deg"] < 360.0


def reach_table():
    """One slice; the share of members that fall is 2.5 km / r at the rings (1, 1/2,
    1/4), every fall away from the source."""
    falls = [[[[[theta if k < round(MEMBERS * 2.5 / r) else None for k in range(MEMBERS)]] * 2
                for theta in AZIMUTHS] for r in RINGS]]
    return ForwardTable.toy([("strike-slip", 90.0, 180.0, 10.0, 6.5)], RINGS, AZIMUTHS, falls)


def test_a_source_well_inside_the_reach_gives_no_warning():
    """Three sites 3-5 km from the source, the reach 10 km: no warning, a direction."""
    truth = (0.0, 0.0, 6.5)
    sites = {"A": (4.0, 0.0), "B": (-2.0, 3.0), "C": (0.0, -5.0)}
    table = reach_table()
    for seed in range(3):
        obs = []
        for name, (e, n) in sites.items():
            share = 2.5 / math.hypot(e, n)
            site = observed({name: (e, n)}, truth, share, columns=12, spread_deg=5.0,
                            seed=seed).sites[0]         # alone in its file: at (0, 0)
            obs.append(dataclasses.replace(site, east_km=e - sites["A"][0],
                                           north_km=n - sites["A"][1]))
        from pipeline.inversion.observations import Observations
        summary, found = checked(table, Observations(tuple(obs)), truth,
                                 CandidateGrid(radius_km=15, step_km=1.0), sites["A"])
        assert found["within_reach"] and summary["reach_warning"] is None
        assert summary["direction_reliable"] and summary["back_azimuth_map_deg"] is not None


def test_a_source_beyond_the_reach_gives_the_warning_and_no_direction():
    """One site 16 km from the source, the table's rings end at 10 km: 2 of 12 columns
    fall (the share at 16 km), fewer than anywhere within the reach when the 12 are read
    as 12 independent draws (the predictive likelihood reads a site's columns as a few:
    2 of 12 then does not tell 16 km from 10); the warning, and the whole circle for the
    back azimuth."""
    truth = (0.0, 0.0, 6.5)
    summary, found = checked(reach_table(), observed({"A": (0.0, 16.0)}, truth, 2.5 / 16,
                                                     columns=12), truth,
                             CandidateGrid(radius_km=20, step_km=1.0), (0.0, 16.0),
                             likelihood="independent")
    assert not found["within_reach"] and found["reach_warning"]
    assert summary["back_azimuth_ci95_deg"] == [0.0, 360.0]
    assert summary["back_azimuth_map_deg"] is None and not summary["direction_reliable"]
    assert "direction" in summary["reach_warning"]


def test_a_magnitude_step_out_of_range_is_one_line():
    with pytest.raises(InputError, match=r"magnitude step must lie in \(0, 1\], got 0"):
        ForwardModel(reach_table(), mw_step=0.0)
