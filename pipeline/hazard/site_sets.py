"""Survival of a set of specimens: at one site, specimens of different known ages that the
same earthquakes shake; over sites, the product of each site's survival.

At one site the specimens overturn independently given the motion of an event
(:func:`pipeline.hazard.fragility_ratio.overturn_probability`, ``combine="any_common"``);
the events are a Poisson process.  With the ages sorted, t_1 <= ... <= t_n, the events
of the last t_1 years met every specimen, those between t_k-1 and t_k years ago only the
specimens at least t_k old.  The probability that all survived is

    exp(-sum_k (t_k - t_k-1) lambda_any(S_k)),   t_0 = 0,

S_k the specimens at least t_k old and lambda_any(S) the annual rate of events that
overturn any of S (a rate of overturning computed with P_any = 1 - prod_S (1 - P_i)).
Sites far enough apart that one earthquake does not shake two of them hard are taken as
independent: the set's survival is the product of the sites'.  Ages in years, rates in
1/yr.
"""
import math

import numpy as np

from pipeline.files import InputError


def site_set_survival(ages_yr, any_rate_per_yr):
    """P(every specimen of one site survived) for known ``ages_yr`` (one per specimen);
    ``any_rate_per_yr(indices)``: the annual rate of events that overturn any of the
    specimens ``indices`` (a tuple of positions in ``ages_yr``)."""
    ages = np.asarray(ages_yr, float)
    if ages.ndim != 1 or ages.size == 0:
        raise InputError("a site set needs at least one specimen's age")
    if not (np.all(np.isfinite(ages)) and np.all(ages >= 0)):
        raise InputError("ages must be finite and not negative (years)")
    order = np.argsort(ages, kind="stable")
    exponent, before = 0.0, 0.0
    for k, position in enumerate(order):
        span = ages[position] - before
        if span > 0:
            exponent += span * any_rate_per_yr(tuple(int(i) for i in order[k:]))
        before = ages[position]
    return math.exp(-exponent)


def sites_survival(site_survivals):
    """P(every specimen of every site survived): the product of the sites' survivals
    (sites that no one earthquake shakes hard together)."""
    values = np.asarray(site_survivals, float)
    if values.size == 0 or np.any((values < 0) | (values > 1)) or not np.all(
            np.isfinite(values)):
        raise InputError("site survivals must be probabilities in [0, 1], at least one")
    return float(np.prod(values))
