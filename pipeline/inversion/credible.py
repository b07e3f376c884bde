"""Credible regions of the inversion's marginals: highest-posterior-density (HPD) sets.

For the back azimuth, the HPD bins of its circular marginal (possibly several arcs) and the
shortest single arc holding the level ([lo, hi] deg, clockwise from lo to hi; the two agree
for a unimodal marginal); for the magnitude, the fewest consecutive candidate magnitudes
holding the level (an interval in Mw) and the smallest set of magnitudes.
"""
import numpy as np


def magnitude_interval(posterior, level=0.95):
    """[lo, hi] Mw: the fewest consecutive candidate magnitudes holding ``level`` of
    ``posterior`` ({mw: p}), each standing for the span halfway to its neighbours (at the
    table's first and last magnitude, the span ends there)."""
    mws = np.array(sorted(posterior), float)
    mass = np.array([posterior[m] for m in sorted(posterior)], float)
    mass = mass / mass.sum()
    best = (0, len(mws) - 1)
    for length in range(1, len(mws) + 1):
        window = np.convolve(mass, np.ones(length), mode="valid")
        if window.max() >= level - 1e-12:
            start = int(np.argmax(window))
            best = (start, start + length - 1)
            break
    lo = mws[best[0]] if best[0] == 0 else (mws[best[0]] + mws[best[0] - 1]) / 2
    hi = mws[best[1]] if best[1] == len(mws) - 1 else (mws[best[1]] + mws[best[1] + 1]) / 2
    return [round(float(lo), 4), round(float(hi), 4)]


def circular_credible(mass, bin_deg, level):
    """(shortest arc [lo, hi] holding ``level``, HPD arcs [[lo, hi], ...]) of a circular
    histogram (bins from 0, width ``bin_deg``).  Whole circle: [0, 360]."""
    mass = np.asarray(mass, float) / np.sum(mass)
    nb = mass.size
    # HPD set: the most probable bins until the level is reached
    order = np.argsort(-mass, kind="stable")
    count = int(np.searchsorted(np.cumsum(mass[order]), level - 1e-12) + 1)
    chosen = np.zeros(nb, bool)
    chosen[order[:count]] = True
    arcs = _runs(chosen, bin_deg)
    # shortest single arc: the fewest consecutive bins holding the level
    doubled = np.concatenate([[0.0], np.cumsum(np.r_[mass, mass])])
    arc = [0.0, 360.0]
    for length in range(1, nb + 1):
        window = doubled[length:length + nb] - doubled[:nb]
        if window.max() >= level - 1e-12:
            if length < nb:
                start = int(np.argmax(window))
                arc = [float(start * bin_deg % 360.0), float((start + length) * bin_deg % 360.0)]
            break
    return arc, arcs


def _runs(chosen, bin_deg):
    nb = chosen.size
    if chosen.all():
        return [[0.0, 360.0]]
    start = int(np.argmin(chosen))          # a bin outside the set: runs do not wrap there
    arcs, k = [], 0
    while k < nb:
        i = (start + k) % nb
        if chosen[i]:
            j = k
            while j < nb and chosen[(start + j) % nb]:
                j += 1
            arcs.append([float(i * bin_deg % 360.0), float(((start + j) % nb) * bin_deg
                                                           % 360.0 or 360.0)])
            k = j
        else:
            k += 1
    return arcs


def arc_width(arc):
    lo, hi = arc
    if lo == 0.0 and hi == 360.0:
        return 360.0
    return float((hi - lo) % 360.0)


def in_arc(angle_deg, arc):
    lo, hi = arc
    if arc_width(arc) >= 360.0:
        return True
    return bool((angle_deg - lo) % 360.0 <= (hi - lo) % 360.0)
