"""The forward table: grid checks, the sub-event layout, runs into arrays, the file."""
import json

import numpy as np
import pytest

from pipeline.campaign.spec import RunSpec
from pipeline.outcome.summary import RunSummary
from pipeline.files import InputError
from pipeline.inversion.forward import ForwardTags, member_parameters
from pipeline.inversion.grid import TableGrid, node_positions, subevent_layout
from pipeline.inversion.presets import GRIDS
from pipeline.inversion.table import ForwardTable
from pipeline.motion.synthetics import SOURCES, subevents
from pipeline.scenario import RunParams


def test_mw65_layout_is_the_paper_scenarios():
    layout = subevent_layout(6.5)
    paper = subevents("strike_slip")                    # strike 0: along North
    np.testing.assert_allclose([s["y_km"] for s in layout], paper["y_km"])
    np.testing.assert_allclose([s["delay_s"] for s in layout], paper["delay_s"])
    np.testing.assert_allclose([s["m0_nm"] for s in layout], paper["m0_nm"])
    assert layout[0]["duration_s"] == SOURCES["strike_slip"]["subevent_duration_s"]
    bigger = subevent_layout(7.0)                       # self-similar: x 10^0.25
    assert bigger[-1]["y_km"] == pytest.approx(12.0 * 10 ** 0.25)


def test_grid_checks_and_sizes():
    assert GRIDS["quick"].n_runs() == 2 * 2 * 4 * 2
    assert GRIDS["demo"].n_runs() == 2 * 4 * 12 * 7
    with pytest.raises(InputError, match="azimuth-step"):
        TableGrid(azimuth_step_deg=25)
    with pytest.raises(InputError, match="distances"):
        TableGrid(distances_km=(5, 5))
    with pytest.raises(InputError, match="members or the nominal"):
        TableGrid(members=0, nominal=False)
    assert TableGrid(mechanisms="thrust,oblique:60:45").mechanisms[1] == ("oblique", 60.0, 45.0)
    assert TableGrid().key() == TableGrid().replace(members=None).key() != \
        TableGrid(members=7).key()


def test_member_parameters_nominal_first_and_grown_ensembles_keep_their_members():
    params = member_parameters(TableGrid(members=3))
    assert [m for m, _ in params] == [-1, 0, 1, 2]
    assert all(p["column"] == "both" and p["tail_s"] == 5.0 for _, p in params)
    six, twelve = member_parameters(TableGrid(members=6)), member_parameters(TableGrid(members=12))
    assert len(twelve) == 13 and twelve[:7] == six       # the first batch: the same runs
    assert twelve[7][1] != six[1][1]                     # the second batch: a new seed


def test_from_runs_places_each_outcome(tmp_path):
    grid = TableGrid(mechanisms=("strike-slip",), distances_km=(5.0, 10.0),
                     azimuth_step_deg=180.0, members=2)
    r, _, _, _ = node_positions(grid)
    specs = []
    for node in range(len(r)):
        for member in (-1, 0, 1):
            run_id = f"n{node}m{member}"
            fell = node == 1 and member >= 0           # node 1 = (5 km, 180)
            RunSummary(record=run_id, wall_s=2.0, simulated=True, columns=[
                    {"column": "drums", "toppled": fell,
                     "downfall_azimuth_deg": 100.0 + member if fell else None},
                    {"column": "monolithic", "toppled": member == -1,
                     "downfall_azimuth_deg": 7.0 if member == -1 else None}]).save(
                tmp_path / "runs" / run_id / "summary.json")
            specs.append(RunSpec(run_id, run_id, "/m.npz", RunParams(), run_id,
                                 ForwardTags(0, node, member, 0.0, 0.0, grid)))
    table = ForwardTable.from_runs(specs, tmp_path, grid)
    assert table.toppled.shape == (1, 2, 2, 2, 2)
    assert table.toppled[0, 0, 1, 0].all() and table.toppled.sum() == 2
    np.testing.assert_allclose(table.azimuth_deg[0, 0, 1, 0], [100.0, 101.0])
    assert table.nominal_toppled[..., 1].all() and not table.nominal_toppled[..., 0].any()
    assert table.info["yade_wall_s"] == 24.0
    cells = table.cells()
    row = cells[(cells.distance_km == 5) & (cells.azimuth_from_strike_deg == 180)
                & (cells.column == "drums")].iloc[0]
    assert row.p_toppled == 1.0
    assert row.mean_downfall_from_site_direction_deg == pytest.approx(280.5)
    path = table.save(tmp_path / "t.npz")
    again = ForwardTable.load(path)
    np.testing.assert_array_equal(again.toppled, table.toppled)
    np.testing.assert_array_equal(again.nominal_azimuth_deg, table.nominal_azimuth_deg)
    assert again.slices == table.slices and again.info == json.loads(json.dumps(table.info))
    half = table.select_members(np.array([True, False]))
    assert half.toppled.shape[-1] == 1 and half.azimuth_deg[0, 0, 1, 0, 0] == 100.0


def test_bad_table_file(tmp_path):
    bad = tmp_path / "x.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(InputError, match="not a forward table"):
        ForwardTable.load(bad)


def test_turning_the_strike_turns_the_motion():
    """The symmetry the table rests on: pyprop8 with the strike turned by phi, at receivers
    turned by phi, gives the strike-0 motion with its horizontal components turned by phi."""
    from pipeline.motion import rotate_horizontal
    from pipeline.motion.synthetics import numerics, point_source_displacement
    num = numerics(8.0, 2.5, 1.0)
    sub = {"x_km": 0.0, "y_km": 0.0, "depth_km": 6.0, "delay_s": 0.0, "m0_nm": 1e17,
           "rise_s": 0.5, "duration_s": 1.0}
    r, az, phi = np.array([4.0, 7.0]), np.array([20.0, 250.0]), 70.0
    def xy(a):
        return r * np.sin(np.radians(a)), r * np.cos(np.radians(a))
    base = point_source_displacement(*xy(az), (0.0, 40.0, 90.0), sub, num, 1.0)
    turned = point_source_displacement(*xy(az + phi), (phi, 40.0, 90.0), sub, num, 1.0)
    for k in range(len(r)):
        expected = rotate_horizontal(base[k].T, phi)
        np.testing.assert_allclose(turned[k].T, expected, atol=1e-3 * np.abs(base).max())
