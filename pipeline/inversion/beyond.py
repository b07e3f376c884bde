"""The sources beyond the inversion's reach, in the posterior: a shell of epicentres.

The candidates end where the forward table's last ring ends for some site
(:mod:`pipeline.inversion.candidates`): a larger magnitude beyond the last ring shakes the
sites much as a smaller one inside it does, and a posterior of the candidates alone then
sits inside.  So the posterior carries a second set of epicentres beside the candidates:
a shell of lattice cells (``SHELL_STEP`` times the candidates' step) whose farthest site
lies beyond the last ring, out to ``SHELL_FACTOR`` times it, and within the radius of some
site.  There the likelihood reads the last ring's fall directions and carries its P on
by the table's own decay with distance
(:meth:`pipeline.inversion.likelihood.ForwardModel.decay`): an extrapolation of the
table, flagged as such in the summary.

The prior: uniform over area within each set (and the candidates' prior over magnitude,
mechanism and strike in both), and "beyond the reach" given ``PRIOR_BEYOND``: P(beyond) =
r B / (1 + r B), r = PRIOR_BEYOND / (1 - PRIOR_BEYOND), with B the Bayes factor of the
shell against the candidates (their mean likelihoods, ``beyond_bayes_factor``).
The shell stands for "somewhere beyond", whose extent the table cannot bound
(``SHELL_FACTOR`` is a choice), so odds in proportion to area would make P(beyond)
follow that choice; and the shell's mean likelihood dilutes a good fit just beyond the
reach over cells far out, so the prior cannot be the complement of the region's level
(0.05: in the member study the epicentre region then held half the sources just beyond
the reach).  It was chosen on draws the reported member study never uses (its trials
with seed 1, the predictive likelihood, 48 members, three sites, the 20 km table), as
the smallest of 0.05, 0.1, 0.2, 0.3 and 0.5 whose 95 % regions held 0.90 or more of the
sources beyond the reach, just beyond it included, in distance, epicentre and magnitude.
Above ``BEYOND_BAYES_FACTOR`` the summary warns that the source may lie beyond the reach
(and gives no direction, as for the other reach warnings); below it the regions still
hold the shell where it carries mass.  One site cannot tell: the shell about it and the
disk inside explain its falls alike, so a one-site inversion says so in a note
(``reach_note``) instead of a warning; its direction stays (the candidates are a disk
about the site and do not turn it).
"""
import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import expit, logsumexp

SHELL_FACTOR = 2.0          # the shell reaches this many times the table's last ring
SHELL_STEP = 2              # the shell's lattice step in candidate steps
PRIOR_BEYOND = 0.3          # prior probability that the source lies in the shell:
#   chosen on the calibration draws (seed 1, 3 sites, 100 trials a fallen count): the
#   epicentre region held 0.50, 0.74, 0.88, 0.94 and 0.97 of the sources just beyond the
#   reach at 0.05, 0.1, 0.2, 0.3 and 0.5, the distance and Mw 0.97 or more from 0.1 up;
#   the sources well within kept their coverage (epicentre 0.95 at 0.05, 0.94 at 0.3)
#   with a mean P(beyond) of 0.065 (median 0.021) at 0.3
BEYOND_BAYES_FACTOR = 1.4   # the falls favour the shell this much over the candidates:
#   chosen on the same calibration draws, as the smallest factor whose false alarms (the
#   three-site sources well within the reach) stay at 0.03 or fewer (0.024 when first
#   chosen on the 10 km table): 1, 1.2, 1.4, 2 and 3 warned for 0.051, 0.051, 0.030, 0.015 and 0.005 of
#   them and for 0.86, 0.83, 0.76, 0.67 and 0.64 of those beyond it (refusals included)
EXTRAPOLATED = ("the shell's likelihood extrapolates the forward table past its last ring "
                "(the last ring's fall directions, its P carried on by the decay between "
                "the last two rings)")
ONE_SITE_NOTE = ("one site: its falls cannot tell a source beyond the reach from a nearer "
                 "one of smaller magnitude, so P(beyond the reach) says little more than "
                 "its prior, and the distance interval and the epicentre "
                 "region hold a source beyond {reach:g} km only through the table's "
                 "extrapolated decay; the direction does not depend on it (the candidates "
                 "are a disk about the site)")


@dataclass(frozen=True, eq=False)
class Beyond:
    """The shell beyond the reach in the posterior: its cells (km East/North of the first
    site, lattice step ``step_km``), their posterior given the source lies in the shell
    (``probability``: sources x strikes x cells, summing to 1), and ln of the Bayes
    factor of the shell against the candidates (None: no shell, P(beyond) 0); ValueError
    when these disagree (a defect, not an input)."""
    shell_km: tuple                    # (last ring, SHELL_FACTOR x last ring): farthest site
    sites_km: tuple                    # ((east, north) km of each site)
    radius_km: float                   # the candidates' --radius
    step_km: float
    east_km: np.ndarray
    north_km: np.ndarray
    probability: np.ndarray
    log_bayes_factor: float = None

    def __post_init__(self):
        lo, hi = self.shell_km
        if not (0 < lo < hi and self.step_km > 0 and self.radius_km > 0):
            raise ValueError(f"beyond the reach: shell {self.shell_km} km, step "
                             f"{self.step_km:g} km, radius {self.radius_km:g} km")
        cells = self.east_km.size
        if self.north_km.shape != (cells,) or self.probability.shape[-1:] != (cells,):
            raise ValueError("beyond the reach: cells and posterior disagree in shape")
        if cells and not math.isclose(float(self.probability.sum()), 1.0, abs_tol=1e-9):
            raise ValueError("beyond the reach: the shell's posterior does not sum to 1")
        if (self.log_bayes_factor is None) != (cells == 0):
            raise ValueError("beyond the reach: a Bayes factor needs shell cells")

    @property
    def bayes_factor(self):
        if self.log_bayes_factor is None:
            return None
        return math.exp(min(max(self.log_bayes_factor, -700.0), 700.0))

    @property
    def p_beyond(self):
        """The posterior probability that the source lies in the shell."""
        if self.log_bayes_factor is None:
            return 0.0
        odds = math.log(PRIOR_BEYOND / (1.0 - PRIOR_BEYOND))
        return float(expit(self.log_bayes_factor + odds))

    @property
    def warning(self):
        factor = self.bayes_factor
        return factor is not None and factor > BEYOND_BAYES_FACTOR

    @property
    def cell_mass(self):
        """Each cell's posterior given the source lies in the shell."""
        return self.probability.sum(axis=(0, 1))

    def in_shell(self, east_km, north_km):
        """Whether (east, north) km lies where the shell's cells may lie."""
        d = [math.hypot(e - east_km, n - north_km) for e, n in self.sites_km]
        lo, hi = self.shell_km
        return bool(lo + 1e-9 < max(d) <= hi + 1e-9 and min(d) <= self.radius_km + 1e-9)

    def cell_of(self, east_km, north_km):
        """The index of the shell cell holding (east, north) km, or None: its square, or,
        for a point within the shell's extent whose own square is no shell cell (a sliver
        at the shell's boundary), the nearest cell within two steps."""
        if self.east_km.size == 0:
            return None
        d = np.hypot(self.east_km - east_km, self.north_km - north_km)
        k = int(np.argmin(d))
        square = max(abs(self.east_km[k] - east_km), abs(self.north_km[k] - north_km))
        if square <= self.step_km / 2 + 1e-9 or (
                self.in_shell(east_km, north_km) and d[k] <= 2.0 * self.step_km + 1e-9):
            return k
        return None

    def summary(self):
        """The summary's keys of the shell (the one place they are written)."""
        return {"beyond_bayes_factor": self.bayes_factor,
                "beyond_shell_km": [float(v) for v in self.shell_km],
                "beyond_warning": bool(self.warning), "p_beyond": self.p_beyond,
                "beyond_cells": int(self.east_km.size),
                "beyond_prior": PRIOR_BEYOND if self.east_km.size else None,
                "beyond_extrapolated": EXTRAPOLATED if self.east_km.size else None}


def shell_lattice(observations, grid, last_ring_km):
    """(east, north) km of the shell's cells: farthest site beyond ``last_ring_km`` and
    within SHELL_FACTOR times it, some site within ``grid``'s radius; and their step."""
    step = min(grid.step_km * SHELL_STEP, grid.radius_km / 2)
    coarse = dataclasses.replace(grid, step_km=step)
    east, north = coarse.lattice(observations, SHELL_FACTOR * last_ring_km)
    farthest = np.max([np.hypot(s.east_km - east, s.north_km - north)
                       for s in observations.sites], axis=0)
    keep = farthest > last_ring_km + 1e-9
    return east[keep], north[keep], step


def beyond_shell(model, observations, grid, log_prior_slice, log_likelihood):
    """The :class:`Beyond` of ``observations`` against the candidates' ``log_likelihood``
    (n_sources, n_strikes, n_cells) and prior over the sources ``log_prior_slice``; no
    shell cell (P(beyond) 0) when the table has one ring (no decay to carry P beyond it)."""
    last_ring = float(model.table.distances_km[-1])
    sites = tuple((s.east_km, s.north_km) for s in observations.sites)
    east, north, step = shell_lattice(observations, grid, last_ring)
    if len(model.table.distances_km) < 2 or east.size == 0:
        east = north = np.zeros(0)
    common = {"shell_km": (last_ring, SHELL_FACTOR * last_ring), "sites_km": sites,
              "radius_km": float(grid.radius_km), "step_km": float(step),
              "east_km": east, "north_km": north}
    if east.size == 0:
        return Beyond(**common, probability=np.zeros(log_likelihood.shape[:2] + (0,)))
    shell = model.log_likelihood(observations, east, north, grid.strikes_deg)
    log_post = log_prior_slice[:, None, None] + shell
    log_z = [float(logsumexp(log_prior_slice[:, None, None] + ll)) - math.log(ll[0].size)
             for ll in (shell, log_likelihood)]
    probability = np.exp(log_post - logsumexp(log_post))
    return Beyond(**common, probability=probability / probability.sum(),
                  log_bayes_factor=log_z[0] - log_z[1])
