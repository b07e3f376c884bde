"""What standing and fallen columns at one site say about the motion there: the range of
PGA (at a stated PGV/PGA) under which the observed outcome is likely.

Each column's outcome is a range of damage states (:mod:`pipeline.hazard.damage_states`):
fallen is collapse, standing is none to severe, a standing column whose damage state was
seen is that state, and one whose drums were seen shifted is at least the state the
shift gives.  The columns are taken as independent given the motion (each ends in a state
with its own fragility's P at that motion); one event is assumed to have decided them
all.  The likelihood over PGA is L(a) = prod_i P_i(lowest_i <= DS <= highest_i | a), for
fallen and standing alone prod_fallen P_i(a) prod_standing (1 - P_i(a)); the estimate is
its maximum and the interval the likelihood-ratio one, 2 (ln L_max - ln L(a)) <=
chi2_1(0.95) = 3.84 (an open end when every column's outcome reaches collapse, or every
column's starts at none: L then only grows, or only falls, with PGA).
"""
import math

import numpy as np
from scipy import optimize, stats

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.damage_states import COLLAPSE, STATES, StateFragility

LR_DROP_95 = 0.5 * stats.chi2.ppf(0.95, 1)     # 1.92: ln L below the maximum at the ends
PGA_RANGE_M_S2 = (1e-3, 1e3)                   # the search range, 0.0001-100 g
PGV_PGA_RANGE_S = (0.001, 10.0)                # a stated PGV/PGA (s) the range is found at
GRID = 2001


def _per_state(fragility):
    """A :class:`StateFragility` of a column's fragility (P(topple) alone when it is one)."""
    return fragility if isinstance(fragility, StateFragility) else \
        StateFragility.toppling(fragility)


def _state_range(outcome):
    """(lowest, highest) state index of an outcome: a (lowest, highest) pair, or a
    boolean fell (collapse) or stands (none to severe)."""
    if isinstance(outcome, (bool, np.bool_)):
        return (COLLAPSE, COLLAPSE) if outcome else (0, COLLAPSE - 1)
    lowest, highest = (int(s) for s in outcome)
    if not 0 <= lowest <= highest <= COLLAPSE or (lowest, highest) == (0, COLLAPSE):
        raise InputError(f"damage states {lowest}-{highest}: not an observed range")
    return lowest, highest


def log_likelihood(pga_m_s2, fragilities, outcomes, pgv_pga_s=None):
    """ln L at PGA levels (m/s^2): ``fragilities`` one per column (a fragility of
    toppling, or a :class:`StateFragility`), ``outcomes`` one per column: fell (a boolean)
    or the (lowest, highest) damage states it is in."""
    pga = np.atleast_1d(np.asarray(pga_m_s2, float))
    total = np.zeros(pga.shape)
    tiny = np.finfo(float).tiny
    ratio = None if pgv_pga_s is None else np.full(pga.shape, float(pgv_pga_s))
    for fragility, outcome in zip(fragilities, outcomes):
        p = _per_state(fragility).probability(*_state_range(outcome), pga, ratio)
        total += np.log(np.maximum(p, tiny))
    return total


def motion_bound(fragilities, outcomes, pgv_pga_s=None):
    """The maximum-likelihood PGA and its 95 % likelihood-ratio interval (m/s^2) given the
    columns' fragilities and outcomes (:func:`log_likelihood`); dict for the JSON."""
    ranges = [_state_range(o) for o in outcomes]
    if not ranges:
        raise InputError("no columns at the site")
    fragilities = [_per_state(f) for f in fragilities]
    for k, (fragility, (lowest, highest)) in enumerate(zip(fragilities, ranges)):
        missing = fragility.missing(lowest, highest)
        if missing:
            raise InputError(f"column {k + 1}: its observed damage state needs the fragility "
                             f"of state {STATES[missing[0]]!r}, which is not given")
    if any(f.uses_ratio for f in fragilities) and pgv_pga_s is None:
        raise InputError("the fragility depends on PGV/PGA: give --at-pgv-pga")
    outcomes = ranges
    ln_a = np.linspace(*np.log(PGA_RANGE_M_S2), GRID)
    ll = log_likelihood(np.exp(ln_a), fragilities, outcomes, pgv_pga_s)
    k = int(np.argmax(ll))
    def negative(x):
        return -float(log_likelihood(math.exp(x), fragilities, outcomes, pgv_pga_s)[0])
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
    n_fallen = sum(h == COLLAPSE for _, h in outcomes)
    rising = all(h == COLLAPSE for _, h in outcomes)       # L only grows with PGA
    falling = all(low == 0 for low, _ in outcomes)         # L only falls
    estimate = None if rising or falling else math.exp(best_ln)
    g = STANDARD_GRAVITY
    note = "every column stands: an upper bound on PGA only" if falling else \
        "every column fell: a lower bound on PGA only" if rising else None
    return {
        "columns": len(outcomes), "fallen": n_fallen, "standing": len(outcomes) - n_fallen,
        "column_states": [{"lowest": STATES[a], "highest": STATES[b]} for a, b in outcomes],
        "pgv_pga_s": pgv_pga_s,
        "pga_ml_m_s2": estimate, "pga_ml_g": None if estimate is None else estimate / g,
        "pga_interval95_m_s2": [lo, hi],
        "pga_interval95_g": [None if v is None else v / g for v in (lo, hi)],
        "note": note,
        "definition": "L(PGA) = prod_i P_i(lowest_i <= DS <= highest_i | PGA): fallen "
                      "P_i(collapse), standing 1 - P_i(collapse), a standing column's "
                      "observed damage states P_i(DS >= lowest) - P_i(DS >= highest + 1); "
                      "the columns independent given the motion of one event; pga_ml: its "
                      "maximum; pga_interval95: 2 (ln L_max - ln L) <= 3.84 (chi2, 1 dof), "
                      "null where the interval stays open",
        "search_range_m_s2": list(PGA_RANGE_M_S2)}


def site_motion(observations, site_name, fragility_for, pgv_pga_s=None):
    """:func:`motion_bound` for the site ``site_name`` of ``observations``
    (:class:`~pipeline.inversion.observations.Observations`, each column's outcome its
    ``state_range``); ``fragility_for(column)`` gives a column type's fragility (of
    toppling, or a :class:`StateFragility`)."""
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
    outcomes = [c.state_range for c in site.columns]
    for k, (column, (lowest, highest)) in enumerate(zip(site.columns, outcomes)):
        fragility = _per_state(cache[column.column])
        missing = fragility.missing(lowest, highest)
        if missing:
            seen = STATES[lowest] if lowest == highest else f"at least {STATES[lowest]}"
            raise InputError(f"{observations.source}: site {site_name!r}, column {k + 1} "
                             f"({column.column}): observed {seen}, which needs the "
                             f"fragility of damage state {STATES[missing[0]]!r}; it is not "
                             "given" + ("" if fragility.source is None else
                                        f" ({fragility.source})"))
    result = motion_bound(fragilities, outcomes, pgv_pga_s)
    per_state = {name: _per_state(f) for name, f in cache.items()}
    states = {name: f.describe_states() for name, f in per_state.items()
              if f.describe_states()}
    sources = {name: f.source for name, f in per_state.items() if f.source is not None}
    return {"site": site_name, "observations": observations.source, **result,
            "fragilities": {name: f.collapse.describe() for name, f in per_state.items()},
            **({"state_fragilities": states} if states else {}),
            **({"state_fragilities_from": sources} if sources else {})}
