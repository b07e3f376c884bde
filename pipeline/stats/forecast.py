"""Scores of probability forecasts of yes/no outcomes (a rock overturned or not), as a
forecaster reads them: log-likelihood, the Brier score and its decomposition, accuracy
and balanced accuracy of P > 0.5, and the data of a reliability diagram.

Plain functions on arrays: ``observed`` 0/1 (or bool), ``p`` forecast probabilities in
[0, 1], ``runs`` the Monte Carlo runs behind each P (None: a 0/1 or exact forecast).

- **Log-likelihood** (nats per test) takes P clipped away from 0 and 1
  (:func:`clipped`): a P estimated from n runs that all agree is no certainty, so it is
  held within 1/(2(n + 1)) of 0 or 1 (the Jeffreys-prior posterior mean of a proportion
  whose n trials all agree: 0.1 for 4 runs, 0.056 for 8); a forecast without Monte
  Carlo error (a single parameter set, a 0/1 model) within :data:`FLOOR` (0.01, as the
  pulse-grid fragility's check against the tests), so that a certain wrong forecast costs
  ln 0.01, not -inf.
- **Brier score** BS = mean (P - o)^2 on the raw P, and Murphy's (1973) decomposition
  over the bins :data:`BIN_EDGES` (ten of width 0.1, the last closed at 1):
  REL = sum_k n_k (f_k - o_k)^2 / N, RES = sum_k n_k (o_k - o)^2 / N, UNC = o (1 - o)
  (f_k, o_k: mean forecast and observed rate in bin k; o: the overall rate).
  BS = REL - RES + UNC holds exactly when the forecasts within each bin are equal (the
  P = k/n of 4 or 8 members fall in separate bins); otherwise the difference is the
  within-bin term (Stephenson, Coelho & Jolliffe 2008, Weather and Forecasting 23),
  returned as ``within_bin``.
- **Reliability diagram**: per bin the mean forecast and the observed rate with its
  Wilson 95 % interval (scipy's ``binomtest(...).proportion_ci(method="wilson")``).
"""
import numpy as np

from pipeline.stats.ensemble import wilson_interval

FLOOR = 0.01                      # clip of a forecast without Monte Carlo error
BIN_EDGES = np.round(np.linspace(0.0, 1.0, 11), 10)
THRESHOLD = 0.5                   # P above it: predicted overturned


def _arrays(observed, p):
    y = np.asarray(observed, float).ravel()
    q = np.asarray(p, float).ravel()
    if y.shape != q.shape:
        raise ValueError("observed and forecasts differ in length")
    if not np.isin(y, (0.0, 1.0)).all():
        raise ValueError("observed outcomes must be 0 or 1")
    if not (np.isfinite(q).all() and ((q >= 0) & (q <= 1)).all()):
        raise ValueError("forecast probabilities must be in [0, 1]")
    return y, q


def clip_margin(runs=None, floor=FLOOR):
    """How far from 0 and 1 a forecast is held for its log-likelihood: 1/(2(n + 1)) for a
    P from n Monte Carlo runs (array or number), ``floor`` without runs (None)."""
    if runs is None:
        return floor
    n = np.asarray(runs, float)
    if (n < 1).any():
        raise ValueError("a forecast from Monte Carlo runs needs at least one run")
    return np.maximum(0.5 / (n + 1.0), floor)


def clipped(p, runs=None, floor=FLOOR):
    """P held within :func:`clip_margin` of 0 and 1."""
    c = clip_margin(runs, floor)
    return np.clip(np.asarray(p, float), c, 1.0 - c)


def log_likelihood(observed, p, runs=None, floor=FLOOR):
    """Mean log-likelihood per test (nats) of the outcomes under the clipped forecasts."""
    y, q = _arrays(observed, p)
    q = clipped(q, None if runs is None else np.asarray(runs, float).ravel(), floor)
    return float(np.mean(y * np.log(q) + (1.0 - y) * np.log(1.0 - q))) if y.size else None


def bin_index(p, edges=BIN_EDGES):
    """Bin of each forecast: [e_k, e_k+1), the last bin closed at its upper edge."""
    return np.clip(np.searchsorted(edges, np.asarray(p, float), side="right") - 1,
                   0, len(edges) - 2)


def brier_decomposition(observed, p, edges=BIN_EDGES):
    """{"brier", "reliability", "resolution", "uncertainty", "within_bin"} (Murphy 1973;
    ``within_bin`` = BS - (REL - RES + UNC), zero when forecasts within a bin are
    equal); None for each with no forecast."""
    y, q = _arrays(observed, p)
    if not y.size:
        return {k: None for k in ("brier", "reliability", "resolution", "uncertainty",
                                  "within_bin")}
    k = bin_index(q, edges)
    n = np.bincount(k, minlength=len(edges) - 1).astype(float)
    used = n > 0
    f = np.bincount(k, weights=q, minlength=len(n))[used] / n[used]
    o = np.bincount(k, weights=y, minlength=len(n))[used] / n[used]
    base = float(y.mean())
    brier = float(np.mean((q - y) ** 2))
    rel = float(np.sum(n[used] * (f - o) ** 2) / y.size)
    res = float(np.sum(n[used] * (o - base) ** 2) / y.size)
    unc = base * (1.0 - base)
    return {"brier": brier, "reliability": rel, "resolution": res, "uncertainty": unc,
            "within_bin": brier - (rel - res + unc)}


def classification(observed, p, threshold=THRESHOLD):
    """Accuracy and balanced accuracy (the mean of the rates of overturned and of standing
    tests called right; None when one class is absent) of "overturned when P > threshold"."""
    y, q = _arrays(observed, p)
    called = q > threshold
    fell = y.astype(bool)
    if not y.size:
        return {"accuracy": None, "balanced_accuracy": None}
    rates = [float(np.mean(called[c] == fell[c])) for c in (fell, ~fell) if c.any()]
    return {"accuracy": float(np.mean(called == fell)),
            "balanced_accuracy": float(np.mean(rates)) if len(rates) == 2 else None}


def reliability_table(observed, p, edges=BIN_EDGES, confidence=0.95):
    """Per bin with forecasts: edges, n, mean forecast, observed rate and its Wilson
    interval (the reliability diagram's points)."""
    y, q = _arrays(observed, p)
    k = bin_index(q, edges)
    rows = []
    for b in range(len(edges) - 1):
        inside = k == b
        n = int(inside.sum())
        if not n:
            continue
        hits = int(y[inside].sum())
        rows.append({"bin": [float(edges[b]), float(edges[b + 1])], "n": n,
                     "mean_forecast": float(q[inside].mean()), "overturned": hits,
                     "observed_rate": hits / n,
                     "observed_ci95": wilson_interval(hits, n, confidence)})
    return rows


def forecast_scores(observed, p, runs=None, edges=BIN_EDGES):
    """Every score of one set of forecasts: n, log-likelihood per test, the Brier
    decomposition, accuracy and balanced accuracy of P > 0.5, the reliability table, and
    the clip used (``clip``: the margin, or [smallest, largest] when the tests' runs
    differ)."""
    y, q = _arrays(observed, p)
    margin = clip_margin(None if runs is None else np.asarray(runs, float).ravel())
    clip = (float(margin) if np.ndim(margin) == 0 or not np.size(margin)
            else [float(np.min(margin)), float(np.max(margin))])
    if isinstance(clip, list) and clip[0] == clip[1]:
        clip = clip[0]
    return {"n": int(y.size), "overturned": int(y.sum()),
            "log_likelihood_per_test": log_likelihood(y, q, runs),
            **brier_decomposition(y, q, edges), **classification(y, q),
            "clip": clip, "reliability_diagram": reliability_table(y, q, edges)}



def end_bins(p, edges=BIN_EDGES):
    """Bin of each forecast with the certain forecasts apart: 0 for P = 0, k + 1 for
    (0, e_1) and [e_k, e_k+1) (k >= 1), len(edges) for P = 1."""
    q = np.asarray(p, float)
    inner = np.clip(np.searchsorted(edges, q, side="right") - 1, 0, len(edges) - 2) + 1
    return np.where(q == 0.0, 0, np.where(q == 1.0, len(edges), inner))


def end_bin_label(b, edges=BIN_EDGES):
    """The text of bin ``b`` of :func:`end_bins`: "P = 0", "(0, 0.1)", "[0.1, 0.2)", ...,
    "[0.9, 1)", "P = 1"."""
    if b == 0:
        return "P = 0"
    if b == len(edges):
        return "P = 1"
    lo, hi = edges[b - 1], edges[b]
    return f"{'(' if b == 1 else '['}{lo:g}, {hi:g})"


def reliability_with_ends(observed, p, runs=None, edges=BIN_EDGES, confidence=0.95):
    """The reliability diagram's rows (as :func:`reliability_table`'s, with ``label``)
    over :func:`end_bins`: the forecasts P = 0 and P = 1 each a bin of their own, so that
    a model's certainties are checked apart from its near-certainties.  ``covers``: the
    bin's mean forecast, P held as for the log-likelihood (:func:`clipped`: 1/(2(n + 1))
    from 0 and 1 for a P of n runs, ``runs`` None: :data:`FLOOR`), lies within the
    observed rate's Wilson interval."""
    y, q = _arrays(observed, p)
    k = end_bins(q, edges)
    held = clipped(q, None if runs is None else np.asarray(runs, float).ravel())
    rows = []
    for b in range(len(edges) + 1):
        inside = k == b
        n = int(inside.sum())
        if not n:
            continue
        hits = int(y[inside].sum())
        lo, hi = wilson_interval(hits, n, confidence)
        mean_held = float(held[inside].mean())
        rows.append({"label": end_bin_label(b, edges), "n": n,
                     "mean_forecast": float(q[inside].mean()), "mean_forecast_held": mean_held,
                     "overturned": hits, "observed_rate": hits / n,
                     "observed_ci95": [lo, hi], "covers": bool(lo <= mean_held <= hi)})
    return rows
