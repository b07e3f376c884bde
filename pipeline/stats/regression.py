"""Binary regressions of outcomes (toppled or not) on covariates: the test for separation
of the outcomes (Konis 2007) and maximum-likelihood or Firth-penalised logit and probit
fits with Wald intervals."""
import numpy as np
from scipy import optimize, stats
import warnings


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
    fitted = _statsmodels_logit(X, y) if link == "logit" and not firth else None
    b, converged, method = fitted or _scipy_fit(X, y, link, firth)
    loglik, _, info = _likelihood_parts(X, y, b, link)
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


def _likelihood_parts(X, y, b, link):
    """(log-likelihood, score, Fisher information) of coefficients ``b``."""
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


def _statsmodels_logit(X, y):
    """(coefficients, converged, method) of statsmodels' Logit, or None without it."""
    try:
        import statsmodels.api as sm  # lazy: statsmodels is slow to import
    except ImportError:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = sm.Logit(y, X).fit(disp=0, maxiter=200)
    return (np.asarray(fit.params, float), bool(fit.mle_retvals.get("converged", True)),
            "maximum likelihood (statsmodels Logit, Newton)")


def _scipy_fit(X, y, link, firth):
    """(coefficients, converged, method) by scipy.optimize: Firth's penalised likelihood
    (Nelder-Mead, then BFGS) or the concave log-likelihood by Newton steps in a trust
    region."""
    def objective(b):
        loglik, score, info = _likelihood_parts(X, y, b, link)
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
    else:
        fit = optimize.minimize(objective, start, jac=True,
                                hess=lambda b: _likelihood_parts(X, y, b, link)[2],
                                method="trust-exact", options={"gtol": 1e-9})
    method = ("Firth-penalised likelihood" + f" ({link}, scipy.optimize Nelder-Mead + BFGS)"
              if firth else f"maximum likelihood ({link}, scipy.optimize trust-exact Newton)")
    return fit.x, bool(fit.success), method
