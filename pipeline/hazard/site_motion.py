"""What standing and fallen columns at one site say about the motion there: the range of
PGA (at a stated PGV/PGA) under which the observed outcome is likely.

The columns are taken as independent given the motion (each falls with its own fragility's
P at that motion); one event is assumed to have decided them all.  The likelihood over PGA
is L(a) = prod_fallen P_i(a) prod_standing (1 - P_i(a)); the estimate is its maximum and
the interval the likelihood-ratio one, 2 (ln L_max - ln L(a)) <= chi2_1(0.95) = 3.84 (an
open end when every column fell, or every column stands).
"""
import math

import numpy as np
from scipy import optimize, stats

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError

LR_DROP_95 = 0.5 * stats.chi2.ppf(0.95, 1)     # 1.92: ln L below the maximum at the ends
PGA_RANGE_M_S2 = (1e-3, 1e3)                   # the search range, 0.0001-100 g
GRID = 2001


def log_likelihood(pga_m_s2, fragilities, fallen, pgv_pga_s=None):
    """ln L at PGA levels (m/s^2): ``fragilities`` one per column, ``fallen`` booleans."""
    pga = np.atleast_1d(np.asarray(pga_m_s2, float))
    total = np.zeros(pga.shape)
    tiny = np.finfo(float).tiny
    for fragility, fell in zip(fragilities, fallen):
        ratio = None if pgv_pga_s is None else np.full(pga.shape, float(pgv_pga_s))
        p = fragility.probability(pga, ratio) if fragility.uses_ratio else \
            fragility.probability(pga)
        total += np.log(np.maximum(p if fell else 1.0 - p, tiny))
    return total


def motion_bound(fragilities, fallen, pgv_pga_s=None):
    """The maximum-likelihood PGA and its 95 % likelihood-ratio interval (m/s^2) given the
    columns' fragilities and which fell; dict for the JSON."""
    fallen = [bool(f) for f in fallen]
    if not fallen:
        raise InputError("no columns at the site")
    if any(f.uses_ratio for f in fragilities) and pgv_pga_s is None:
        raise InputError("the fragility depends on PGV/PGA: give --at-pgv-pga")
    ln_a = np.linspace(*np.log(PGA_RANGE_M_S2), GRID)
    ll = log_likelihood(np.exp(ln_a), fragilities, fallen, pgv_pga_s)
    k = int(np.argmax(ll))
    def negative(x):
        return -float(log_likelihood(math.exp(x), fragilities, fallen, pgv_pga_s)[0])
    best_ln = ln_a[k]
    if 0 < k < GRID - 1:
        best_ln = optimize.minimize_scalar(negative, bounds=(ln_a[k - 1], ln_a[k + 1]),
                                           method="bounded",
                                           options={"xatol": 1e-10}).x
    ll_max = -negative(best_ln)
    def excess(x):
        return -negative(x) - (ll_max - LR_DROP_95)
    ends = []
    low = ll < ll_max - LR_DROP_95
    for side in (ln_a[(ln_a < best_ln) & low], ln_a[(ln_a > best_ln) & low][::-1]):
        outside = side
        if not len(outside):
            ends.append(None)
            continue
        edge = outside[-1]
        ends.append(math.exp(optimize.brentq(excess, min(edge, best_ln), max(edge, best_ln),
                                             xtol=1e-12)))
    lo, hi = ends
    n_fallen = sum(fallen)
    estimate = None if n_fallen in (0, len(fallen)) else math.exp(best_ln)
    g = STANDARD_GRAVITY
    return {
        "columns": len(fallen), "fallen": n_fallen, "standing": len(fallen) - n_fallen,
        "pgv_pga_s": pgv_pga_s,
        "pga_ml_m_s2": estimate, "pga_ml_g": None if estimate is None else estimate / g,
        "pga_interval95_m_s2": [lo, hi],
        "pga_interval95_g": [None if v is None else v / g for v in (lo, hi)],
        "note": {0: "every column stands: an upper bound on PGA only",
                 len(fallen): "every column fell: a lower bound on PGA only"}.get(n_fallen),
        "definition": "L(PGA) = prod_fallen P_i(PGA) prod_standing (1 - P_i(PGA)), the "
                      "columns independent given the motion of one event; pga_ml: its "
                      "maximum; pga_interval95: 2 (ln L_max - ln L) <= 3.84 (chi2, 1 dof), "
                      "null where the interval stays open",
        "search_range_m_s2": list(PGA_RANGE_M_S2)}


def site_motion(observations, site_name, fragility_for, pgv_pga_s=None):
    """:func:`motion_bound` for the site ``site_name`` of ``observations``
    (:class:`~pipeline.inversion.observations.Observations`); ``fragility_for(column)``
    gives a column type's fragility."""
    names = [s.name for s in observations.sites]
    if site_name not in names:
        raise InputError(f"{observations.source}: no site {site_name!r} (has "
                         f"{', '.join(map(str, names))})")
    site = observations.sites[names.index(site_name)]
    cache = {}
    fragilities = []
    for column in site.columns:
        if column.column not in cache:
            cache[column.column] = fragility_for(column.column)
        fragilities.append(cache[column.column])
    result = motion_bound(fragilities, [c.fallen for c in site.columns], pgv_pga_s)
    result = {"site": site_name, "observations": observations.source, **result,
              "fragilities": {name: f.describe() for name, f in cache.items()}}
    return result
