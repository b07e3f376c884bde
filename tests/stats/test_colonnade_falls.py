"""Where a colonnade's columns fell (colonnade_falls.png): the fall azimuths of a
hand-made runs table grouped, beams and the nominal run left out, their circular mean
against a hand computation (wrapped about North), and the figure drawn."""
import math

import pandas as pd
import pytest

from pipeline.campaign.tables import plot_falls
from pipeline.figures.colonnade_falls import panel_title, plot_fall_directions
from pipeline.files import InputError
from pipeline.stats.colonnade_falls import FallDirections, fall_directions, wrapped_azimuths

NAN = math.nan
COLUMNS = ("c1", "c2", "c3")
# runs.csv rows: (run_id, column, toppled, downfall azimuth); beam "e1" and the nominal
# run r0 (member -1) must not count
RUNS = pd.DataFrame(
    [("r0", "c1", True, 180.0, -1), ("r1", "c1", True, 350.0, 0),
     ("r1", "c2", True, 10.0, 0), ("r1", "c3", False, NAN, 0), ("r1", "e1", True, 90.0, 0),
     ("r2", "c1", True, 340.0, 1), ("r2", "c2", False, NAN, 1), ("r2", "c3", False, NAN, 1),
     ("r3", "c1", False, NAN, 2), ("r3", "c2", False, NAN, 2), ("r3", "c3", False, NAN, 2)],
    columns=["run_id", "column", "toppled", "downfall_azimuth_deg", "member"])
GROUPS = {"r0": "A", "r1": "A", "r2": "A", "r3": "B"}


def hand_mean(azimuths):
    """The circular mean written out: the direction of the summed unit vectors."""
    east = sum(math.sin(math.radians(a)) for a in azimuths)
    north = sum(math.cos(math.radians(a)) for a in azimuths)
    return math.degrees(math.atan2(east, north)) % 360.0


def test_falls_grouped_and_their_mean_about_north():
    a, b = fall_directions(RUNS, GROUPS, COLUMNS)
    assert (a.group, a.runs, a.shaken, a.fallen) == ("A", 2, 6, 3)
    assert sorted(a.azimuths_deg) == [10.0, 340.0, 350.0]
    # -20, -10, +10 about North: the mean lies just west of North, not near 180
    assert hand_mean([350.0, 10.0, 340.0]) == pytest.approx(353.2954, abs=1e-3)
    assert a.mean_deg == pytest.approx(hand_mean([350.0, 10.0, 340.0]), abs=1e-9)
    r = math.hypot(sum(math.sin(math.radians(x)) for x in (350, 10, 340)),
                   sum(math.cos(math.radians(x)) for x in (350, 10, 340))) / 3
    assert a.resultant_length == pytest.approx(r)
    assert a.spread_deg == pytest.approx(math.degrees(math.sqrt(-2 * math.log(r))))
    assert "mean 353°" in panel_title(a) and "3 of 6 columns fell (2 runs)" in panel_title(a)
    assert (b.group, b.fallen, b.shaken, b.mean_deg, b.spread_deg) == ("B", 0, 3, None, None)
    assert "mean" not in panel_title(b)


def test_symmetric_falls_about_north_average_to_north():
    falls = FallDirections("x", 1, 4, (355.0, 5.0, 340.0, 20.0))
    assert falls.mean_deg == pytest.approx(0.0, abs=1e-9) or \
        falls.mean_deg == pytest.approx(360.0, abs=1e-9)
    assert 0.0 <= falls.mean_deg < 360.0


def test_azimuths_wrap_into_0_360():
    assert list(wrapped_azimuths([-1e-17, 360.0, 725.0, -90.0])) == [0.0, 0.0, 5.0, 270.0]
    with pytest.raises(InputError, match=r"\[0, 360\)"):
        FallDirections("x", 1, 1, (360.0,))
    with pytest.raises(InputError, match="2 falls of 1"):
        FallDirections("x", 1, 1, (0.0, 1.0))
    bad = RUNS.assign(downfall_azimuth_deg=NAN)
    with pytest.raises(InputError, match="without a fall azimuth"):
        fall_directions(bad, GROUPS, COLUMNS)


def test_the_figure_is_drawn(tmp_path):
    path = plot_fall_directions(fall_directions(RUNS, GROUPS, COLUMNS), 90.0,
                                tmp_path / "falls.png", {"A": 0.0})
    assert path.stat().st_size > 10_000


def test_a_campaign_draws_it_from_its_tables(tmp_path):
    table = pd.DataFrame({"run_id": ["r0", "r1", "r2", "r3"], "member": [-1, 0, 1, 2],
                          "direction": ["in-plane", "in-plane", "in-plane", "oblique"],
                          "azimuth_deg": [90.0, 90.0, 90.0, 135.0]})
    description = {"name": "row", "stylobate": {"start": [0, 0], "end": [10, 0]},
                   "columns": [{"name": c} for c in COLUMNS]}
    path = plot_falls(tmp_path, table, RUNS.drop(columns="member"), description, "direction")
    assert path == tmp_path / "colonnade_falls.png" and path.stat().st_size > 10_000
