"""Synthetic sites around a true source: where they lie, in which frame, the columns they
show (drawn from a forward table's members) and how far a MAP direction is off."""
import math

import numpy as np

from pipeline.inversion.observations import ColumnObservation, Observations, Site
from pipeline.stats.circular import angle_difference_deg

OBS_UNCERTAINTY_DEG = 10.0      # the measurement error of a synthetic fall direction


def site_position(r_km, alpha_deg):
    """(east, north) km of a point ``r_km`` from the origin at azimuth ``alpha_deg``."""
    a = math.radians(alpha_deg)
    return r_km * math.sin(a), r_km * math.cos(a)


def site_frame(sites_world, truth_world=(0.0, 0.0)):
    """Sites relative to the first one; the truth in that frame."""
    e0, n0 = sites_world[0][1], sites_world[0][2]
    sites = [Site(name, e - e0, n - n0, cols) for name, e, n, cols in sites_world]
    truth = (truth_world[0] - e0, truth_world[1] - n0)
    return Observations(tuple(sites), "synthetic"), truth


def draw_site_columns(pool, s, i, j, strike_deg, fallen, rng, sigma_deg=OBS_UNCERTAINTY_DEG,
                      pick_slice=None, pick_ring=None):
    """Columns at node (slice s, ring i, azimuth j) drawn from ``pool`` until ``fallen``
    have fallen: a column type and a member at random, falls turned by the strike with a
    normal measurement error of ``sigma_deg``; ``pick_slice()`` and ``pick_ring()``, when
    given, choose each column's slice and ring instead of ``s`` and ``i``.  None when no
    slice that may be picked has a fall there (the caller checks that for the pickers)."""
    if pick_slice is None and pick_ring is None and not pool.toppled[s, i, j].any():
        return None
    cols, count = [], 0
    for _ in range(50 * fallen + 50):
        k = s if pick_slice is None else pick_slice()
        ring = i if pick_ring is None else pick_ring()
        choices = np.argwhere(pool.valid[k, ring, j])
        c, m = choices[rng.integers(len(choices))]
        if pool.toppled[k, ring, j, c, m]:
            az = (pool.azimuth_deg[k, ring, j, c, m] + strike_deg
                  + rng.normal(0.0, sigma_deg)) % 360.0
            cols.append(ColumnObservation(pool.columns[c], "fallen", float(az), sigma_deg))
            count += 1
            if count == fallen:
                break
        else:
            cols.append(ColumnObservation(pool.columns[c], "standing"))
    return tuple(cols)


def map_azimuth_error(summary, true_baz):
    """The MAP back azimuth's error (deg); NaN when the summary gives no direction (the
    source may lie beyond the reach)."""
    if summary["back_azimuth_map_deg"] is None:
        return np.nan
    return angle_difference_deg(summary["back_azimuth_map_deg"], true_baz)
