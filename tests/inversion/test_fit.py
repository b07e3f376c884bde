"""The fit check: observations no candidate can produce are flagged (the warning, no
direction); observations drawn from the table at a candidate are not."""
import numpy as np

from pipeline.inversion.fit import FIT_P_VALUE
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import ColumnObservation, Observations, Site
from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.posterior import invert

GRID = CandidateGrid(radius_km=10.0, step_km=1.0, strike_step_deg=90.0)


def site(name, east, north, azimuths):
    return Site(name, east, north, tuple(
        ColumnObservation("drums" if k % 2 else "monolithic", "fallen", float(a), 5.0)
        for k, a in enumerate(azimuths)))


def test_falls_toward_opposite_sides_at_one_site_fit_no_source(make_away_table):
    """Every member falls away from the source (8 deg scatter): twenty columns at one site,
    half toward North and half toward South, fit no epicentre."""
    table = make_away_table(members=12)
    obs = Observations((site("A", 0.0, 0.0, [0.0, 180.0] * 10),), "synthetic")
    for kind in ("independent", "predictive"):
        summary = invert(ForwardModel(table, likelihood=kind), obs, GRID).summary()
        assert summary["fit_p_value"] < FIT_P_VALUE and summary["fit_warning"]
        assert summary["reach_warning"] and not summary["direction_reliable"]
        assert summary["back_azimuth_ci95_deg"] == [0.0, 360.0]


def test_falls_away_from_one_source_fit(make_away_table):
    """Two sites, their columns falling away from a source 5 km North-East of the first
    (the table's behaviour, 8 deg scatter): no fit warning."""
    table = make_away_table(members=12)
    rng = np.random.default_rng(4)
    source = np.array([3.5, 3.5])
    sites = []
    for name, (e, n) in (("A", (0.0, 0.0)), ("B", (6.0, 1.0))):
        away = np.degrees(np.arctan2(e - source[0], n - source[1])) % 360.0
        sites.append(site(name, e, n, away + rng.normal(0.0, 8.0, 8)))
    for kind in ("independent", "predictive"):
        summary = invert(ForwardModel(table, likelihood=kind), Observations(tuple(sites)),
                         GRID).summary()
        assert summary["fit_p_value"] > 0.1 and summary["fit_warning"] is None
