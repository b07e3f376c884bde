"""The one interpolation of a pulse grid's cells: P(overturn) at any (PGA, PGV/PGA) from
the fractions of runs that overturned in the cells of ``campaign fragility --pulses``.
Survival (:class:`pipeline.hazard.fragility.PulseGrid`) and the shake-table check of a
fragility (:mod:`pipeline.campaign.pulse_check`) read P from cells through it, so the
same cells give the same P to both.

Space: bilinear in (ln PGA, ln PGV/PGA).  The fragility's smooth form, Purvance et
al.'s logistic surface, is linear in ln PGA and ln PGV/PGA (log-odds), and a rocking
body's threshold scales with ratios of these quantities (the overturning amplitude of a
block grows with omega_p / p, a ratio): equal steps in log are equal steps in what
decides overturning.  The Virtual Shake Robot's grid is linear (PGA 0.2-1.1 g, PGV/PGA
0.1-1.0 s in steps of 0.1), so its first PGV/PGA cells span a factor of 2 while its last
span 1.1: linear interpolation there would put the midpoint of a factor-2 cell at its
arithmetic mean, log at its geometric one.  Log space is also free of units (g or
m/s^2 give the same P).

Outside the grid's box: the nearest edge cell's P (the point held on the box, each
axis clipped on its own), with a mask of the points outside, so that a caller says
what it does there: the shake-table check keeps the edge P and counts the tests
outside; survival carries the logistic surface's trend from that edge P, or ramps P
below the first PGA (docs/survival.md).
"""
import numpy as np
from scipy.interpolate import RegularGridInterpolator

CONTOUR_LEVELS = (0.16, 0.5, 0.84)   # P of a pulse grid's contours: median and +-1 sigma


def lay_cells(pga_axis, ratio_axis, cells, members=0):
    """The one layout of a pulse grid's cells
    (:class:`~pipeline.hazard.fragility.file.GridCell`) on its axes ``pga_axis`` (g) x
    ``ratio_axis`` (s), each cell found by its values to 9 digits (the axes are distinct
    to 9 digits and every cell on them, checked by the file's reader): (n, overturned,
    P, P per set) as arrays n_pga x n_ratio (``members`` x n_pga x n_ratio per set, none
    without ``members``); n
    and overturned 0, P NaN where no cell is given or a set has no run."""
    index_a = {round(float(v), 9): i for i, v in enumerate(pga_axis)}
    index_r = {round(float(v), 9): j for j, v in enumerate(ratio_axis)}
    n = np.zeros((len(index_a), len(index_r)), int)
    overturned = np.zeros_like(n)
    p = np.full(n.shape, np.nan)
    per_set = np.full((members, *n.shape), np.nan)
    for cell in cells:
        i, j = index_a[round(cell.pga_g, 9)], index_r[round(cell.pgv_pga_s, 9)]
        n[i, j], overturned[i, j] = cell.n, cell.overturned
        p[i, j] = np.nan if cell.P is None else cell.P
        for s, value in zip(cell.sets or (), cell.P_per_set or ()):
            if members and value is not None:
                per_set[s, i, j] = float(value)
    return n, overturned, p, per_set


def fill_empty(values):
    """The one rule for a grid's empty cells (NaN: no run): P interpolated along PGA
    between the nearest cells with runs of its PGV/PGA row (the nearest one's beyond
    them), a row without any the mean of all.  Survival and the shake-table check score
    the same filled cells.  Returns (filled values, number of cells filled)."""
    cells = np.array(values, float)
    empty = np.isnan(cells)
    if not empty.any():
        return cells, 0
    for j in range(cells.shape[1]):
        column = cells[:, j]
        good = ~np.isnan(column)
        if good.any():
            idx = np.arange(len(column))
            cells[:, j] = np.interp(idx, idx[good], column[good])
    return np.where(np.isnan(cells), np.nanmean(cells), cells), int(empty.sum())


def interpolate(pga_axis, ratio_axis, values, pga, ratio):
    """P at (pga, ratio) from the cells ``values`` (n_pga x n_ratio, no NaN; or a stack of
    grids' cells, n_pga x n_ratio x ...) on the increasing axes (PGA and PGV/PGA, any one
    unit each, the points in the same): bilinear in (ln PGA, ln PGV/PGA), the nearest edge
    cell's P outside the grid's box (an axis of one value: along the other axis only).
    Returns (P, outside): P of the points' broadcast shape (a stack: its axes first), outside
    True where a point lies beyond the box.  A stack is one matrix product: the
    interpolant is linear in the cells' values, so its weights at the points are the
    interpolation of the unit cells, the same for every grid of the stack."""
    pga, ratio = np.broadcast_arrays(np.asarray(pga, float), np.asarray(ratio, float))
    ln_a, ln_r = np.log(np.asarray(pga_axis, float)), np.log(np.asarray(ratio_axis, float))
    with np.errstate(divide="ignore", invalid="ignore"):     # a zero is below any grid
        ln_pga, ln_ratio = np.log(pga), np.log(ratio)
    x, y = np.clip(ln_pga, ln_a[0], ln_a[-1]), np.clip(ln_ratio, ln_r[0], ln_r[-1])
    outside = (x != ln_pga) | (y != ln_ratio)
    values = np.asarray(values, float)
    shape, stack = values.shape[:2], values.shape[2:]
    cells = values if not stack else np.eye(shape[0] * shape[1]).reshape(*shape, -1)
    axes = [ln_a, ln_r]
    for k in (0, 1):           # one value: doubled a unit apart, the points lie on it
        if len(axes[k]) == 1:
            axes[k] = np.array([axes[k][0], axes[k][0] + 1.0])
            cells = np.concatenate([cells, cells], axis=k)
    p = RegularGridInterpolator(tuple(axes), cells)(np.stack([x, y], axis=-1))
    if stack:                  # the cells of each grid times the weights (points x cells)
        p = (values.reshape(p.shape[-1], -1).T @ p.reshape(-1, p.shape[-1]).T).reshape(
            stack + pga.shape)
    return np.clip(p, 0.0, 1.0, out=p), outside
