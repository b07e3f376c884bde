"""Do the observations look like what any candidate within the reach would produce?

A posterior predictive check (Gelman, Meng & Stern 1996): for candidates drawn from the
posterior, replicate observations of the same design (the same number of columns of each
type at each site) are drawn from the model at the candidate, and the discrepancy

    T = sum over columns of log(1 - P) (standing) or log(P d(psi)) (fallen at psi)

(the independent log-likelihood at the candidate, the directions on a grid every
``PSI_GRID_DEG``) of the observations is compared with the replicates'.  The p-value is
the share of replicates with T at most the observations'.  A source beyond the reach
that no candidate can imitate (falls in directions or numbers the table gives nowhere
within it) makes T low against every candidate: a p-value below :data:`FIT_P_VALUE` puts
a ``fit_warning`` in the summary.  The replicates follow the likelihood in use: with
``predictive``, each site's columns of one type are drawn by its urn (a fresh column
from the node's distribution with probability A / (A + j), else a copy of an earlier one
of the site, its direction re-measured), so that columns sharing a site's motion are not
taken for a misfit.  A check, not a proof: a source beyond the reach that a candidate
within it imitates (a weaker shaking read as a smaller magnitude) passes it.
"""
import math

import numpy as np

PSI_GRID_DEG = 5.0
DRAWS = 16                   # posterior candidates drawn
REPLICATES = 32              # replicate observations per candidate
FIT_P_VALUE = 0.01           # below it: fit_warning (false alarms measured by the study)
FIT_SEED = 20261128


def fit_check(model, observations, post, draws=DRAWS, replicates=REPLICATES,
              seed=FIT_SEED):
    """{"fit_p_value": share of replicates at most as probable as the observations,
    "fit_warning": a line or None} at ``draws`` candidates drawn from ``post``."""
    rng = np.random.default_rng(seed)
    flat = rng.choice(post.probability.size, size=draws, p=post.probability.ravel())
    s_idx, f_idx, e_idx = np.unravel_index(flat, post.probability.shape)
    epicentres, e_pick = np.unique(e_idx, return_inverse=True)
    strikes = post.strikes_deg
    psi = np.arange(0.0, 360.0, PSI_GRID_DEG)
    t_obs, t_rep = np.zeros(draws), np.zeros((draws, replicates))
    for site in observations.sites:
        by_type = {}
        for obs in site.columns:
            by_type.setdefault(obs.column, []).append(obs)
        for column, group in by_type.items():
            sigma = float(np.mean([o.uncertainty_deg for o in group if o.fallen] or [10.0]))
            q, f = model.column_distribution(site, column, post.east_km[epicentres],
                                             post.north_km[epicentres], strikes, psi, sigma)
            log_q = np.log(q[s_idx, f_idx, e_pick])                       # (draws,)
            log_f = np.log(f[:, s_idx, f_idx, e_pick]).T                  # (draws, npsi)
            t_obs += _discrepancy(group, log_q, log_f)
            weight = model.urn_weight(model.column_index(column)) \
                if model.likelihood == "predictive" else math.inf
            t_rep += _replicates(len(group), log_q, log_f, weight, sigma, replicates, rng)
    p_value = float(np.mean(t_rep <= t_obs[:, None]))
    warning = None
    if p_value < FIT_P_VALUE:
        warning = (f"the observations fit none of the probable candidates (posterior "
                   f"predictive p-value {p_value:.3g}): the source may lie beyond what "
                   "the forward table reaches, and its direction is not known either")
    return {"fit_p_value": p_value, "fit_warning": warning}


def _discrepancy(group, log_q, log_f):
    """T of the observed columns ``group`` at each drawn candidate: (draws,)."""
    total = np.zeros(log_q.shape)
    for obs in group:
        if obs.fallen:
            k = int(round(obs.downfall_azimuth_deg / PSI_GRID_DEG)) % log_f.shape[1]
            total += log_f[:, k]
        else:
            total += log_q
    return total


def _replicates(n_columns, log_q, log_f, weight, sigma_deg, replicates, rng):
    """T of ``replicates`` replicate sets of ``n_columns`` columns at each candidate:
    (draws, replicates); the urn of weight ``weight`` (inf: independent columns)."""
    draws, npsi = log_f.shape
    p_fall = np.clip(np.exp(log_f).sum(axis=1) * math.radians(PSI_GRID_DEG), 0.0, 1.0)
    cdf = np.cumsum(np.exp(log_f), axis=1)
    cdf /= cdf[:, -1:]
    shape = (draws, replicates)
    state = np.zeros(shape + (n_columns,), int)      # -1 standing, else the psi index
    noise = math.sqrt(2.0) * sigma_deg / PSI_GRID_DEG
    rows = np.arange(draws)[:, None]
    for j in range(n_columns):
        fell = rng.uniform(size=shape) < p_fall[:, None]
        k = np.minimum((rng.uniform(size=shape)[..., None] > cdf[:, None, :]).sum(-1),
                       npsi - 1)
        fresh = np.where(fell, k, -1)
        if j and math.isfinite(weight):
            earlier = state[rows, np.arange(replicates)[None, :],
                            rng.integers(j, size=shape)]
            moved = np.mod(earlier + np.round(rng.normal(0.0, noise, shape)).astype(int),
                           npsi)
            copied = np.where(earlier < 0, -1, moved)
            fresh = np.where(rng.uniform(size=shape) < weight / (weight + j), fresh, copied)
        state[..., j] = fresh
    values = np.where(state < 0, log_q[:, None, None],
                      np.take_along_axis(log_f[:, None, :].repeat(replicates, 1),
                                         np.maximum(state, 0), axis=2))
    return values.sum(axis=-1)
