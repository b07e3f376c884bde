"""fragility.json as one type: what the one writer writes the one reader gives back, the
older spellings of a pulse grid's 2D block load, and the same file read by survival and
by the shake-table check gives both one P."""
import copy
import re
import json
import math

import numpy as np
import pytest

from pipeline.campaign.pulse_check import grid_probability
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.files import InputError
from pipeline.hazard.fragility import load_campaign_fragility
from pipeline.campaign.pulse_summary import contours
from pipeline.hazard.fragility.experiments import Experiments, Scores
from pipeline.hazard.fragility.file import (ContourRow, FragilityFile, GridCell, LogisticSurface,
                                            LognormalFit, read_fragility_file,
                                            write_fragility_file)
from tests.hazard.test_reader_robustness import COLUMN, grid_document


@pytest.mark.parametrize("document", [COLUMN, grid_document()], ids=["columns", "grid"])
def test_written_then_read_is_the_same_file_and_the_same_json(tmp_path, document):
    file = FragilityFile.of(copy.deepcopy(document))
    path = write_fragility_file(tmp_path, file)
    assert json.loads(path.read_text()) == document          # nothing added, nothing lost
    read = read_fragility_file(tmp_path)
    assert read == file and read.path == path


def test_sections_are_typed():
    columns = FragilityFile.of(copy.deepcopy(COLUMN))
    entry = columns.columns["monolithic"]
    assert entry.fits["PGA"].median == 3.0 and entry.logistic.b[1] == 3.0
    assert columns.records == ("R1", "R2") and columns.block2d.alpha_rad == 0.2
    grid = FragilityFile.of(grid_document()).pulse_grid
    assert grid.pga_g == (0.1, 0.2, 0.4) and grid.members == 2
    assert len(grid.models["monolithic"].cells) == 6 and grid.block2d.uplift_g == 0.05


def test_cells_and_contour_rows_are_typed_and_written_back_as_the_campaign_wrote_them(tmp_path):
    document = grid_document(p_of=lambda a, r: min(1.0, a / (2 * r)))
    model = document["pulse_grid"]["models"]["monolithic"]
    model["contours"] = json.loads(json.dumps(contours(model["cells"])))   # the campaign's
    path = write_fragility_file(tmp_path, FragilityFile.of(copy.deepcopy(document)))
    assert json.loads(path.read_text()) == document
    read = read_fragility_file(path).pulse_grid.models["monolithic"]
    cell = read.cells[0]
    assert isinstance(cell, GridCell) and (cell.pga_g, cell.pgv_pga_s) == (0.1, 0.1)
    assert cell.P == cell.overturned / cell.n == 0.5 and cell.sets == (0, 1)
    row = read.contours["0.5"][0]
    assert isinstance(row, ContourRow) and row.pgv_pga_s == 0.1
    assert row.pga_g == pytest.approx(0.1)   # P = a / 0.2 reaches 0.5 at the first cell
    assert len(row.pga_g_band) == 2 and set(row.pga_g_per_set) == {"0", "1"}


@pytest.mark.parametrize("drop, expected_g", [
    (("uplift_g_smallest",), 0.05),                       # the runs' median: uplift_g
    (("uplift_g_smallest", "uplift_g"), math.tan(0.3)),   # g tan(alpha)
])
def test_older_spellings_of_the_uplift_load(tmp_path, drop, expected_g):
    document = grid_document(uplift_g=0.05)
    block = document["pulse_grid"]["block2d"]
    block["alpha_rad"] = 0.3
    for key in drop:
        del block[key]
    (tmp_path / "fragility.json").write_text(json.dumps(document))
    assert read_fragility_file(tmp_path).pulse_grid.block2d.uplift_g_smallest == \
        pytest.approx(expected_g)
    assert load_campaign_fragility(tmp_path).uplift_m_s2 == pytest.approx(expected_g * G)


def test_the_reader_refuses_in_one_line(tmp_path):
    document = grid_document()
    document["pulse_grid"]["members"] = 0
    (tmp_path / "fragility.json").write_text(json.dumps(document))
    with pytest.raises(InputError, match="pulse_grid.members") as caught:
        read_fragility_file(tmp_path)
    assert "\n" not in str(caught.value)


def test_survival_and_the_shake_table_check_read_one_p_from_the_cells(tmp_path):
    """P = a / (a + r) in the cells (not bilinear in either space): at points inside
    the grid the pulse grid of survival and the check's interpolation agree."""
    document = grid_document(pga_g=(0.1, 0.2, 0.4, 0.8), ratios=(0.1, 0.3, 0.9),
                             p_of=lambda a, r: a / (a + r), n=400)
    (tmp_path / "fragility.json").write_text(json.dumps(document))
    file = read_fragility_file(tmp_path)
    grid = load_campaign_fragility(tmp_path)
    pga_g, ratio = np.array([0.15, 0.33, 0.7]), np.array([0.2, 0.5, 0.12])
    checked, outside, _ = grid_probability(file.pulse_grid,
                                           file.pulse_grid.models["monolithic"].cells, pga_g,
                                           ratio)
    assert not outside.any()
    np.testing.assert_allclose(grid.probability(pga_g * G, ratio), checked, atol=1e-12)


@pytest.mark.parametrize("build, words", [
    (lambda: LognormalFit(median=2.0, beta=0.5, median_ci95=(3.0, 4.0)),
     "median_ci95 [3, 4] does not hold its estimate 2"),
    (lambda: LognormalFit(median=-1.0), "median"),
    (lambda: LogisticSurface(coefficients={"b0": 0.0, "b1": 1.0, "b2": 0.0},
                             cov=((1.0, 2.0, 0.0), (2.0, 1.0, 0.0), (0.0, 0.0, 1.0))),
     "cov is not positive semi-definite"),
    (lambda: GridCell(pga_g=0.2, pgv_pga_s=0.1, n=10, overturned=11), "overturned must be"),
    (lambda: GridCell(pga_g=0.2, pgv_pga_s=0.1, n=10, overturned=5, P=0.4),
     "P 0.4 is not overturned / n = 5/10"),
    (lambda: ContourRow(pgv_pga_s=0.1, outside_grid="left"), "outside_grid must be one of"),
    (lambda: Scores(log_likelihood_per_test=-0.3, brier=1.5, n=4), "brier"),
    (lambda: Experiments(tests=3, overturned=4), "overturned must be 0 to 3"),
])
def test_each_part_of_the_file_refuses_what_contradicts_itself_when_built(build, words):
    with pytest.raises(InputError, match=re.escape(words)):
        build()


def test_a_singular_covariance_written_as_nulls_reads_as_none_and_writes_back_as_nulls():
    data = {"coefficients": {"b0": -1.0, "b1": 2.0, "b2": 0.5}, "cov": [[None] * 3] * 3}
    surface = LogisticSurface.of(copy.deepcopy(data))
    assert surface.covariance is None and surface.b == (-1.0, 2.0, 0.5)
    assert surface.to_json() == data
