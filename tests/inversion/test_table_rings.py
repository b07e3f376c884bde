"""A forward table extended by rings (``invert --extend-table``): the joined table holds
each part's outcomes at its rings, in ring order, and is the table of the whole grid."""
import json

import numpy as np
import pytest

from pipeline.files import InputError
from pipeline.inversion import forward, workflows
from pipeline.inversion.grid import TableGrid
from pipeline.inversion.options import InversionOptions
from pipeline.inversion.table import ForwardTable

SLICES = [("strike-slip", 90.0, 180.0, 10.0, 7.0)]
GRID = TableGrid(mechanisms=("strike-slip",), depths_km=(10.0,), magnitudes=(7.0,),
                 distances_km=(2.5, 5.0, 20.0), azimuth_step_deg=180.0, members=2,
                 nominal=False)


def _table(distances, seed):
    """A toy table at ``distances`` (two node azimuths, two columns, two members) whose
    outcomes are drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    falls = [[[[[float(rng.uniform(0, 360)) if rng.random() < 0.5 else None
                 for _ in range(2)] for _ in range(2)] for _ in range(2)]
              for _ in distances]]
    ring_grid = GRID.replace(distances_km=tuple(distances))
    return ForwardTable.toy(SLICES, distances, [0.0, 180.0], falls,
                            info={"grid": ring_grid.as_dict(), "grid_key": ring_grid.key(),
                                  "code_version": f"code{seed}", "yade_wall_s": 10.0 * seed,
                                  "runs": 8 * len(distances), "simulated_runs": 7})


def test_joined_rings_hold_each_part_at_its_ring():
    inner, outer = _table([2.5, 5.0], 1), _table([20.0], 2)
    joined = outer.with_rings(inner, GRID)        # the order of the parts does not matter
    assert list(joined.distances_km) == [2.5, 5.0, 20.0]
    for name in ("toppled", "valid"):
        assert np.array_equal(getattr(joined, name)[:, :2], getattr(inner, name))
        assert np.array_equal(getattr(joined, name)[:, 2:], getattr(outer, name))
    np.testing.assert_array_equal(joined.azimuth_deg[:, 2:], outer.azimuth_deg)
    assert joined.info["grid_key"] == GRID.key()
    assert joined.info["runs"] == 24 and joined.info["yade_wall_s"] == 30.0
    assert [p["distances_km"] for p in joined.info["parts"]] == [[20.0], [2.5, 5.0]]


def test_joined_table_survives_its_file(tmp_path):
    joined = _table([2.5, 5.0], 1).with_rings(_table([20.0], 2), GRID)
    back = ForwardTable.load(joined.save(tmp_path / "t.npz"))
    assert np.array_equal(back.toppled, joined.toppled)
    assert back.info["parts"] == json.loads(json.dumps(joined.info["parts"]))


def test_tables_that_differ_in_more_than_rings_are_refused():
    inner = _table([2.5, 5.0], 1)
    with pytest.raises(InputError, match="share a ring"):
        inner.with_rings(_table([5.0], 2), GRID)
    with pytest.raises(InputError, match="not the grid's"):
        inner.with_rings(_table([10.0], 2), GRID)
    other = inner.select_members(np.array([True, False]))
    with pytest.raises(InputError, match="differ in more than their rings"):
        other.with_rings(_table([20.0], 2), GRID)


def test_extend_table_runs_only_the_missing_rings(tmp_path, monkeypatch):
    base = _table([2.5, 5.0], 1).save(tmp_path / "base.npz")
    asked = []

    def fake_run_forward(grid, campaign_dir, jobs, scheduler):
        asked.append(grid.distances_km)
        return _table(list(grid.distances_km), 2), {"runs": grid.n_runs(), "elapsed_s": 0.0}

    monkeypatch.setattr(forward, "run_forward", fake_run_forward)
    options = InversionOptions(extend_table=base, forward_dir=tmp_path / "fw", jobs=1)
    table, info = workflows.forward_table(options, GRID)
    assert asked == [(20.0,)]
    assert list(table.distances_km) == [2.5, 5.0, 20.0]
    assert ForwardTable.load(info["table"]).info["grid_key"] == GRID.key()
    # a base table of another grid, or rings the grid does not have: one line, no run
    for grid in (GRID.replace(members=3), GRID.replace(distances_km=(5.0, 20.0))):
        with pytest.raises(InputError, match="--extend-table"):
            workflows.forward_table(options, grid)
    assert asked == [(20.0,)]


def test_table_and_extend_table_exclude_each_other(tmp_path):
    with pytest.raises(InputError, match="not both"):
        InversionOptions(table=tmp_path / "a.npz", extend_table=tmp_path / "b.npz")
