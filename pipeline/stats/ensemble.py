"""Statistics of ensembles: toppling probability with its Wilson interval, the mean
downfall azimuth with a bootstrap interval, direction fractions, circular density,
and lognormal fragility curves fitted by maximum likelihood."""
import math

import numpy as np
from scipy import optimize, stats

from pipeline.constants import MODEL_GRAVITY
from pipeline.stats.circular import (AWAY_MIN_DEG as AWAY, TOWARD_MAX_DEG as TOWARD,
                                     angle_difference_deg, circular_summary, direction_class,
                                     mean_direction_error_deg)


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


# ---------------------------------------------------------------- binary regressions
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


def separated(X, y):
    """True when a hyperplane separates the outcomes (complete or quasi-complete
    separation): then the maximum-likelihood estimate of a logit or probit model does
    not exist.  Linear program of Konis (2007): maximise sum_i s_i x_i.b subject to
    s_i x_i.b >= 0 and |b_j| <= 1 (s_i = +1 toppled, -1 not); separated when positive.
    """
    X = np.asarray(X, float)
    s = np.where(np.asarray(y, bool), 1.0, -1.0)
    Z = X * s[:, None]
    scale = np.abs(Z).max(axis=0)
    Z = Z / np.where(scale > 0, scale, 1.0)
    res = optimize.linprog(-Z.sum(axis=0), A_ub=-Z, b_ub=np.zeros(len(Z)),
                           bounds=[(-1.0, 1.0)] * X.shape[1], method="highs")
    return bool(res.status == 0 and -res.fun > 1e-7 * len(Z))


def binary_regression(X, y, link="logit", firth=False):
    """Maximum-likelihood (or Firth-penalised) binary regression P(y) = F(X b).

    link: "logit" or "probit"; firth: maximise log L + (1/2) ln det I(b) (Firth 1993,
    finite also under separation).  Plain logit ML uses statsmodels' ``Logit`` when
    statsmodels is installed, else scipy.optimize (Newton steps in a trust region with
    the analytic gradient and Fisher information; valid for the logit link, whose
    observed and expected information coincide).
    Returns dict: coefficients, se, ci95 (Wald, from the inverse Fisher information),
    cov, log_likelihood, converged, method (which estimator and library).
    """
    X = np.asarray(X, float)
    y = np.asarray(y, bool).astype(float)
    if link not in ("logit", "probit"):
        raise ValueError(f"unknown link {link!r}")

    def parts(b):
        eta = X @ b
        if link == "logit":
            log_p, log_q = -np.logaddexp(0.0, -eta), -np.logaddexp(0.0, eta)
            p = np.exp(log_p)
            w = p * (1.0 - p)
            score = X.T @ (y - p)
        else:
            log_p, log_q = stats.norm.logcdf(eta), stats.norm.logsf(eta)
            pdf = stats.norm.pdf(eta)
            w = pdf ** 2 / np.maximum(np.exp(log_p) * np.exp(log_q), 1e-300)
            ratio = np.where(y > 0, np.exp(stats.norm.logpdf(eta) - log_p),
                             -np.exp(stats.norm.logpdf(eta) - log_q))
            score = X.T @ ratio
        loglik = float(np.sum(y * log_p + (1.0 - y) * log_q))
        info = X.T @ (X * w[:, None])
        return loglik, score, info

    method = None
    if link == "logit" and not firth:
        try:
            import statsmodels.api as sm
        except ImportError:
            sm = None
        if sm is not None:
            import warnings
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fit = sm.Logit(y, X).fit(disp=0, maxiter=200)
            b = np.asarray(fit.params, float)
            method = "maximum likelihood (statsmodels Logit, Newton)"
            converged = bool(fit.mle_retvals.get("converged", True))
    if method is None:
        def objective(b):
            loglik, score, info = parts(b)
            if not firth:
                return -loglik, -score
            sign, logdet = np.linalg.slogdet(info)
            return -(loglik + 0.5 * (logdet if sign > 0 else -1e6))

        start = np.zeros(X.shape[1])
        if firth:
            fit = optimize.minimize(objective, start, method="Nelder-Mead",
                                    options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 20000,
                                             "maxfev": 40000})
            fit = optimize.minimize(objective, fit.x, method="BFGS")
        else:   # concave log-likelihood: Newton steps in a trust region
            fit = optimize.minimize(objective, start, jac=True, hess=lambda b: parts(b)[2],
                                    method="trust-exact", options={"gtol": 1e-9})
        b, converged = fit.x, bool(fit.success)
        method = ("Firth-penalised likelihood" + f" ({link}, scipy.optimize Nelder-Mead + BFGS)"
                  if firth else f"maximum likelihood ({link}, scipy.optimize trust-exact Newton)")
    loglik, _, info = parts(b)
    try:
        cov = np.linalg.inv(info)
    except np.linalg.LinAlgError:
        cov = np.full((X.shape[1],) * 2, np.nan)
    se = np.sqrt(np.abs(np.diag(cov)))
    z = stats.norm.ppf(0.975)
    return {"coefficients": [float(v) for v in b], "se": [float(v) for v in se],
            "ci95": [[float(v - z * e), float(v + z * e)] for v, e in zip(b, se)],
            "cov": cov.tolist(), "log_likelihood": loglik, "converged": converged,
            "method": method}


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
    return 1.0 / (1.0 + np.exp(-eta))


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


# ---------------------------------------------------------------- ensembles compared
def compare_ensembles(toppled_a, azimuths_a, toppled_b, azimuths_b, min_falls=5):
    """Do two ensembles of one record and column (e.g. two numerical settings) sample one
    distribution?  P(toppled) by Fisher's exact test on the 2 x 2 counts, the fall
    directions (deg; NaN for standing members) by Kuiper's two-sample test (astropy;
    invariant to where the circle is cut), with at least ``min_falls`` falls in each.
    Returns p-values (None where a test does not apply) and the difference of P(toppled)
    with its Monte Carlo error (binomial, the two ensembles independent)."""
    from astropy.stats import kuiper_two
    ta, tb = np.asarray(toppled_a, bool), np.asarray(toppled_b, bool)
    ka, kb, na, nb = int(ta.sum()), int(tb.sum()), ta.size, tb.size
    p_fisher = float(stats.fisher_exact([[ka, na - ka], [kb, nb - kb]])[1]) if na and nb else None
    fa = np.asarray(azimuths_a, float)
    fb = np.asarray(azimuths_b, float)
    fa, fb = fa[np.isfinite(fa)], fb[np.isfinite(fb)]
    p_kuiper = None
    if fa.size >= min_falls and fb.size >= min_falls:
        p_kuiper = float(kuiper_two(np.mod(fa, 360.0) / 360.0, np.mod(fb, 360.0) / 360.0)[1])
    pa, pb = (ka / na if na else math.nan), (kb / nb if nb else math.nan)
    error = math.sqrt(pa * (1 - pa) / na + pb * (1 - pb) / nb) if na and nb else math.nan
    return {"p_toppled_difference": pb - pa, "p_toppled_difference_mc_error": error,
            "fisher_p": p_fisher, "kuiper_p": p_kuiper, "falls": [int(fa.size), int(fb.size)]}


def holm_reject(p_values, alpha=0.05):
    """Holm's step-down rejections (list of bool, None for a None p-value) of a family of
    tests at family-wise level ``alpha``."""
    given = [(p, i) for i, p in enumerate(p_values) if p is not None]
    reject = [None if p is None else False for p in p_values]
    for rank, (p, i) in enumerate(sorted(given)):
        if p > alpha / (len(given) - rank):
            break
        reject[i] = True
    return reject


# ---------------------------------------------------------------- pooled over records
NO_RELATION = {"fraction_toward": 0.25, "fraction_away": 0.25, "fraction_transverse": 0.5,
               "radial_alignment": 0.0, "polarity": 0.0}   # falls that ignore the epicentre


def _pooled(toppled, relative):
    """Record-weighted statistics of one (re)sample: lists per record of toppled flags
    (bool arrays) and fall-minus-back-azimuth angles of the falls (deg)."""
    p = float(np.mean([t.mean() for t in toppled]))
    with_falls = [r for r in relative if r.size]
    if not with_falls:
        return {"p_toppled": p, **dict.fromkeys(NO_RELATION)}
    size = [np.abs(angle_difference_deg(r, 0.0)) for r in with_falls]
    rad = [np.radians(r) for r in with_falls]
    return {"p_toppled": p,
            "fraction_toward": float(np.mean([(s <= TOWARD).mean() for s in size])),
            "fraction_away": float(np.mean([(s >= AWAY).mean() for s in size])),
            "fraction_transverse": float(np.mean([((s > TOWARD) & (s < AWAY)).mean()
                                                  for s in size])),
            "radial_alignment": float(np.mean([np.cos(2 * r).mean() for r in rad])),
            "polarity": float(np.mean([np.cos(r).mean() for r in rad]))}


def pooled_answer(toppled, relative_deg, resamples=2000, seed=0, confidence=0.95):
    """The paper's question over records: does a column fall toward (or away from) the
    epicentre?  ``toppled``: per record, the members' toppled flags; ``relative_deg``:
    per record, the members' downfall minus back azimuth (deg; NaN when standing).

    Every record weighs alike (a record's falls share its weight): P(toppled); the
    fractions of falls toward (|diff| <= 45 deg), away (>= 135) and transverse; the
    radial alignment, mean cos(2 diff) (+1 along the epicentre line, -1 across it, 0 no
    relation); the polarity, mean cos(diff) (+1 toward, -1 away).  Intervals: a two-stage
    percentile bootstrap, records drawn with replacement and then each drawn record's
    members, so that they hold both the choice of records and the ensembles' Monte Carlo
    error; ``mc_error``: the bootstrap standard deviation.  ``no_relation``: the values
    of falls that ignore the epicentre; ``differs``: the interval excludes it."""
    toppled = [np.asarray(t, bool) for t in toppled]
    relative = [np.asarray(r, float) for r in relative_deg]
    if not toppled or len(toppled) != len(relative) or any(
            t.size == 0 or t.size != r.size for t, r in zip(toppled, relative)):
        raise ValueError("pooled_answer needs, per record, as many members as directions")
    falls = [r[t & np.isfinite(r)] for t, r in zip(toppled, relative)]
    estimate = _pooled(toppled, falls)
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(resamples):
        picked = rng.integers(0, len(toppled), len(toppled))
        t_draw, f_draw = [], []
        for k in picked:
            members = rng.integers(0, toppled[k].size, toppled[k].size)
            t, r = toppled[k][members], relative[k][members]
            t_draw.append(t)
            f_draw.append(r[t & np.isfinite(r)])
        draws.append(_pooled(t_draw, f_draw))
    tail = 50.0 * (1.0 - confidence)
    out = {"records": len(toppled), "members": int(sum(t.size for t in toppled)),
           "records_with_falls": int(sum(f.size > 0 for f in falls)),
           "falls": int(sum(f.size for f in falls)), "resamples": resamples, "seed": seed,
           "confidence": confidence, "statistics": {}}
    for name, value in estimate.items():
        values = np.array([d[name] for d in draws if d[name] is not None], float)
        ok = value is not None and values.size >= 0.5 * resamples
        ci = [float(v) for v in np.percentile(values, [tail, 100 - tail])] if ok else None
        reference = NO_RELATION.get(name)
        out["statistics"][name] = {
            "estimate": value, "ci95": ci, "mc_error": float(values.std(ddof=1)) if ok else None,
            "no_relation": reference,
            "differs": None if reference is None or ci is None
            else bool(not ci[0] <= reference <= ci[1])}
    return out


QUESTION = ("Do the columns fall toward (or away from) the epicentre?  Hinzen (2009) asked it "
            "of single runs; here every record's ensemble answers, pooled over the records.")


def pooled_summary(runs, resamples=2000):
    """The paper's question over the records of an ensemble campaign that have a back
    azimuth (:func:`pooled_answer` per column: every record
    weighs alike; intervals hold the choice of records and the members' Monte Carlo
    error); None for fewer than two such records."""
    members = runs[(runs["member"] >= 0) & runs["back_azimuth_deg"].notna()]
    records = list(dict.fromkeys(members["record_id"]))
    if len(records) < 2:
        return None
    columns = []
    for column, group in members.groupby("column", sort=True):
        toppled, relative = [], []
        for record_id in records:
            sub = group[group["record_id"] == record_id].sort_values("member")
            t = sub["toppled"].astype(bool).to_numpy()
            toppled.append(t)
            relative.append(np.where(t, angle_difference_deg(
                sub["downfall_azimuth_deg"].to_numpy(float),
                sub["back_azimuth_deg"].to_numpy(float)), np.nan))
        answer = pooled_answer(toppled, relative, resamples=resamples)
        columns.append({"column": column, **answer, "answer": pooled_sentence(answer)})
    return {"question": QUESTION, "records": len(records), "record_ids": records,
            "members_per_record": {r: int((members["record_id"] == r).sum()
                                          / members["column"].nunique()) for r in records},
            "columns": columns}


def pooled_sentence(answer):
    """One sentence: what the pooled fall directions say of the epicentre's direction."""
    st = answer["statistics"]

    def value(name, digits=2):
        s = st[name]
        return (f"{s['estimate']:.{digits}f} [{s['ci95'][0]:.{digits}f}, "
                f"{s['ci95'][1]:.{digits}f}]")

    p = f"P(toppled) {value('p_toppled')} per record"
    if answer["falls"] < 2 or st["polarity"]["ci95"] is None:
        return f"{p}; too few falls to say where they point"
    polar, radial = st["polarity"], st["radial_alignment"]
    if polar["differs"]:
        side = "toward" if polar["estimate"] > 0 else "away from"
        finding = f"falls lean {side} the epicentre (polarity {value('polarity')}, 0: no relation)"
    elif radial["differs"]:
        side = "along" if radial["estimate"] > 0 else "across"
        finding = (f"falls gather {side} the epicentre line, as often toward as away "
                   f"(radial alignment {value('radial_alignment')}, 0: no relation)")
    else:
        finding = (f"the fall directions show no relation to the epicentre's direction "
                   f"(polarity {value('polarity')}, radial alignment "
                   f"{value('radial_alignment')}; 0: no relation)")
    return (f"{p}; {finding}; toward {value('fraction_toward')}, away "
            f"{value('fraction_away')} of the falls (0.25 each without a relation)")


def record_summary(runs, record_id, seed):
    """An ensemble campaign's ``ensemble_summary.json`` content of one record (runs:
    its runs table with ``member``, -1 the nominal run)."""
    back = runs["back_azimuth_deg"].dropna()
    back = float(back.iloc[0]) if len(back) else None
    members = runs[runs["member"] >= 0]
    columns = []
    for column, group in members.groupby("column", sort=True):
        fell = group[group["toppled"].astype(bool)]
        az = fell["downfall_azimuth_deg"].to_numpy(float)
        stats = circular_summary(az)
        nominal_row = runs[(runs["member"] == -1) & (runs["column"] == column)]
        nominal_az = (None if nominal_row.empty or not np.isfinite(
            nominal_row["downfall_azimuth_deg"].iloc[0]) else
            float(nominal_row["downfall_azimuth_deg"].iloc[0]))
        columns.append({
            "column": column, "members": int(len(group)), "toppled": int(len(fell)),
            "p_toppled": float(len(fell) / len(group)),
            "p_toppled_ci95": wilson_interval(len(fell), len(group)),
            "p_toppled_mc_error": float(math.sqrt(len(fell) * (len(group) - len(fell))
                                                  / len(group) ** 3)),
            "mean_azimuth_mc_error_deg": mean_direction_error_deg(az),
            "mean_downfall_azimuth_deg": None if not len(fell) or not np.isfinite(
                stats["mean_deg"]) else stats["mean_deg"],
            "resultant_length": None if not len(fell) else stats["resultant_length"],
            "mean_azimuth_ci95_deg": bootstrap_mean_azimuth_ci(az),
            **direction_fractions(az, back),
            "nominal_toppled": None if nominal_row.empty else bool(
                nominal_row["toppled"].iloc[0]),
            "nominal_downfall_azimuth_deg": nominal_az,
            "impact_time_s_median": None if not len(fell) else float(
                np.median(fell["impact_time_s"]))})
    return {"record": record_id, "members": int(members["member"].nunique()), "seed": seed,
            "back_azimuth_deg": back, "columns": columns}
