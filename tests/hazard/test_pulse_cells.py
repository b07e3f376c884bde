"""The one interpolation of a pulse grid's cells: the shake-table check and survival read
the same P from the same cells; bilinear in (ln PGA, ln PGV/PGA); the edge cell's P
outside the grid, said."""
import numpy as np
import pytest

from pipeline.campaign.pulse_check import grid_probability
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.fragility import PulseGrid
from pipeline.hazard.fragility.file import GridCell
from pipeline.hazard.pulse_cells import cell_table, interpolate

PGA_G = np.round(np.linspace(0.2, 1.1, 10), 9)           # the Virtual Shake Robot's grid
RATIO_S = np.round(np.linspace(0.1, 1.0, 10), 9)


def _log_bilinear(a, r):
    """A function bilinear in (ln a, ln r), in [0, 1] on the grid."""
    x, y = np.log(a / 0.2) / np.log(5.5), np.log(r / 0.1) / np.log(10.0)
    return 0.1 + 0.5 * x + 0.2 * y + 0.15 * x * y


def _cells(p=_log_bilinear):
    return [GridCell(pga_g=float(a), pgv_pga_s=float(r), P=float(p(a, r)))
            for a in PGA_G for r in RATIO_S]


def _survival_grid(cells):
    pgas, ratios, values = cell_table(cells)
    return PulseGrid(tuple(pgas * G), tuple(ratios), np.ones(values.shape, int), values,
                     values[None], None, below="edge")


def test_a_function_bilinear_in_log_amplitudes_is_read_back_exactly_between_cells():
    rng = np.random.default_rng(5)
    a = np.exp(rng.uniform(np.log(0.2), np.log(1.1), 200))
    r = np.exp(rng.uniform(np.log(0.1), np.log(1.0), 200))
    p, outside = grid_probability(_cells(), a, r)
    assert not outside.any()
    assert p == pytest.approx(_log_bilinear(a, r), abs=1e-12)


def test_the_shake_table_check_and_survival_read_the_same_p_from_the_same_cells():
    rng = np.random.default_rng(6)
    cells = _cells(lambda a, r: rng.uniform(0, 1))
    a = np.exp(rng.uniform(np.log(0.05), np.log(3.0), 500))      # inside, beside, above, below
    r = np.exp(rng.uniform(np.log(0.03), np.log(2.0), 500))
    check, _ = grid_probability(cells, a, r)
    assert _survival_grid(cells).probability(a * G, r) == pytest.approx(check, abs=1e-12)


def test_outside_the_grid_p_is_the_nearest_edge_cells_and_the_point_is_said_outside():
    cells = _cells()
    p, outside = grid_probability(cells, np.array([3.0, 0.1, 0.5]), np.array([0.05, 0.5, 4.0]))
    assert outside.all()
    assert p == pytest.approx([_log_bilinear(1.1, 0.1), _log_bilinear(0.2, 0.5),
                               _log_bilinear(0.5, 1.0)], abs=1e-12)


def test_the_interpolation_is_free_of_units_and_of_a_one_row_grid():
    pgas, ratios, values = cell_table(_cells())
    in_g, _ = interpolate(pgas, ratios, values, 0.63, 0.27)
    in_si, _ = interpolate(pgas * G, ratios, values, 0.63 * G, 0.27)
    assert in_g == pytest.approx(in_si, abs=1e-12)
    row, _ = interpolate(pgas, ratios[:1], values[:, :1], 0.63, 0.1)
    assert row == pytest.approx(_log_bilinear(0.63, 0.1), abs=1e-12)
