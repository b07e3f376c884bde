"""Candidate sources of the inversion and its reach.

Candidates are the product of the forward table's slices (mechanism, depth, magnitude;
optionally a subset), strikes every ``strike_step_deg`` from 0, and epicentres on a
square lattice of spacing ``step_km`` (km East/North of the first site) with the first
site at the centre of a cell (the lattice maps onto itself when turned by 90 deg about the
first site), every lattice point within ``radius_km`` of some site and within the forward
table's last ring of every site: the table speaks for every candidate, none takes the last
ring's values for a farther site (the inversion's reach; :class:`OutOfReach` when no
candidate is left).  The prior is uniform over epicentre area, strike, depth and the
candidates' magnitudes; mechanisms uniform unless ``mechanism_prior`` gives weights;
magnitudes uniform unless ``gr_b`` gives a Gutenberg-Richter b value (prior proportional
to 10^(-b M)).
"""
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import logsumexp

from pipeline.files import InputError
from pipeline.inversion.observations import Observations, Site

MAX_RADIUS_KM = 100.0    # candidates within this of a site at most
MAX_GR_B = 3.0           # the Gutenberg-Richter prior's b value at most


class OutOfReach(InputError):
    """No candidate epicentre lies within the forward table's reach of every site."""


@dataclass(frozen=True)
class CandidateGrid:
    radius_km: float = 30.0
    step_km: float = 1.0
    strike_step_deg: float = 30.0
    mechanisms: tuple = None          # names; None: every mechanism of the table
    depths_km: tuple = None
    magnitudes: tuple = None
    mechanism_prior: dict = None      # name: weight
    gr_b: float = None

    def __post_init__(self):
        if not (0 < self.radius_km <= MAX_RADIUS_KM):
            raise InputError(f"--radius must lie in (0, {MAX_RADIUS_KM:g}] km, got "
                             f"{self.radius_km:g}")
        if not (0 < self.step_km <= self.radius_km / 2):
            raise InputError(f"--step must lie in (0, radius/2] km, got {self.step_km:g}")
        if (self.radius_km / self.step_km) > 400:
            raise InputError(f"--radius {self.radius_km:g} / --step {self.step_km:g}: more "
                             "than 400 cells across; use a coarser step")
        n = 360.0 / self.strike_step_deg if self.strike_step_deg > 0 else 0
        if not (0 < self.strike_step_deg <= 360 and abs(n - round(n)) < 1e-9):
            raise InputError(f"--strike-step must divide 360, got {self.strike_step_deg:g}")
        if self.gr_b is not None and not (0 <= self.gr_b <= MAX_GR_B):
            raise InputError(f"--gr-b must lie in [0, {MAX_GR_B:g}], got {self.gr_b:g}")

    @property
    def strikes_deg(self):
        return np.arange(0.0, 360.0 - 1e-9, float(self.strike_step_deg))

    def as_dict(self):
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}

    def lattice(self, observations, reach_km=math.inf):
        """Epicentres (east, north) km from the first site: cell centres within the radius
        of a site and within ``reach_km`` (the forward table's last ring) of every site."""
        east = np.array([s.east_km for s in observations.sites])
        north = np.array([s.north_km for s in observations.sites])
        half = math.ceil((self.radius_km + np.hypot(east, north).max()) / self.step_km)
        axis = (np.arange(-half, half) + 0.5) * self.step_km
        ge, gn = np.meshgrid(axis, axis)
        ge, gn = ge.ravel(), gn.ravel()
        near = np.zeros(ge.shape, bool)
        reached = np.ones(ge.shape, bool)
        for e, n in zip(east, north):
            distance = np.hypot(ge - e, gn - n)
            near |= distance <= self.radius_km + 1e-9
            reached &= distance <= reach_km + 1e-9
        keep = near & reached
        return ge[keep], gn[keep]

    def edge_cells(self, east_km, north_km):
        """Bool mask of the candidate cells with a lattice neighbour (of the four) that is
        not a candidate: the outermost cells, where the candidates end."""
        i = np.round(np.asarray(east_km) / self.step_km - 0.5).astype(int)
        j = np.round(np.asarray(north_km) / self.step_km - 0.5).astype(int)
        i, j = i - i.min() + 1, j - j.min() + 1
        inside = np.zeros((i.max() + 2, j.max() + 2), bool)
        inside[i, j] = True
        return ~(inside[i - 1, j] & inside[i + 1, j] & inside[i, j - 1] & inside[i, j + 1])

    def slice_mask(self, table):
        keep = []
        names = {s["mechanism"] for s in table.slices}
        for wanted, key in ((self.mechanisms, "mechanism"), (self.depths_km, "depth_km"),
                            (self.magnitudes, "mw")):
            if wanted is not None:
                missing = [w for w in wanted if w not in {s[key] for s in table.slices}]
                if missing:
                    raise InputError(f"the forward table has no {key} {missing} (it has "
                                     f"{sorted({s[key] for s in table.slices})})")
        for s in table.slices:
            keep.append((self.mechanisms is None or s["mechanism"] in self.mechanisms)
                        and (self.depths_km is None or s["depth_km"] in self.depths_km)
                        and (self.magnitudes is None or s["mw"] in self.magnitudes))
        if self.mechanism_prior:
            unknown = sorted(set(self.mechanism_prior) - names)
            if unknown:
                raise InputError(f"--mechanism-prior names {unknown}: not in the table "
                                 f"({sorted(names)})")
        return np.array(keep)

    def log_prior_slices(self, slices):
        """Log prior weight of each slice (normalised over slices)."""
        logp = np.zeros(len(slices))
        if self.mechanism_prior:
            for k, s in enumerate(slices):
                w = float(self.mechanism_prior.get(s["mechanism"], 0.0))
                logp[k] += math.log(w) if w > 0 else -np.inf
        if self.gr_b:
            logp += np.array([-self.gr_b * s["mw"] * math.log(10.0) for s in slices])
        # per (mechanism): uniform over its depths and magnitudes
        return logp - logsumexp(logp)

    def prior_statement(self):
        parts = ["uniform over epicentre area (lattice cells within the radius of a site)",
                 "uniform over strike", "uniform over depth"]
        parts.append("mechanisms " + (", ".join(f"{k} {v:g}" for k, v in
                                                self.mechanism_prior.items())
                                      if self.mechanism_prior else "equally likely"))
        parts.append(f"magnitudes Gutenberg-Richter b = {self.gr_b:g}" if self.gr_b
                     else "magnitudes equally likely")
        return "; ".join(parts)


def reached_lattice(observations, last_ring_km, grid):
    """The candidate epicentres of ``grid`` within ``last_ring_km`` of every site (east,
    north km from the first site); OutOfReach (one line) when there is none."""
    east, north = grid.lattice(observations, last_ring_km)
    if east.size == 0:
        raise OutOfReach(_out_of_reach(observations, last_ring_km, grid))
    return east, north


def check_reach(sites, last_ring_km, grid):
    """OutOfReach (one line) when no candidate of ``grid`` lies within ``last_ring_km`` of
    every site of ``sites`` ((name, east km, north km, ...) in any frame): before any run
    whose observations would be inverted there."""
    _, e0, n0 = sites[0][:3]
    reached_lattice(Observations(tuple(Site(s[0], s[1] - e0, s[2] - n0, ()) for s in sites)),
                    float(last_ring_km), grid)


def within_reach(east_km, north_km, sites_km, last_ring_km, radius_km):
    """Whether (east, north) km lies within the forward table's last ring of every site
    ((east, north) pairs) and within the radius of some site."""
    distances = [math.hypot(e - east_km, n - north_km) for e, n in sites_km]
    return bool(max(distances) <= last_ring_km + 1e-9 and min(distances) <= radius_km + 1e-9)


def _out_of_reach(observations, last_ring, grid):
    """The one-line reason why no candidate epicentre is within reach of every site."""
    pairs = [(p, q) for k, p in enumerate(observations.sites)
             for q in observations.sites[k + 1:]] or [(observations.sites[0],) * 2]
    p, q = max(pairs, key=lambda pq: math.hypot(pq[0].east_km - pq[1].east_km,
                                                  pq[0].north_km - pq[1].north_km))
    gap = math.hypot(p.east_km - q.east_km, p.north_km - q.north_km)
    if gap > 2 * last_ring:
        return (f"sites {p.name} and {q.name} lie {gap:.1f} km apart, but the forward table's "
                f"rings end at {last_ring:g} km: no epicentre is within its reach of every "
                f"site (invert fewer sites together, or use a table with rings to at least "
                f"{gap / 2:.1f} km)")
    return (f"no cell of the candidate grid (--step {grid.step_km:g} km, --radius "
            f"{grid.radius_km:g} km) lies within the forward table's last ring "
            f"({last_ring:g} km) of every site (sites {p.name} and {q.name} lie {gap:.1f} km "
            "apart): a finer --step, a larger --radius or a table with farther rings")
