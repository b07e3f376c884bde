"""Circular statistics of downfall directions: one implementation for every stage.

Angles in degrees clockwise from North; astropy.stats does the work in radians.
Differences are wrapped to (-180, 180]; axial statistics double the angles
(a direction known up to 180 deg).  Direction classes relative to the back
azimuth: toward (|downfall - back azimuth| <= 45 deg: falls toward the
epicentre), away (>= 135 deg), transverse otherwise.  Von Mises kernels (the
inversion's direction densities): their density, and the concentration whose mean
resultant length is a wrapped normal's of a given width.
"""
import math

import numpy as np
import pandas as pd
from scipy import optimize, special
from astropy.stats import circcorrcoef, circmean, circvar, rayleightest

from pipeline.constants import COLUMN_TYPES
from pipeline.files import InputError

TOWARD_MAX_DEG = 45.0
AWAY_MIN_DEG = 135.0
# reference direction name -> runs column holding its azimuth (deg)
REFERENCE_AZIMUTHS = {
    "back_azimuth": "back_azimuth_deg",
    "max_acc": "az_max_acc_deg",
    "max_vel": "az_max_vel_deg",
    "max_disp": "az_max_disp_deg",
}


def wrap_deg(angle_deg, period=360.0):
    """Angle(s) wrapped into (-period/2, period/2]."""
    a = np.asarray(angle_deg, dtype=float)
    out = -np.mod(-a + period / 2, period) + period / 2
    return out if out.ndim else float(out)


def azimuth_deg(east, north):
    """Azimuth (deg clockwise from North, in [0, 360)) of the vector (east, north); arrays
    element-wise, a float for scalars."""
    out = np.mod(np.degrees(np.arctan2(east, north)), 360.0)
    return out if np.ndim(out) else float(out)


def angle_difference_deg(a, b):
    """Angle a - b (deg) wrapped into (-180, 180]; NaN stays NaN."""
    return wrap_deg(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))


def circular_summary(angles_deg, axial=False):
    """Summary of directions (deg; NaN entries are ignored).

    Returns dict(n, mean_deg, resultant_length, circular_std_deg, rayleigh_p).
    mean_deg is in [0, 360), or in [0, 180) when ``axial`` (angles doubled
    before averaging, mean and spread halved after; the direction is then
    known up to 180 deg).  circular_std_deg is sqrt(-2 ln R) (Mardia); NaN
    entries when no angle is given.
    """
    angles = np.asarray(angles_deg, dtype=float).ravel()
    angles = angles[np.isfinite(angles)]
    n = int(angles.size)
    if n == 0:
        return dict(n=0, mean_deg=np.nan, resultant_length=np.nan,
                    circular_std_deg=np.nan, rayleigh_p=np.nan)
    factor = 2.0 if axial else 1.0
    radians = np.deg2rad(angles * factor)
    length = float(1.0 - circvar(radians))
    length = min(max(length, 0.0), 1.0)  # rounding
    period = 360.0 / factor
    mean = np.rad2deg(float(circmean(radians))) / factor if length > 1e-12 else np.nan
    # Mardia's sqrt(-2 ln R) of the clipped R (astropy's circstd warns when rounding puts R
    # a hair above 1 for identical angles)
    std = np.rad2deg(math.sqrt(max(0.0, -2.0 * math.log(length)))) / factor if length > 0 else np.inf
    # astropy's small-sample series can dip below 0 for very concentrated data
    p_value = min(max(float(rayleightest(radians)), 0.0), 1.0)
    mean = float(np.mod(mean, period))
    mean = 0.0 if mean >= period else mean       # numpy's mod gives the period a hair below 0
    return dict(n=n, mean_deg=mean, resultant_length=length,
                circular_std_deg=float(std), rayleigh_p=p_value)


def circular_correlation(a_deg, b_deg):
    """Circular-circular correlation (astropy circcorrcoef) of paired angles (deg).

    Pairs with a NaN are dropped; NaN when fewer than 3 pairs remain or one
    set has (almost) no spread, e.g. one back azimuth for all runs.
    """
    a = np.asarray(a_deg, dtype=float).ravel()
    b = np.asarray(b_deg, dtype=float).ravel()
    keep = np.isfinite(a) & np.isfinite(b)
    if keep.sum() < 3:
        return np.nan
    a, b = np.deg2rad(a[keep]), np.deg2rad(b[keep])
    if min(float(circvar(a)), float(circvar(b))) < 1e-9:
        return np.nan
    return float(circcorrcoef(a, b))


def direction_statistics(runs):
    """Table comparing downfall azimuths with the reference directions.

    One row per campaign, column type, record (and ``record_id == "all"`` for
    all records of the campaign together) and reference direction
    (back_azimuth, max_acc, max_vel, max_disp).  Only toppled runs with a
    finite downfall azimuth and reference azimuth are used.  Columns:
    n_runs, n_toppled, n (pairs used), mean_downfall_deg, mean_reference_deg,
    mean_difference_deg (downfall - reference, (-180, 180]),
    resultant_length (of the differences), rayleigh_p, axial_mean_difference_deg
    ([-90, 90)), axial_resultant_length, axial_rayleigh_p, circcorr and
    axial_circcorr (NaN when n < 3).
    """
    needed = ["campaign", "record_id", "column", "toppled", "downfall_azimuth_deg",
              *REFERENCE_AZIMUTHS.values()]
    runs = checked_runs(runs, needed)
    rows = []
    for (campaign, column), group in runs.groupby(["campaign", "column"], sort=True):
        subsets = [(str(rec), sub) for rec, sub in group.groupby("record_id", sort=True)]
        if len(subsets) > 1:
            subsets.append(("all", group))
        for record_id, sub in subsets:
            for reference, ref_column in REFERENCE_AZIMUTHS.items():
                rows.append(dict(campaign=campaign, column=column, record_id=record_id,
                                 reference=reference,
                                 **_difference_statistics(sub, ref_column)))
    return pd.DataFrame(rows)


def _difference_statistics(sub, ref_column):
    toppled = sub[sub["toppled"]]
    downfall = toppled["downfall_azimuth_deg"].to_numpy(float)
    reference = toppled[ref_column].to_numpy(float)
    keep = np.isfinite(downfall) & np.isfinite(reference)
    downfall, reference = downfall[keep], reference[keep]
    difference = angle_difference_deg(downfall, reference)
    directional = circular_summary(difference)
    axial = circular_summary(difference, axial=True)
    return dict(
        n_runs=len(sub), n_toppled=len(toppled), n=directional["n"],
        mean_downfall_deg=circular_summary(downfall)["mean_deg"],
        mean_reference_deg=circular_summary(reference)["mean_deg"],
        mean_difference_deg=wrap_deg(directional["mean_deg"]),
        resultant_length=directional["resultant_length"],
        rayleigh_p=directional["rayleigh_p"],
        axial_mean_difference_deg=wrap_deg(axial["mean_deg"], 180.0),
        axial_resultant_length=axial["resultant_length"],
        axial_rayleigh_p=axial["rayleigh_p"],
        circcorr=circular_correlation(downfall, reference),
        axial_circcorr=circular_correlation(2.0 * downfall, 2.0 * reference),
    )


def checked_runs(runs, columns):
    """Return a copy of ``runs`` with ``toppled`` as bool, or raise InputError."""
    if not isinstance(runs, pd.DataFrame):
        raise InputError(f"runs table must be a pandas DataFrame, got {type(runs).__name__}")
    if runs.empty:
        raise InputError("runs table is empty")
    missing = [c for c in columns if c not in runs.columns]
    if missing:
        raise InputError(f"runs table lacks column(s): {', '.join(missing)}")
    runs = runs.copy()
    if "column" in columns:
        unknown = sorted(set(runs["column"].astype(str)) - set(COLUMN_TYPES))
        if unknown:
            raise InputError(f"runs table has unknown column type(s): {', '.join(unknown)}")
    if "toppled" in columns:
        runs["toppled"] = _as_bool(runs["toppled"], "toppled")
    return runs


def _as_bool(series, name):
    mapping = {True: True, False: False, "True": True, "False": False, "true": True,
               "false": False}
    values = series.map(lambda v: mapping.get(v.item() if isinstance(v, np.generic) else v))
    if values.isna().any():
        raise InputError(f"runs column '{name}' must hold True/False only")
    return values.astype(bool)


def direction_class(diff_deg):
    """'toward', 'away' or 'transverse' for downfall-minus-back-azimuth differences (deg);
    NaN gives 'not toppled'."""
    size = np.abs(np.asarray(diff_deg, dtype=float))
    return np.select([~np.isfinite(size), size <= TOWARD_MAX_DEG, size >= AWAY_MIN_DEG],
                     ["not toppled", "toward", "away"], "transverse")


def direction_differences(runs):
    """Per run: ``diff_deg`` = downfall azimuth minus back azimuth in (-180, 180] (NaN if
    not toppled or no back azimuth) and ``direction_class``."""
    frame = runs.copy()
    toppled = frame["toppled"].astype(bool) & frame["downfall_azimuth_deg"].notna()
    diff = angle_difference_deg(frame["downfall_azimuth_deg"].to_numpy(float),
                                frame["back_azimuth_deg"].to_numpy(float))
    frame["diff_deg"] = np.where(toppled, diff, np.nan)
    frame["direction_class"] = direction_class(frame["diff_deg"])
    return frame


def direction_table(runs):
    """Counts and circular statistics of downfall minus back azimuth.

    One row per source (when ``runs`` has a ``source`` column) and column type:
    n_runs, n_toppled, toward, away, transverse; mean difference (deg, (-180, 180])
    with its resultant length and Rayleigh p; axial mean difference in (-90, 90]
    (0 = along the back-azimuth line, +-90 = transverse), axial resultant length
    and Rayleigh p.
    """
    frame = direction_differences(runs)
    keys = [k for k in ("source", "column") if k in frame.columns]
    rows = []
    for key, group in frame.groupby(keys, sort=True):
        diffs = group["diff_deg"].dropna().to_numpy()
        row = dict(zip(keys, key if isinstance(key, tuple) else (key,)))
        row.update({"n_runs": len(group), "n_toppled": diffs.size})
        for cls in ("toward", "away", "transverse"):
            row[cls] = int((group["direction_class"] == cls).sum())
        if diffs.size:
            directional, axial = circular_summary(diffs), circular_summary(diffs, axial=True)
            row["mean_diff_deg"] = wrap_deg(directional["mean_deg"])
            row["resultant_length"] = directional["resultant_length"]
            row["rayleigh_p"] = directional["rayleigh_p"]
            row["axial_mean_diff_deg"] = wrap_deg(axial["mean_deg"], 180.0)
            row["axial_resultant_length"] = axial["resultant_length"]
            row["axial_rayleigh_p"] = axial["rayleigh_p"]
        rows.append(row)
    return pd.DataFrame(rows)


def mean_direction_error_deg(azimuths_deg):
    """Standard error (deg) of the circular mean of ``azimuths_deg`` (Fisher 1993, eq.
    4.21: sqrt((1 - R2) / (2 n R^2)), R2 the mean resultant of the doubled deviations);
    None for fewer than 2 or a mean that is not defined."""
    a = np.radians(np.asarray(azimuths_deg, float))
    a = a[np.isfinite(a)]
    if a.size < 2:
        return None
    c, s = np.cos(a).mean(), np.sin(a).mean()
    r = math.hypot(c, s)
    if r < 1e-9:
        return None
    r2 = float(np.cos(2 * (a - math.atan2(s, c))).mean())
    return float(math.degrees(math.sqrt(max(0.0, 1 - r2) / (2 * a.size * r * r))))


# ---------------------------------------------------------------- von Mises kernels
def mean_resultant_length(kappa):
    """A(kappa) = I1(kappa) / I0(kappa) of a von Mises distribution."""
    return special.i1e(kappa) / special.i0e(kappa)


def concentration(sigma_deg):
    """Von Mises concentration whose mean resultant length is the wrapped normal's,
    exp(-sigma^2 / 2) (sigma in deg); inf for sigma 0."""
    sigma = math.radians(float(sigma_deg))
    if sigma <= 0:
        return math.inf
    target = math.exp(-sigma * sigma / 2.0)
    if target < 1e-8:
        return 0.0
    return float(optimize.brentq(lambda k: mean_resultant_length(k) - target, 1e-10, 1e8,
                                 xtol=1e-12, rtol=1e-12))


def von_mises_pdf(x_rad, kappa):
    """Von Mises density (per radian) at angles ``x_rad`` about 0, stable for large kappa."""
    x = np.asarray(x_rad, float)
    if kappa == 0:
        return np.full(x.shape, 1.0 / (2 * math.pi))
    return np.exp(kappa * (np.cos(x) - 1.0)) / (2 * math.pi * special.i0e(kappa))
