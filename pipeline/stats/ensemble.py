"""Statistics of ensembles: toppling probability with its Wilson interval, the mean
downfall azimuth with a bootstrap interval, direction fractions, circular density,
and lognormal fragility curves fitted by maximum likelihood."""
import math

import numpy as np
from scipy import optimize, stats

from pipeline.stats.circular import angle_difference_deg, circular_summary, direction_class


def wilson_interval(successes, trials, confidence=0.95):
    """Wilson score interval [lo, hi] of a binomial proportion; [0, 1] without trials."""
    if trials == 0:
        return [0.0, 1.0]
    ci = stats.binomtest(int(successes), int(trials)).proportion_ci(confidence, method="wilson")
    return [float(ci.low), float(ci.high)]


def bootstrap_mean_azimuth_ci(azimuths_deg, confidence=0.95, resamples=2000, seed=0):
    """[lo, hi] (deg, clockwise from lo to hi) of the circular mean azimuth by a percentile
    bootstrap; None for fewer than two directions or no defined mean."""
    angles = np.asarray(azimuths_deg, float)
    angles = angles[np.isfinite(angles)]
    mean = circular_summary(angles)["mean_deg"] if angles.size else np.nan
    if angles.size < 2 or not np.isfinite(mean):
        return None
    rng = np.random.default_rng(seed)
    samples = np.radians(angles[rng.integers(0, angles.size, (resamples, angles.size))])
    means = np.degrees(np.arctan2(np.sin(samples).sum(axis=1), np.cos(samples).sum(axis=1)))
    offsets = angle_difference_deg(means, mean)
    tail = 50.0 * (1.0 - confidence)
    lo, hi = np.nanpercentile(offsets, [tail, 100.0 - tail])
    return [float((mean + lo) % 360.0), float((mean + hi) % 360.0)]


def direction_fractions(azimuths_deg, back_azimuth_deg):
    """Fractions of falls toward / away from / transverse to the epicentre (None without a
    back azimuth or without falls)."""
    angles = np.asarray(azimuths_deg, float)
    angles = angles[np.isfinite(angles)]
    if back_azimuth_deg is None or not angles.size:
        return {"fraction_toward": None, "fraction_away": None, "fraction_transverse": None}
    classes = direction_class(angle_difference_deg(angles, back_azimuth_deg))
    return {f"fraction_{c}": float(np.mean(classes == c))
            for c in ("toward", "away", "transverse")}


def circular_density(azimuths_deg, grid_deg, kappa=20.0):
    """Von Mises kernel density (1/deg) of azimuths on ``grid_deg``; kappa sets the width
    (20: about 13 deg)."""
    angles = np.radians(np.asarray(azimuths_deg, float))[:, None]
    grid = np.radians(np.asarray(grid_deg, float))[None, :]
    if angles.size == 0:
        return np.zeros(grid.shape[1])
    density = stats.vonmises.pdf(grid - angles, kappa).mean(axis=0)
    return density * math.pi / 180.0


def lognormal_fragility(im, toppled):
    """Maximum-likelihood lognormal fragility P(toppled | IM) = Phi(ln(IM / median) / beta).

    Returns dict(median, beta, median_ci95, beta_ci95, n): intervals from the observed
    information (delta method on ln median and ln beta).  IM > 0.
    """
    im = np.asarray(im, float)
    y = np.asarray(toppled, bool)
    keep = np.isfinite(im) & (im > 0)
    x, y = np.log(im[keep]), y[keep]
    if x.size < 2 or y.all() or not y.any():
        return {"median": None, "beta": None, "median_ci95": None, "beta_ci95": None,
                "n": int(x.size)}

    def nll(theta):
        mu, log_beta = theta
        z = (x - mu) / math.exp(log_beta)
        return -(stats.norm.logcdf(z)[y].sum() + stats.norm.logsf(z)[~y].sum())

    start = [float(np.median(x)), math.log(max(np.std(x), 0.1))]
    fit = optimize.minimize(nll, start, method="BFGS")
    mu, log_beta = fit.x
    cov = fit.hess_inv if np.all(np.isfinite(fit.hess_inv)) else np.full((2, 2), np.nan)
    se_mu, se_lb = np.sqrt(np.abs(np.diag(cov)))
    z = stats.norm.ppf(0.975)
    return {"median": float(math.exp(mu)), "beta": float(math.exp(log_beta)),
            "median_ci95": [float(math.exp(mu - z * se_mu)), float(math.exp(mu + z * se_mu))],
            "beta_ci95": [float(math.exp(log_beta - z * se_lb)),
                          float(math.exp(log_beta + z * se_lb))],
            "n": int(x.size)}
