"""Fragility fitted to campaign outcomes: lognormal fragility curves P(toppled | IM) by
maximum likelihood (Firth's probit under separation), observed fractions per IM bin with
Wilson intervals, and Purvance's logistic surface in ln PGA (m/s^2) and ln PGV/PGA (s)."""
import math

import numpy as np
from scipy import optimize, special, stats

from pipeline.constants import MODEL_GRAVITY
from pipeline.stats.ensemble import wilson_interval
from pipeline.stats.regression import binary_regression, separated


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


def binned_fractions(im, toppled, max_bins=8):
    """Observed fraction toppled per IM bin with its Wilson interval.

    Bins: one per distinct IM value when there are at most ``max_bins`` of them
    (an intensity ladder), else ``max_bins`` bins equally wide in ln IM.  Returns
    a list of dicts: lo, hi (bin edges), im (geometric mean of the IM in the bin),
    n, toppled, fraction, ci95 ([lo, hi], Wilson).
    """
    im = np.asarray(im, float)
    y = np.asarray(toppled, bool)
    keep = np.isfinite(im) & (im > 0)
    im, y = im[keep], y[keep]
    if not im.size:
        return []
    distinct = np.unique(np.round(np.log(im), 9))
    if distinct.size <= max_bins:
        middles = 0.5 * (distinct[1:] + distinct[:-1])
        edges = np.concatenate([[distinct[0] - 1e-6], middles, [distinct[-1] + 1e-6]])
    else:
        edges = np.linspace(distinct[0] - 1e-9, distinct[-1] + 1e-9, max_bins + 1)
    index = np.clip(np.searchsorted(edges, np.log(im), side="right") - 1, 0, edges.size - 2)
    out = []
    for b in range(edges.size - 1):
        inside = index == b
        if not inside.any():
            continue
        k, n = int(y[inside].sum()), int(inside.sum())
        out.append({"lo": float(math.exp(edges[b])), "hi": float(math.exp(edges[b + 1])),
                    "im": float(np.exp(np.log(im[inside]).mean())), "n": n, "toppled": k,
                    "fraction": k / n, "ci95": wilson_interval(k, n)})
    return out


LOGISTIC_SURFACE_FORM = "logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s)"


def logistic_surface(pga, pgv_pga, toppled, alpha=None, p=None, g=MODEL_GRAVITY):
    """Two-parameter logistic fragility surface after Purvance et al. (2008):
    logit P(toppled) = b0 + b1 ln PGA + b2 ln(PGV/PGA) (PGA in m/s^2, PGV/PGA in s),
    fitted by maximum likelihood (statsmodels when installed, else scipy.optimize;
    ``method`` says which); under separation of the outcomes, where the ML estimate
    does not exist, by Firth's penalised likelihood (``separated`` true).

    With the block's alpha (rad) and p (1/s) the same surface is also given in
    Purvance's dimensionless groups, logit P = c0 + b1 ln(PGA / (g tan alpha)) +
    b2 ln(p PGV/PGA), c0 = b0 + b1 ln(g tan alpha) - b2 ln p (``dimensionless``).
    Returns dict: form, coefficients {b0, b1, b2}, se, ci95, cov (3 x 3, b0-b2), n,
    toppled, method, separated, converged, log_likelihood[, dimensionless]; coefficients None when
    every run has the same outcome or fewer than 3 runs.
    """
    pga = np.asarray(pga, float)
    ratio = np.asarray(pgv_pga, float)
    y = np.asarray(toppled, bool)
    keep = np.isfinite(pga) & np.isfinite(ratio) & (pga > 0) & (ratio > 0)
    pga, ratio, y = pga[keep], ratio[keep], y[keep]
    out = {"form": LOGISTIC_SURFACE_FORM, "n": int(y.size), "toppled": int(y.sum())}
    if y.size < 3 or y.all() or not y.any():
        return {**out, "coefficients": None, "se": None, "ci95": None, "cov": None,
                "method": None, "separated": None, "converged": None, "log_likelihood": None,
                "note": "every run has the same outcome (or fewer than 3 runs): not fitted"}
    X = np.column_stack([np.ones(y.size), np.log(pga), np.log(ratio)])
    note = None
    if np.unique(np.round(X[:, 2], 9)).size < 2:
        X = X[:, :2]
        note = "one PGV/PGA value only: b2 not identified, fitted without it (b2 = 0)"
    split = separated(X, y)
    fit = binary_regression(X, y, "logit", firth=split)
    names = ["b0", "b1", "b2"]
    coef = dict(zip(names, fit["coefficients"] + [0.0] * (3 - X.shape[1])))
    se = dict(zip(names, fit["se"] + [None] * (3 - X.shape[1])))
    ci = dict(zip(names, fit["ci95"] + [None] * (3 - X.shape[1])))
    if split:
        note = ((note + "; ") if note else "") + (
            "the outcomes are separable in (ln PGA, ln PGV/PGA): the maximum-likelihood "
            "estimate does not exist; Firth-penalised estimate")
    cov = np.zeros((3, 3))
    cov[:X.shape[1], :X.shape[1]] = fit["cov"]      # b2 fixed at 0: no variance
    out.update(coefficients=coef, se=se, ci95=ci, cov=cov.tolist(), method=fit["method"],
               separated=split, converged=fit["converged"],
               log_likelihood=fit["log_likelihood"], note=note)
    if alpha is not None and p is not None:
        c0 = coef["b0"] + coef["b1"] * math.log(g * math.tan(alpha)) - coef["b2"] * math.log(p)
        out["dimensionless"] = {
            "form": "logit P = c0 + b1 ln(PGA / (g tan alpha)) + b2 ln(p PGV/PGA)",
            "c0": c0, "b1": coef["b1"], "b2": coef["b2"], "alpha_rad": alpha, "p_per_s": p}
    return out


def logistic_probability(coefficients, pga, pgv_pga):
    """P(toppled) of a logistic surface (``logistic_surface(...)["coefficients"]``)."""
    eta = (coefficients["b0"] + coefficients["b1"] * np.log(pga)
           + coefficients["b2"] * np.log(pgv_pga))
    return special.expit(eta)              # no overflow for any eta


def fragility_fit(im, toppled, min_distinct=3):
    """Lognormal fragility P(toppled | IM) = Phi(ln(IM / median) / beta) for campaign data.

    Maximum likelihood (:func:`lognormal_fragility`) when it exists; when the outcomes
    are separated by an IM value (every run below it stood, every run above fell, the
    ML beta is 0) Firth's penalised probit in ln IM instead (``method`` says which,
    ``separated`` true).  Not fitted (median None, with a ``note``) when every run has
    the same outcome, when fewer than ``min_distinct`` distinct IM values were run
    (e.g. PGV/PGA, unchanged by scaling, with fewer records than that), or when the
    toppled fraction does not grow with the IM.  Adds n_distinct, toppled, method.
    """
    im = np.asarray(im, float)
    y = np.asarray(toppled, bool)
    keep = np.isfinite(im) & (im > 0)
    im, y = im[keep], y[keep]
    distinct = int(np.unique(np.round(np.log(im), 9)).size) if im.size else 0
    empty = {"median": None, "beta": None, "median_ci95": None, "beta_ci95": None,
             "n": int(im.size), "toppled": int(y.sum()), "n_distinct": distinct,
             "method": None, "separated": None}
    if not y.any() or y.all():
        return {**empty, "note": "every run has the same outcome: not fitted"}
    if distinct < min_distinct:
        return {**empty, "note": f"{distinct} distinct IM value(s) (< {min_distinct}): "
                "the curve is not identified"}
    x = np.log(im)
    X = np.column_stack([np.ones(x.size), x])
    slope = binary_regression(X, y, "logit", firth=True)["coefficients"][1]
    if slope <= 0:
        return {**empty, "note": "the toppled fraction does not grow with this IM: not fitted"}
    if not separated(X, y):
        fit = lognormal_fragility(im, y)
        return {**fit, "toppled": int(y.sum()), "n_distinct": distinct,
                "method": "maximum likelihood (scipy.optimize BFGS)", "separated": False,
                "note": None}
    # Firth probit: z = b0 + b1 ln IM, median = exp(-b0 / b1), beta = 1 / b1
    centre, spread = float(x.mean()), float(x.std()) or 1.0
    Xs = np.column_stack([np.ones(x.size), (x - centre) / spread])
    fit = binary_regression(Xs, y, "probit", firth=True)
    c0, c1 = fit["coefficients"]
    cov = np.asarray(fit["cov"])
    b1 = c1 / spread
    ln_median = centre - c0 * spread / c1
    g_median = np.array([-spread / c1, c0 * spread / c1 ** 2])   # d ln median / d(c0, c1)
    g_beta = np.array([0.0, -1.0 / c1])                          # d ln beta / d(c0, c1)
    se_m = float(np.sqrt(max(g_median @ cov @ g_median, 0.0)))
    se_b = float(np.sqrt(max(g_beta @ cov @ g_beta, 0.0)))
    z = stats.norm.ppf(0.975)
    beta = 1.0 / b1
    return {"median": float(math.exp(ln_median)), "beta": float(beta),
            "median_ci95": [float(math.exp(ln_median - z * se_m)),
                            float(math.exp(ln_median + z * se_m))],
            "beta_ci95": [float(beta * math.exp(-z * se_b)), float(beta * math.exp(z * se_b))],
            "n": int(im.size), "toppled": int(y.sum()), "n_distinct": distinct,
            "method": "Firth-penalised probit (scipy.optimize)", "separated": True,
            "note": "the outcomes are separated in IM: the maximum-likelihood beta is 0; "
                    "Firth-penalised estimate"}
