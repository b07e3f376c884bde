"""Where do the falls point? A grid search for the point whose directions (axial)
best explain the downfall azimuths at sites with known positions (km, East/North)."""
import math

import numpy as np
import pandas as pd

from pipeline.stats.circular import direction_differences


def axial_misfit(x_km, y_km, downfall_deg, px_km, py_km):
    """Mean of sin^2(downfall - azimuth from site to P) over sites, for points P.

    0 when every fall lies on the line through its site and P (toward or
    away), 1 when all are transverse, 0.5 expected for random directions.
    ``px_km``/``py_km`` are arrays of candidate points (any shape); sites
    coinciding with P count 0.5.
    """
    px, py = np.asarray(px_km, float)[..., None], np.asarray(py_km, float)[..., None]
    dx, dy = px - np.asarray(x_km, float), py - np.asarray(y_km, float)
    term = np.sin(np.radians(np.asarray(downfall_deg, float)) - np.arctan2(dx, dy)) ** 2
    term = np.where(np.hypot(dx, dy) < 1e-9, 0.5, term)
    return term.mean(axis=-1)


def locate_source_from_falls(runs, extent_km=30.0, step_km=0.25, reference_points=None):
    """Grid search for the point whose directions best explain the falls (axial).

    For each source (if ``runs`` has a ``source`` column) and column type, and
    for both column types together ('all'), minimises :func:`axial_misfit`
    over a square grid of half-width ``extent_km`` around the epicentre.
    Returns a DataFrame: n_falls, best_x_km, best_y_km, error_km (to the
    epicentre at the origin), at_grid_edge (True: the minimum is not
    constrained inside the grid), misfit_best, misfit_epicentre and, for
    known sources, error_rupture_centre_km (to the middle of the sub-event
    line) given as ``reference_points`` = {source: (x_km, y_km)}.
    """
    frame = direction_differences(runs)
    frame = frame[frame["direction_class"] != "not toppled"]
    by_source = frame.groupby("source") if "source" in frame.columns else [(None, frame)]
    grid = np.arange(-extent_km, extent_km + step_km / 2, step_km)
    gx, gy = np.meshgrid(grid, grid)
    rows = []
    for source, source_runs in by_source:
        groups = [(c, g) for c, g in source_runs.groupby("column")] + [("all", source_runs)]
        for column, group in groups:
            row = {"source": source, "column": column, "n_falls": len(group)}
            if len(group):
                args = (group["x_km"], group["y_km"], group["downfall_azimuth_deg"])
                misfit = axial_misfit(*args, gx, gy)
                best = np.unravel_index(np.argmin(misfit), misfit.shape)
                bx, by = float(gx[best]), float(gy[best])
                row.update({"best_x_km": bx, "best_y_km": by, "error_km": math.hypot(bx, by),
                            "at_grid_edge": bool(max(abs(bx), abs(by)) >= grid[-1] - 1e-9),
                            "misfit_best": float(misfit[best]),
                            "misfit_epicentre": float(axial_misfit(*args, 0.0, 0.0))})
                if reference_points and source in reference_points:
                    cx, cy = reference_points[source]
                    row["error_rupture_centre_km"] = math.hypot(bx - cx, by - cy)
            rows.append(row)
    return pd.DataFrame(rows)
