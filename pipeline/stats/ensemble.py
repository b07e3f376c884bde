"""Statistics of one ensemble (members of one record and column): toppling probability
with its Wilson interval, the mean downfall azimuth (deg) with a bootstrap interval,
direction fractions, circular density (1/deg), an ensemble's summary, and two ensembles
compared (Fisher, Kuiper, Holm)."""
import math

import numpy as np
from scipy import stats

from pipeline.stats.circular import (angle_difference_deg, circular_summary, direction_class,
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


# ---------------------------------------------------------------- ensembles compared
def compare_ensembles(toppled_a, azimuths_a, toppled_b, azimuths_b, min_falls=5):
    """Do two ensembles of one record and column (e.g. two numerical settings) sample one
    distribution?  P(toppled) by Fisher's exact test on the 2 x 2 counts, the fall
    directions (deg; NaN for standing members) by Kuiper's two-sample test (astropy;
    invariant to where the circle is cut), with at least ``min_falls`` falls in each.
    Returns p-values (None where a test does not apply) and the difference of P(toppled)
    with its Monte Carlo error (binomial, the two ensembles independent)."""
    from astropy.stats import kuiper_two     # lazy: astropy is slow to import
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
