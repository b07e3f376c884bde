"""Survival under a hazard curve: plain functions on arrays.

Units: PGA levels in m/s^2, rates in 1/yr, ages in years.  ``probability`` is a
function of PGA (m/s^2, array) returning P(overturn) in one event of that PGA (already
averaged over PGV/PGA: :func:`pipeline.hazard.set_probability.overturn_probability`).

The hazard curve lambda(x) (annual rate of PGA > x) is interpolated linearly in
(ln x, ln lambda) between its levels x_1 < ... < x_N.  The annual rate of overturning is

    lambda_ov = integral_{x_1}^{x_N} P(x) |d lambda(x)| + P(x_N) lambda(x_N)

No extrapolation: below x_1 nothing is counted, and every exceedance of the last level is
counted at it (P(x_N), a lower bound as P grows with x).  What the ends hold is reported:
the share of lambda_ov in the first interval and in the top term, and the most the
exceedances of x_N could add, lambda(x_N) (P(x_0) - P(x_N)) with x_0 the level the file
gives a rate of 0 (else P = 1).  Overturnings are a Poisson process: survival of an age t
is exp(-lambda_ov t); an uncertain age (normal, truncated at 0) is integrated over.
"""
import math

import numpy as np
from scipy import optimize
from scipy.special import erfcx, log_ndtr

MAX_LN_FACTOR = 700.0         # ln of the largest factor on the rates said (exp(709) overflows)
CELLS_PER_INTERVAL = 200      # integration cells between two levels of the curve


def hazard_cells(levels_m_s2, rates_per_yr, cells=CELLS_PER_INTERVAL):
    """The log-log interpolated curve cut into ``cells`` per interval: (x_mid (m/s^2, the
    geometric midpoint), d_rate (1/yr, the rate of PGA falling in the cell), interval
    index, d_ln_x)."""
    u, v = np.log(levels_m_s2), np.log(rates_per_yr)
    t = np.linspace(0.0, 1.0, cells + 1)
    uu = u[:-1, None] + np.diff(u)[:, None] * t
    rate = np.exp(v[:-1, None] + np.diff(v)[:, None] * t)
    d_rate = rate[:, :-1] - rate[:, 1:]
    x_mid = np.exp(0.5 * (uu[:, :-1] + uu[:, 1:]))
    interval = np.repeat(np.arange(len(u) - 1), cells)
    return x_mid.ravel(), d_rate.ravel(), interval, np.diff(uu, axis=1).ravel()


def overturning_rate(levels_m_s2, rates_per_yr, probability, zero_rate_from_m_s2=None,
                     cells=CELLS_PER_INTERVAL):
    """Annual rate of overturning (1/yr) and what the curve's ends hold (see the module):
    dict rate_per_yr, within_curve_per_yr, at_last_level_per_yr, share_first_interval,
    share_at_last_level, last_level_could_add_per_yr."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.asarray(rates_per_yr, float)
    x_mid, d_rate, interval, _ = hazard_cells(levels, rates, cells)
    inside = probability(x_mid) * d_rate
    p_top = float(probability(levels[-1:])[0])
    top = p_top * rates[-1]
    total = float(inside.sum()) + top
    p_upper = 1.0 if zero_rate_from_m_s2 is None else \
        float(probability(np.array([zero_rate_from_m_s2]))[0])
    return {"rate_per_yr": total, "within_curve_per_yr": float(inside.sum()),
            "at_last_level_per_yr": top,
            "share_first_interval": float(inside[interval == 0].sum()) / total if total > 0
            else None,
            "share_at_last_level": top / total if total > 0 else None,
            "last_level_could_add_per_yr": rates[-1] * max(p_upper - p_top, 0.0)}


def contribution_by_intensity(levels_m_s2, rates_per_yr, probability,
                              cells=CELLS_PER_INTERVAL):
    """The rate of overturning by PGA interval of the curve, and at (above) the last level:
    list of dict lo_m_s2, hi_m_s2 (None above the last), rate_per_yr, share."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.asarray(rates_per_yr, float)
    x_mid, d_rate, interval, _ = hazard_cells(levels, rates, cells)
    by = np.bincount(interval, probability(x_mid) * d_rate, minlength=len(levels) - 1)
    top = float(probability(levels[-1:])[0]) * rates[-1]
    total = by.sum() + top
    rows = [{"lo_m_s2": float(lo), "hi_m_s2": float(hi), "rate_per_yr": float(r)}
            for lo, hi, r in zip(levels[:-1], levels[1:], by)]
    rows.append({"lo_m_s2": float(levels[-1]), "hi_m_s2": None, "rate_per_yr": top})
    for row in rows:
        row["share"] = row["rate_per_yr"] / total if total > 0 else None
    return rows


def rate_density(levels_m_s2, rates_per_yr, probability, cells=CELLS_PER_INTERVAL):
    """(x_mid (m/s^2), P(x) |d lambda / d ln x| (1/yr per unit ln PGA)): the
    fragility-weighted rate density whose integral over ln x is the rate within the curve."""
    x_mid, d_rate, _, d_ln_x = hazard_cells(levels_m_s2, rates_per_yr, cells)
    return x_mid, probability(x_mid) * d_rate / d_ln_x


def survival_probability(rate_per_yr, age_yr, age_sd_yr=0.0):
    """P(no overturning in the age): exp(-rate age) (Poisson), averaged over an age normal
    with mean ``age_yr`` and sd ``age_sd_yr`` truncated at 0:
    E[exp(-r T)] = exp(-r mu + r^2 s^2 / 2) Phi((mu - r s^2) / s) / Phi(mu / s).
    ``rate_per_yr`` may be an array."""
    rate = np.asarray(rate_per_yr, float)
    if age_sd_yr == 0:
        return np.exp(-rate * age_yr)
    mu, s = float(age_yr), float(age_sd_yr)
    a = (mu - rate * s * s) / s
    with np.errstate(over="ignore", invalid="ignore"):
        # a < 0: -r mu + r^2 s^2 / 2 + ln Phi(a) = a^2/2 + ln Phi(a) - mu^2 / (2 s^2), and
        # a^2/2 + ln Phi(a) = ln(erfcx(-a / sqrt 2) / 2): no difference of huge numbers
        below = np.log(erfcx(-a / math.sqrt(2.0)) / 2.0) - 0.5 * (mu / s) ** 2
        above = -rate * mu + 0.5 * (rate * s) ** 2 + log_ndtr(a)
    log_p = np.where(a < 0, below, above) - log_ndtr(mu / s)
    return np.exp(log_p)


def rate_scale_bound(rate_per_yr, age, floor):
    """The largest factor F by which every rate of the hazard curve can be multiplied and
    still leave survival >= ``floor``: -ln(floor) / (rate age) for a known age, else the
    root of survival(F rate) = floor over the age ``age`` (an
    :class:`~pipeline.hazard.ages.AgeModel`).  None when the rate is 0 (no bound) or F would
    pass exp(MAX_LN_FACTOR) (a rate so small that no factor a float holds reaches
    ``floor``)."""
    if not rate_per_yr > 0:
        return None
    ln_rate = math.log(rate_per_yr)
    known = age.fixed_yr
    ln_closed = math.log(-math.log(floor)) - ln_rate - math.log(
        age.typical_yr if known is None else known)
    if ln_closed > MAX_LN_FACTOR:
        return None
    if known is not None:
        return math.exp(ln_closed)
    def excess(ln_f):
        return float(age.survival(math.exp(ln_f + ln_rate))) - floor
    hi = ln_closed
    for _ in range(60):                # survival falls to 0 as F grows: a bracket exists
        if excess(hi) <= 0:
            break
        hi += math.log(10.0)
    lo = hi - math.log(10.0)
    for _ in range(60):
        if excess(lo) >= 0:
            break
        lo -= math.log(10.0)
    root = optimize.brentq(excess, lo, hi, xtol=1e-10)
    return None if root > MAX_LN_FACTOR else math.exp(root)


def intensity_scale_bound(levels_m_s2, rates_per_yr, probability, age, floor,
                          zero_rate_from_m_s2=None, limits=(1e-3, 1e3)):
    """The largest factor c by which the curve's intensities can be multiplied
    (lambda_c(x) = lambda(x / c)) and still leave survival >= ``floor`` over the age
    ``age`` (an :class:`~pipeline.hazard.ages.AgeModel`); (c, note): c None with a note
    when survival stays on one side of ``floor`` over ``limits``."""
    levels = np.asarray(levels_m_s2, float)

    def excess(ln_c):
        c = math.exp(ln_c)
        zero = None if zero_rate_from_m_s2 is None else zero_rate_from_m_s2 * c
        rate = overturning_rate(levels * c, rates_per_yr, probability, zero)["rate_per_yr"]
        return float(age.survival(rate)) - floor

    lo, hi = math.log(limits[0]), math.log(limits[1])
    if excess(hi) >= 0:
        return None, f"survival stays >= {floor:g} up to {limits[1]:g} x the intensities"
    if excess(lo) < 0:
        return None, f"survival is below {floor:g} even at {limits[0]:g} x the intensities"
    return math.exp(optimize.brentq(excess, lo, hi, xtol=1e-8)), None


def rate_outside(levels_m_s2, rates_per_yr, probability, lo_m_s2, hi_m_s2,
                 cells=CELLS_PER_INTERVAL):
    """The parts of the rate of overturning (1/yr) from PGA below ``lo_m_s2`` and above
    ``hi_m_s2`` (e.g. outside a fragility's grid): (below, above), the exceedances of the
    curve's last level counted above when that level lies above ``hi_m_s2``."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.asarray(rates_per_yr, float)
    x_mid, d_rate, _, _ = hazard_cells(levels, rates, cells)
    part = probability(x_mid) * d_rate
    top = float(probability(levels[-1:])[0]) * rates[-1]
    above = float(part[x_mid > hi_m_s2].sum()) + (top if levels[-1] > hi_m_s2 else 0.0)
    return float(part[x_mid < lo_m_s2].sum()), above


def rate_exceeding(levels_m_s2, rates_per_yr, x_m_s2):
    """The annual rate (1/yr) of PGA above ``x_m_s2`` as the rate of overturning counts
    the curve: lambda(x) interpolated in (ln x, ln lambda) inside it, lambda(x_1) below
    its first level (nothing below x_1 is counted) and 0 from its last level up (the
    exceedances of x_N are counted at x_N)."""
    levels = np.asarray(levels_m_s2, float)
    rates = np.asarray(rates_per_yr, float)
    if x_m_s2 >= levels[-1]:
        return 0.0
    if x_m_s2 <= levels[0]:
        return float(rates[0])
    return float(np.exp(np.interp(math.log(x_m_s2), np.log(levels), np.log(rates))))
