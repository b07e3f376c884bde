"""The forward table shipped for the member study (records/inversion/) is what it says it
is: the code's `study` grid, every run finished, and outcomes a table can hold."""
import json
from pathlib import Path

import numpy as np

from pipeline.inversion.presets import GRIDS
from pipeline.inversion.table import ForwardTable

SHIPPED = Path(__file__).resolve().parents[2] / "records" / "inversion" / "forward_table_study.npz"


def test_the_shipped_table_is_the_study_grid_of_this_code():
    table = ForwardTable.load(SHIPPED)
    grid = GRIDS["study"]
    # the grid the file states (JSON) is the preset's: a changed preset needs a new table
    assert table.info["grid"] == json.loads(json.dumps(grid.as_dict()))
    assert table.info["grid_key"] == grid.key()
    assert table.info["runs"] == grid.n_runs()
    assert table.toppled.shape == (len(grid.mechanisms) * len(grid.depths_km)
                                   * len(grid.magnitudes), len(grid.distances_km),
                                   round(360 / grid.azimuth_step_deg), 2, grid.members)
    assert list(table.members) == list(range(grid.members))
    assert table.valid.all()                     # every run finished
    assert table.info["code_version"] and table.info["yade_wall_s"] > 0


def test_the_shipped_outcomes_are_outcomes():
    table = ForwardTable.load(SHIPPED)
    fallen = table.toppled
    # a fallen column has a downfall azimuth in [0, 360), a standing one none
    assert np.all((table.azimuth_deg[fallen] >= 0) & (table.azimuth_deg[fallen] < 360))
    assert np.all(np.isnan(table.azimuth_deg[~fallen]))


def test_toppled_fraction_counts_the_fallen_columns():
    slices = [{"mechanism": "strike-slip", "dip_deg": 90.0, "rake_deg": 180.0,
               "depth_km": 10.0, "mw": mw} for mw in (6.0, 7.0)]
    # two nodes (azimuths 0 and 180 deg), 4 members: Mw 6 topples nothing, Mw 7 topples
    # 6 of 8 columns at one node and 4 of 8 at the other: 10 of 16
    standing = [[None] * 4, [None] * 4]
    falls = [[[standing, standing]],
             [[[[10.0, 20.0, None, 30.0], [40.0, None, 50.0, 60.0]],
               [[10.0, None, None, 30.0], [None, None, 50.0, 60.0]]]]]
    table = ForwardTable.toy(slices, [2.5], [0.0, 180.0], falls)
    assert [s["fraction"] for s in table.toppled_fraction_by_slice()] == [0.0, 0.625]
    assert [s["mw"] for s in table.toppled_fraction_by_slice()] == [6.0, 7.0]
