"""The one interpolation of a pulse grid's cells: the shake-table check and survival read
the same P from the same cells; bilinear in (ln PGA, ln PGV/PGA); the edge cell's P
outside the grid, said."""
import numpy as np
import pytest

from pipeline.campaign.pulse_check import grid_probability
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.fragility import PulseGrid
from pipeline.hazard.fragility.file import GridCell, PulseGridSection
from pipeline.hazard.pulse_cells import fill_empty, interpolate, lay_cells

PGA_G = np.round(np.linspace(0.2, 1.1, 10), 9)           # the Virtual Shake Robot's grid
RATIO_S = np.round(np.linspace(0.1, 1.0, 10), 9)
SECTION = PulseGridSection(pga_g=tuple(PGA_G), pgv_pga_s=tuple(RATIO_S))


def _log_bilinear(a, r):
    """A function bilinear in (ln a, ln r), in [0, 1] on the grid."""
    x, y = np.log(a / 0.2) / np.log(5.5), np.log(r / 0.1) / np.log(10.0)
    return 0.1 + 0.5 * x + 0.2 * y + 0.15 * x * y


def _cells(p=_log_bilinear):
    return [GridCell(pga_g=float(a), pgv_pga_s=float(r), P=float(p(a, r)))
            for a in PGA_G for r in RATIO_S]


def _survival_grid(cells):
    pgas, ratios = PGA_G, RATIO_S
    values = lay_cells(pgas, ratios, cells)[2]
    return PulseGrid(tuple(pgas * G), tuple(ratios), np.ones(values.shape, int), values,
                     values[None], None, below="edge")


def test_a_function_bilinear_in_log_amplitudes_is_read_back_exactly_between_cells():
    rng = np.random.default_rng(5)
    a = np.exp(rng.uniform(np.log(0.2), np.log(1.1), 200))
    r = np.exp(rng.uniform(np.log(0.1), np.log(1.0), 200))
    p, outside = grid_probability(SECTION, _cells(), a, r)[:2]
    assert not outside.any()
    assert p == pytest.approx(_log_bilinear(a, r), abs=1e-12)


def test_the_shake_table_check_and_survival_read_the_same_p_from_the_same_cells():
    rng = np.random.default_rng(6)
    cells = _cells(lambda a, r: rng.uniform(0, 1))
    a = np.exp(rng.uniform(np.log(0.05), np.log(3.0), 500))      # inside, beside, above, below
    r = np.exp(rng.uniform(np.log(0.03), np.log(2.0), 500))
    check, _ = grid_probability(SECTION, cells, a, r)[:2]
    assert _survival_grid(cells).probability(a * G, r) == pytest.approx(check, abs=1e-12)


def test_outside_the_grid_p_is_the_nearest_edge_cells_and_the_point_is_said_outside():
    cells = _cells()
    p, outside = grid_probability(SECTION, cells, np.array([3.0, 0.1, 0.5]),
                                  np.array([0.05, 0.5, 4.0]))[:2]
    assert outside.all()
    assert p == pytest.approx([_log_bilinear(1.1, 0.1), _log_bilinear(0.2, 0.5),
                               _log_bilinear(0.5, 1.0)], abs=1e-12)


def test_the_interpolation_is_free_of_units_and_of_a_one_row_grid():
    pgas, ratios, values = PGA_G, RATIO_S, lay_cells(PGA_G, RATIO_S, _cells())[2]
    in_g, _ = interpolate(pgas, ratios, values, 0.63, 0.27)
    in_si, _ = interpolate(pgas * G, ratios, values, 0.63 * G, 0.27)
    assert in_g == pytest.approx(in_si, abs=1e-12)
    row, _ = interpolate(pgas, ratios[:1], values[:, :1], 0.63, 0.1)
    assert row == pytest.approx(_log_bilinear(0.63, 0.1), abs=1e-12)


def test_an_empty_cell_is_filled_alike_for_survival_and_the_shake_table_check():
    """One rule for a cell without runs: the check scores the grid survival reads (the
    cell interpolated along PGA between its neighbours), and says how many it filled."""
    cells = [c for c in _cells() if not (c.pga_g == PGA_G[4] and c.pgv_pga_s == RATIO_S[3])]
    n = np.array([[0 if (a == PGA_G[4] and r == RATIO_S[3]) else 1 for r in RATIO_S]
                  for a in PGA_G])
    values = lay_cells(PGA_G, RATIO_S, cells)[2]
    grid = PulseGrid(tuple(PGA_G * G), tuple(RATIO_S), n, np.nan_to_num(values), values[None],
                     None, below="edge")
    a, r = np.array([PGA_G[4], 0.5, 0.9]), np.array([RATIO_S[3], 0.3, 0.7])
    check, _, filled = grid_probability(SECTION, cells, a, r)
    assert filled == 1
    assert grid.probability(a * G, r) == pytest.approx(check, abs=1e-12)
    # the filled cell: the mean of its PGA neighbours (equal steps of index)
    neighbours = (_log_bilinear(PGA_G[3], RATIO_S[3]) + _log_bilinear(PGA_G[5], RATIO_S[3])) / 2
    assert check[0] == pytest.approx(neighbours, abs=1e-12)
    assert fill_empty(values)[1] == 1


@pytest.mark.parametrize("axes", [((0.1, 0.2, 0.4), (0.1, 0.5)), ((0.3,), (0.1, 0.5, 1.0)),
                                  ((0.1, 0.2), (0.7,))])
def test_a_stack_of_grids_gives_each_grid_alone(axes):
    """A stack (the weights at the points times every grid's cells) against each grid
    interpolated alone, points inside, beside and beyond the box, an axis of one value."""
    values = np.random.default_rng(0).random((len(axes[0]), len(axes[1]), 5, 3))
    a, r = np.geomspace(0.05, 0.6, 7)[:, None], np.geomspace(0.05, 2.0, 4)[None, :]
    stacked, outside = interpolate(*axes, values, a, r)
    alone = [[interpolate(*axes, values[..., i, j], a, r) for j in range(3)]
             for i in range(5)]
    assert stacked.shape == (5, 3, 7, 4)
    np.testing.assert_allclose(stacked, [[p for p, _ in row] for row in alone],
                               rtol=1e-14, atol=1e-15)
    assert np.array_equal(outside, alone[0][0][1])
