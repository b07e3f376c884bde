"""Could the source lie beyond the inversion's reach?  A test of the sources beyond it.

The candidates end where the forward table's last ring ends for some site
(:mod:`pipeline.inversion.candidates`), so the posterior cannot say that the source lies
farther: a larger magnitude beyond the last ring shakes the sites much as a smaller one
inside it does, and the posterior then sits inside.  This test puts a second set of
epicentres beside the candidates: a shell of lattice cells (``SHELL_STEP`` times the
candidates' step) whose farthest site lies beyond the last ring, out to ``SHELL_FACTOR``
times it, and within the radius of some site.  There the likelihood reads the last
ring's fall directions and carries its P on by the table's own decay with distance
(:meth:`pipeline.inversion.likelihood.ForwardModel.decay`).

With the prior uniform over area within each set (and the candidates' prior over
magnitude, mechanism and strike), the Bayes factor of "beyond" against "within" is the
shell's mean likelihood over the candidates' (``beyond_bayes_factor``).  Above
``BEYOND_BAYES_FACTOR`` the summary warns that the source may lie beyond the reach, and
the direction is then given as unknown, as for the other reach warnings; the member
study measures its hits (sources beyond the reach) and its false alarms (sources well
within it).  One site cannot tell: the shell about it and the disk inside explain its
falls alike (in the member study's calibration draws the test warned as often for sources
within the reach as beyond it at every threshold), so a one-site inversion says so in a
note (``reach_note``) instead of a warning: its direction stays, since the candidates are
a disk about the site and do not turn it.  The shell's likelihood is an extrapolation
of the table: it enters the test only, never the posterior, its regions or its
magnitudes.
"""
import dataclasses
import math

import numpy as np
from scipy.special import logsumexp

SHELL_FACTOR = 2.0          # the shell reaches this many times the table's last ring
SHELL_STEP = 2              # the shell's lattice step in candidate steps (a test, not a map)
BEYOND_BAYES_FACTOR = 3.0   # the falls favour the shell this much over the candidates:
#   chosen once on draws the reported member study never uses (its trials with seed 1, the
#   predictive likelihood, 48 members): 3 sites x 1-30 fallen columns gave false alarms
#   for 0.024 of the sources well within the reach and hits for 0.94 of those beyond it
#   (refusals included); 1.4 and 2 gave more false alarms (0.13, 0.06) for few more hits
ONE_SITE_NOTE = ("one site: its falls cannot tell a source beyond the reach from a nearer "
                 "one of smaller magnitude (nor can the test of the sources beyond it), so "
                 "the distance interval and the epicentre region hold only if the source "
                 "lies within {reach:g} km; the direction does not depend on it (the "
                 "candidates are a disk about the site)")


def shell_lattice(observations, grid, last_ring_km):
    """(east, north) km of the shell's cells: farthest site beyond ``last_ring_km`` and
    within SHELL_FACTOR times it, some site within ``grid``'s radius."""
    step = min(grid.step_km * SHELL_STEP, grid.radius_km / 2)
    coarse = dataclasses.replace(grid, step_km=step)
    east, north = coarse.lattice(observations, SHELL_FACTOR * last_ring_km)
    farthest = np.max([np.hypot(s.east_km - east, s.north_km - north)
                       for s in observations.sites], axis=0)
    keep = farthest > last_ring_km + 1e-9
    return east[keep], north[keep]


def beyond_test(model, observations, grid, log_prior_slice, log_likelihood):
    """{"beyond_bayes_factor", "beyond_cells", "beyond_shell_km"} of ``observations``
    against the candidates' ``log_likelihood`` (n_sources, n_strikes, n_cells) and prior
    over the sources ``log_prior_slice``; the factor None when the table has one ring (no
    decay to carry P beyond it) or the shell holds no cell."""
    last_ring = float(model.table.distances_km[-1])
    out = {"beyond_bayes_factor": None, "beyond_cells": 0,
           "beyond_shell_km": [last_ring, SHELL_FACTOR * last_ring]}
    if len(model.table.distances_km) < 2:
        return out
    east, north = shell_lattice(observations, grid, last_ring)
    if east.size == 0:
        return out
    shell = model.log_likelihood(observations, east, north, grid.strikes_deg)
    log_z = [float(logsumexp(log_prior_slice[:, None, None] + ll)) - math.log(ll[0].size)
             for ll in (shell, log_likelihood)]
    factor = math.exp(min(max(log_z[0] - log_z[1], -700.0), 700.0))
    return {**out, "beyond_bayes_factor": factor, "beyond_cells": int(east.size)}
