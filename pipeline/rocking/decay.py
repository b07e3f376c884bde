"""A recorded free-rocking decay read: its impacts (s) and swing amplitudes (rad) from a
tilt record, the record's noise, and the coefficient of restitution that reproduces the
decay (from the amplitudes, or from the rocking frequency in Hz and the amplitude
ratios)."""
import math

import numpy as np
from scipy.stats import norm, theilslopes

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.rocking.housner import block_constants

NOISE_SWINGS = 10.0           # a recorded swing counts above this many noise sd
MAX_AMPLITUDE_OF_ALPHA = 0.99  # free rocking from a frequency: amplitudes below this x alpha
REST_SWINGS = 3               # swings after the decay none of which it exceeds: at rest


def restitution_from_peaks(peaks, alpha):
    """Effective restitution from successive peak amplitudes (rad) of free rocking.

    peaks[k] = |theta| at the peak after k impacts.  Energy at impact
    k+1 is proportional to cos(alpha - theta_k) - cos(alpha) (exact rigid block),
    so the per-impact angular-velocity ratio is
    eta_k = sqrt(E_{k+1} / E_k).  Returns dict: eta_per_impact, r_per_impact
    (arrays), eta, r (overall geometric means over all impacts).
    """
    peaks = np.abs(np.asarray(peaks, float))
    if peaks.size < 2 or np.any(peaks >= alpha) or np.any(peaks <= 0):
        raise InputError("need >= 2 peak amplitudes, all between 0 and alpha")
    energy = np.cos(alpha - peaks) - math.cos(alpha)
    r_k = energy[1:] / energy[:-1]
    r = (energy[-1] / energy[0]) ** (1.0 / (peaks.size - 1))
    return dict(eta_per_impact=np.sqrt(r_k), r_per_impact=r_k, eta=math.sqrt(r), r=r)


def free_rocking_peaks(t, theta, rise=None):
    """Impacts and amplitudes of a recorded free-rocking decay: ``t`` (s, increasing) and
    ``theta`` (rad, signed tilt); with ``rise`` (m, the centre of mass above its rest
    height, one per sample) also the highest rise of each swing (``rise_peaks``).  An impact is a change of sign of theta (linear
    interpolation between samples); the amplitude of a swing is the largest |theta|
    between two impacts (the first swing: from the start to the first impact).  Returns
    dict: impact_times (s), peaks (rad, index k = amplitude after k impacts), swing_s
    (s, durations between successive impacts)."""
    t = np.asarray(t, float)
    theta = np.asarray(theta, float)
    if t.ndim != 1 or t.shape != theta.shape or t.size < 3:
        raise InputError("free rocking: time and tilt need the same length, at least 3 samples")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(theta))):
        raise InputError("free rocking: time and tilt must be finite numbers")
    if np.any(np.diff(t) <= 0):
        raise InputError("free rocking: time must increase from sample to sample")
    crossing = np.flatnonzero(np.sign(theta[1:]) * np.sign(theta[:-1]) < 0)
    impacts = t[crossing] - theta[crossing] * (t[crossing + 1] - t[crossing]) / \
        (theta[crossing + 1] - theta[crossing])
    bounds = np.concatenate([[0], crossing + 1, [t.size]])
    peaks = np.array([np.max(np.abs(theta[a:b])) for a, b in zip(bounds[:-1], bounds[1:])
                      if b > a])
    # the swing after the last impact counts only when it has turned back (a peak inside)
    turned = not (crossing.size and
                  np.argmax(np.abs(theta[bounds[-2]:])) == t.size - 1 - bounds[-2])
    if not turned:
        peaks = peaks[:-1]
    out = dict(impact_times=impacts, peaks=peaks, swing_s=np.diff(impacts))
    if rise is not None:
        rise = np.asarray(rise, float)
        out["rise_peaks"] = np.array([np.max(rise[a:b]) for a, b in
                                      zip(bounds[:-1], bounds[1:]) if b > a])[:peaks.size]
    return out


def fit_free_rocking(height, width, t=None, theta=None, frequency_hz=None,
                     amplitude_ratios=None, g=MODEL_GRAVITY):
    """The rocking coefficient of restitution (eta: angular velocity after / before an
    impact) that reproduces a free-rocking decay of a block of ``height`` and ``width``
    (m, width in the rocking plane), from either a tilt record (``t`` s, ``theta`` rad:
    successive amplitudes, :func:`restitution_from_peaks`, exact for the rigid block) or
    the rocking frequency (Hz, full cycle, at the amplitudes measured) and the ratios of
    successive amplitudes (the amplitude from the frequency by Housner's linearised
    period, eq 7: theta / alpha = 1 - 1 / cosh(p T / 4)).  Returns dict: restitution
    (mean over impacts), restitution_sd (scatter of single impacts; None for one),
    restitution_se (standard error of the mean; None for one), restitution_per_impact,
    impacts, housner_restitution (1 - 1.5 sin^2 alpha), alpha (rad), p (1/s), rest (a
    tilt record whose swings stop decaying, the block at rest and its noise recorded:
    {from_s, swings} of the swings left out, :func:`decaying_swings`; else None)."""
    c = block_constants(height, width, g)
    alpha = c["alpha"]
    rest = None
    if t is not None:
        peaks, times = swing_amplitudes(t, theta, with_times=True)
        kept = decaying_swings(peaks)
        if kept < peaks.size:
            rest = {"from_s": float(times[kept]), "swings": int(peaks.size - kept)}
            peaks = peaks[:kept]
        if np.any(peaks >= alpha):
            raise InputError(f"free rocking: an amplitude of {np.max(peaks):.4g} rad is at or "
                             f"beyond the block's overturning angle alpha {alpha:.4g} rad "
                             "(wrong block size, or tilt in degrees given as radians?)")
        eta = restitution_from_peaks(peaks, alpha)["eta_per_impact"]
        restitution, se = decay_fit(peaks, alpha)
    else:
        if frequency_hz is None or not amplitude_ratios:
            raise InputError("free rocking: give a tilt record, or the rocking frequency and "
                             "the ratios of successive amplitudes")
        slowest = slowest_rocking_hz(height, width, g)
        if not frequency_hz >= slowest:
            raise InputError(f"free rocking at {frequency_hz:g} Hz: a {height:.3g} x "
                             f"{width:.3g} m block rocks no slower than {slowest:.3g} Hz below "
                             f"{MAX_AMPLITUDE_OF_ALPHA:g} of its overturning angle (Housner's "
                             "linearised period): no block of that size rocks at that "
                             "frequency")
        amplitude = 1.0 - 1.0 / math.cosh(c["p"] / (4.0 * frequency_hz))
        ratios = np.asarray(amplitude_ratios, float)
        energy = lambda ratio: np.cos(alpha - ratio * alpha) - math.cos(alpha)  # noqa: E731
        eta = np.sqrt(energy(amplitude * ratios) / energy(amplitude))
        restitution, se = float(np.mean(eta)), None
    n = eta.size
    sd = float(np.std(eta, ddof=1)) if n > 1 else None
    if t is None and sd is not None:
        se = sd / math.sqrt(n)
    return dict(restitution=restitution, restitution_sd=sd, restitution_se=se,
                restitution_per_impact=eta, impacts=int(n),
                housner_restitution=c["restitution"], alpha=alpha, p=c["p"], rest=rest)


def decaying_swings(amplitudes):
    """How many of the leading swing ``amplitudes`` are the decay: those before the first
    swing no larger than one after it, when at least REST_SWINGS swings follow it (the
    block at rest, its record's noise swinging about zero, does not decay); all of them
    otherwise (the fit then judges whether they decay)."""
    a = np.asarray(amplitudes, float)
    later = np.maximum.accumulate(a[::-1])[::-1][1:]      # the largest after each swing
    first = np.flatnonzero(a[:-1] <= later)
    if first.size and first[0] >= 2 and a.size - first[0] >= REST_SWINGS:
        return int(first[0])
    return int(a.size)


def slowest_rocking_hz(height, width, g=MODEL_GRAVITY):
    """The lowest rocking frequency (Hz, full cycles) of a block of ``height`` and
    ``width`` (m) in free rocking below MAX_AMPLITUDE_OF_ALPHA of its overturning angle:
    Housner's linearised period (eq 7) T = 4 / p acosh(1 / (1 - theta / alpha)) grows
    without bound as theta nears alpha."""
    p = block_constants(height, width, g)["p"]
    return p / (4.0 * math.acosh(1.0 / (1.0 - MAX_AMPLITUDE_OF_ALPHA)))


def tilt_noise_sd(theta):
    """Standard deviation (rad) of white noise on a sampled tilt, robustly: the median
    absolute deviation of its second differences (6 sd^2 for the noise; a sampled swing's
    are far smaller, an impact's few) / 0.6745 / sqrt(6)."""
    d2 = np.diff(np.asarray(theta, float), 2)
    return float(np.median(np.abs(d2 - np.median(d2))) / (0.6745 * math.sqrt(6.0)))


def swing_amplitudes(t, theta, with_times=False):
    """Successive swing amplitudes (rad) of a recorded free-rocking decay (``t`` s,
    ``theta`` rad; swings between changes of sign, as :func:`free_rocking_peaks`) that
    stand above its noise (sd :func:`tilt_noise_sd`): a swing under NOISE_SWINGS sd is
    noise crossing zero (about an impact, or once the block is at rest) and is left out.
    On a noisy record a swing's amplitude is the top of a parabola fitted to its samples
    within NOISE_SWINGS / 2 sd of its highest (the highest sample alone reads high by
    about 2 sd).  InputError with fewer than two swings.  ``with_times``: also the time
    (s) each swing starts."""
    free_rocking_peaks(t, theta)                     # the checks of a record
    t, theta = np.asarray(t, float), np.asarray(theta, float)
    sd = tilt_noise_sd(theta)
    crossing = np.flatnonzero(np.sign(theta[1:]) * np.sign(theta[:-1]) < 0)
    bounds = np.concatenate([[0], crossing + 1, [t.size]])
    amplitudes, starts = [], []
    for a, b in zip(bounds[:-1], bounds[1:]):
        swing = np.abs(theta[a:b])
        top = int(np.argmax(swing))
        if swing[top] <= NOISE_SWINGS * sd or a + top == t.size - 1:
            continue                              # noise, or still rising at the end
        near = swing >= swing[top] - 0.5 * NOISE_SWINGS * sd
        amplitudes.append(_parabola_top(t[a:b][near], swing[near], swing[top]))
        starts.append(t[a])
    if len(amplitudes) < 2:
        raise InputError("free rocking: at least one impact with amplitudes before and after "
                         f"it is needed (above the record's noise: {NOISE_SWINGS * sd:.2g} rad)")
    return (np.array(amplitudes), np.array(starts)) if with_times else np.array(amplitudes)


def _parabola_top(t, y, highest):
    """The top of a least-squares parabola through (t, y) when it opens downward with its
    top inside t; else ``highest``."""
    if t.size < 5:
        return float(highest)
    tau = t - t.mean()
    c2, c1, c0 = np.polyfit(tau, y, 2)
    if not c2 < 0 or not tau[0] <= -c1 / (2 * c2) <= tau[-1]:
        return float(highest)
    return float(c0 - c1 ** 2 / (4 * c2))


def decay_fit(peaks, alpha, confidence=0.95):
    """(restitution, its standard error or None for one impact) from successive swing
    amplitudes ``peaks`` (rad) of a block of critical angle ``alpha`` (rad): a robust line
    (Theil-Sen) through the swings' ln energy, ln(cos(alpha - theta_k) - cos(alpha)),
    against the swing number k, whose slope is 2 ln(restitution) (:func:`restitution_from_peaks`
    gives each impact's).  InputError when the slope's ``confidence`` interval reaches 0:
    amplitudes that do not decay are no free-rocking decay."""
    energy = np.cos(alpha - np.asarray(peaks, float)) - math.cos(alpha)
    fit = theilslopes(np.log(energy), np.arange(energy.size, dtype=float), alpha=confidence)
    if not fit.high_slope < 0.0:
        raise InputError(f"free rocking: the {energy.size} swing amplitudes do not decay (their "
                         f"energy changes by a factor {math.exp(fit.slope):.4f} a swing, "
                         f"{confidence:.0%} interval {math.exp(fit.low_slope):.4f}-"
                         f"{math.exp(fit.high_slope):.4f}): not a free-rocking decay")
    restitution = math.exp(fit.slope / 2.0)
    if energy.size < 3:
        return restitution, None
    z = norm.ppf(0.5 + confidence / 2.0)
    return restitution, restitution * (fit.high_slope - fit.low_slope) / (4.0 * z)
