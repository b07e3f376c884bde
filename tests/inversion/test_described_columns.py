"""Column files in the inversion (no YADE): the described column's forward grid and
runs, its table joined to the twin table, and `invert` with a shipped example's name."""
import json

import numpy as np
import pytest

from pipeline.campaign.spec import RunSpec
from pipeline.outcome.summary import RunSummary
from pipeline import cli
from pipeline.campaign.column_file import column_kn, description
from pipeline.files import InputError, write_json
from pipeline.inversion.forward import ForwardTags, member_parameters, table_path
from pipeline.inversion.grid import TableGrid, node_positions
from pipeline.inversion.presets import GRIDS
from pipeline.inversion.table import ForwardTable
from pipeline.scenario import RunParams


def test_twin_grids_keep_their_keys_and_a_description_makes_another():
    assert "column_file" not in GRIDS["demo"].as_dict()
    doric = GRIDS["demo"].replace(column_file="doric-peristyle")
    assert doric.column_file == description("doric-peristyle")
    assert doric.key() != GRIDS["demo"].key() and doric.columns == ("drums",)
    assert TableGrid(**doric.as_dict()) == doric         # the campaign's round trip


def test_described_members_are_that_column_alone():
    grid = TableGrid(members=3, column_file="doric-peristyle")
    data, kn = description("doric-peristyle"), column_kn(description("doric-peristyle"),
                                                         "matched")
    params = member_parameters(grid)
    assert [m for m, _ in params] == [-1, 0, 1, 2]
    assert all(p["column"] == "drums" and p["tail_s"] == 5.0 for _, p in params)
    assert params[0][1]["column_file"] == data and params[0][1]["kn"] == kn
    heights = [sum(b["height"] for b in p["column_file"]["blocks"]) for _, p in params]
    assert heights[0] == pytest.approx(sum(b["height"] for b in data["blocks"]))
    assert len(set(np.round(heights[1:], 9))) == 3      # members: sampled tolerances


def test_from_runs_of_a_described_grid(tmp_path):
    grid = TableGrid(mechanisms=("strike-slip",), distances_km=(5.0,), azimuth_step_deg=180.0,
                     members=1, column_file="roman-granite")
    specs = []
    for node in range(len(node_positions(grid)[0])):
        for member in (-1, 0):
            run_id = f"n{node}m{member}"
            RunSummary(record=run_id, wall_s=1.0, columns=[
                {"column": "drums", "toppled": node == 1,
                 "downfall_azimuth_deg": 33.0 if node else None}]).save(
                tmp_path / "runs" / run_id / "summary.json")
            specs.append(RunSpec(run_id, run_id, "/m.npz", RunParams(), run_id,
                                 ForwardTags(0, node, member, 0.0, 0.0, grid)))
    table = ForwardTable.from_runs(specs, tmp_path, grid)
    assert table.columns == ("drums",) and table.toppled.shape == (1, 1, 2, 1, 1)
    assert table.toppled[0, 0, 1, 0, 0] and table.azimuth_deg[0, 0, 1, 0, 0] == 33.0


def test_with_column_joins_the_first_column(make_away_table):
    away_table = make_away_table
    twin, other = away_table(members=4, seed=1), away_table(members=4, seed=2)
    joined = twin.with_column("doric-peristyle", other)
    assert joined.columns == ("drums", "monolithic", "doric-peristyle")
    np.testing.assert_array_equal(joined.azimuth_deg[..., :2, :], twin.azimuth_deg)
    np.testing.assert_array_equal(joined.azimuth_deg[..., 2, :], other.azimuth_deg[..., 0, :])
    with pytest.raises(InputError, match="is there already"):
        joined.with_column("doric-peristyle", other)
    with pytest.raises(InputError, match="its grid differs"):
        twin.with_column("x", away_table(members=3))


def _observations(tmp_path, column):
    path = tmp_path / "obs.json"
    path.write_text(json.dumps({"sites": [{"name": "A", "east_km": 0, "north_km": 0,
                                           "columns": [{"column": column, "state": "fallen",
                                                        "downfall_azimuth_deg": 45.0},
                                                       {"column": "drums",
                                                        "state": "standing"}]}]}))
    return path


def test_invert_uses_the_described_columns_table_beside_table(tmp_path, capsys,
                                                             make_away_table):
    """--table: the described column's table is read from beside it (its grid key's
    name); its falls (all toward the source) place the source where the column fell."""
    twin = make_away_table(members=4, seed=1)
    slices = [tuple(s[k] for k in ("mechanism", "dip_deg", "rake_deg", "depth_km", "mw"))
              for s in twin.slices]
    DISTANCES, AZIMUTHS = tuple(twin.distances_km), tuple(twin.azimuths_deg)
    grid = TableGrid(mechanisms=[s[:3] for s in slices], distances_km=DISTANCES,
                     azimuth_step_deg=30.0, members=4, nominal=False,
                     column_file="doric-peristyle")
    twin.info["grid"] = dict(grid.as_dict(), column_file=None)  # as a computed table has
    main = twin.save(tmp_path / "tables" / "main.npz")
    obs = _observations(tmp_path, "doric-peristyle")
    out = tmp_path / "out"
    argv = ["invert", str(obs), "--table", str(main), "--out", str(out), "--radius", "12",
            "--step", "1.5"]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no forward table of the described column" in err
    assert not out.exists()
    falls = [[[[[(t + 180.0 + d) % 360.0 for d in (-5.0, 0.0, 5.0, 2.0)]]
                for t in AZIMUTHS] for _ in DISTANCES] for _ in slices]   # toward the source
    ForwardTable.toy(slices, DISTANCES, AZIMUTHS, falls, columns=("drums",)).save(
        table_path(tmp_path, grid))
    assert cli.main(argv) == 0, capsys.readouterr().err
    summary = json.loads((out / "inversion_summary.json").read_text())
    assert abs((summary["back_azimuth_map_deg"] - 45.0 + 180.0) % 360.0 - 180.0) < 20.0


def test_unknown_column_file_is_one_line_before_anything(tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["invert", str(_observations(tmp_path, "corinthian")), "--out",
                     str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "column 'corinthian': no such file" in err
    assert not out.exists() and not (tmp_path / "results").exists()


def test_a_column_file_beside_the_observations(tmp_path):
    from pipeline.inversion.workflows import described_columns
    from pipeline.inversion.observations import load_observations
    data = description("roman-granite")
    write_json(tmp_path / "my_column.json", data)
    found = described_columns(load_observations(_observations(tmp_path, "my_column.json")),
                              tmp_path)
    assert found == {"my_column.json": data}


def test_a_column_file_in_the_current_directory_is_not_taken(tmp_path, monkeypatch, capsys):
    """A column named in the observations is looked for beside the observations file (or
    among the shipped examples), never in the directory the command runs from."""
    import json as _json
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    (elsewhere / "ionic.json").write_text(_json.dumps(
        {"name": "ionic", "density": 2700.0, "blocks": [
            {"shape": "frustum", "height": 3.0, "bottom_diameter": 0.6, "top_diameter": 0.5}]}))
    monkeypatch.chdir(elsewhere)
    obs = _observations(tmp_path, "ionic.json")
    assert cli.main(["invert", str(obs), "--out", str(tmp_path / "out")]) == 2
    assert "column 'ionic.json': no such file" in capsys.readouterr().err
