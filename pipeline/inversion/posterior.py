"""Candidate sources, prior and posterior: marginals, credible regions and the outputs.

Candidates are the product of the forward table's slices (mechanism, depth, magnitude;
optionally a subset), strikes every ``strike_step_deg`` from 0, and epicentres on a
square lattice of spacing ``step_km`` with the first site at the centre of a cell (the
lattice maps onto itself when turned by 90 deg about the first site), every lattice point
within ``radius_km`` of some site and within the forward table's last ring of every site:
the table speaks for every candidate, none takes the last ring's values for a farther
site (the inversion's reach).  The posterior's mass in the outermost cells of the
candidates (``reach_edge_fraction``, f) against the prior's there (p) says when the answer
is "farther than the candidates reach": the Bayes factor of "the source lies in the
outermost cells" against "inside them", (f / (1 - f)) / (p / (1 - p))
(``reach_edge_bayes_factor``), above ``EDGE_BAYES_FACTOR`` puts a ``reach_warning`` in
the summary, and then the back azimuth, which the reach's edge would decide, is given
as unknown (the whole circle; the arcs within the reach are kept apart).  The magnitudes
are the likelihood's sources (:func:`pipeline.inversion.likelihood.magnitude_sources`:
every 0.1 between the table's slices).  The prior is uniform over epicentre area, strike,
depth and the candidates' magnitudes; mechanisms uniform unless ``mechanism_prior`` gives
weights; magnitudes uniform unless ``gr_b`` gives a Gutenberg-Richter b value (prior
proportional to 10^(-b M)).

Frames: km East/North of the first site; the back azimuth is the azimuth from the first
site to the epicentre.  Credible regions are highest-posterior-density (HPD) sets: for the
epicentre, the fewest cells holding the level; for the back azimuth, the HPD bins of its
marginal (``*_hpd*_arcs_deg``, possibly several arcs) and the shortest single arc holding
the level (``back_azimuth_ci*_deg`` = [lo, hi], clockwise from lo to hi; the two agree for
a unimodal marginal).  Marginals of back azimuth and distance spread each cell's mass over
a 5 x 5 sub-grid, so that cells near the site cover their true span of azimuths.
"""
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from pipeline.files import InputError
from pipeline.stats.circular import azimuth_deg
from pipeline.inversion.fit import fit_check
from pipeline.inversion.likelihood import ForwardModel
from pipeline.inversion.observations import Observations, Site

BAZ_BIN_DEG = 2.0
SUBGRID = 5
LEVELS = (0.68, 0.95)
EDGE_BAYES_FACTOR = 3.0   # the outermost cells' posterior odds over their prior odds above
#                           which the source may lie beyond the reach (the member study
#                           measures the false alarms and the hits of this threshold)


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
        if not (0 < self.radius_km <= 100):
            raise InputError(f"--radius must lie in (0, 100] km, got {self.radius_km:g}")
        if not (0 < self.step_km <= self.radius_km / 2):
            raise InputError(f"--step must lie in (0, radius/2] km, got {self.step_km:g}")
        if (self.radius_km / self.step_km) > 400:
            raise InputError(f"--radius {self.radius_km:g} / --step {self.step_km:g}: more "
                             "than 400 cells across; use a coarser step")
        n = 360.0 / self.strike_step_deg if self.strike_step_deg > 0 else 0
        if not (0 < self.strike_step_deg <= 360 and abs(n - round(n)) < 1e-9):
            raise InputError(f"--strike-step must divide 360, got {self.strike_step_deg:g}")
        if self.gr_b is not None and not (0 <= self.gr_b <= 3):
            raise InputError(f"--gr-b must lie in [0, 3], got {self.gr_b:g}")

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


@dataclass
class Posterior:
    """Posterior over candidates (slices x strikes x epicentres)."""
    slices: list
    strikes_deg: np.ndarray
    east_km: np.ndarray
    north_km: np.ndarray
    step_km: float
    log_prior: np.ndarray
    log_likelihood: np.ndarray
    info: dict = field(default_factory=dict)
    edge: np.ndarray = None           # bool per epicentre: the outermost candidate cells

    def __post_init__(self):
        log_post = self.log_prior + self.log_likelihood
        self.log_evidence = float(logsumexp(log_post))
        self.probability = np.exp(log_post - self.log_evidence)
        self.epicentre = self.probability.sum(axis=(0, 1))
        self._sub = None

    # -------------------------------------------------------------- marginals
    def _subsamples(self):
        if self._sub is None:
            offsets = ((np.arange(SUBGRID) + 0.5) / SUBGRID - 0.5) * self.step_km
            oe, on = np.meshgrid(offsets, offsets)
            e = (self.east_km[:, None] + oe.ravel()[None, :]).ravel()
            n = (self.north_km[:, None] + on.ravel()[None, :]).ravel()
            mass = np.repeat(self.epicentre / SUBGRID ** 2, SUBGRID ** 2)
            self._sub = (e, n, mass)
        return self._sub

    def back_azimuth_marginal(self):
        """(bin centres deg, mass) of the azimuth from the first site to the epicentre."""
        e, n, mass = self._subsamples()
        baz = azimuth_deg(e, n)
        edges = np.arange(0.0, 360.0 + BAZ_BIN_DEG / 2, BAZ_BIN_DEG)
        hist, _ = np.histogram(baz, bins=edges, weights=mass)
        return edges[:-1] + BAZ_BIN_DEG / 2, hist / hist.sum()

    def distance_marginal(self, bin_km=None):
        e, n, mass = self._subsamples()
        d = np.hypot(e, n)
        bin_km = bin_km or self.step_km
        edges = np.arange(0.0, d.max() + bin_km, bin_km)
        hist, _ = np.histogram(d, bins=edges, weights=mass)
        return edges[:-1] + bin_km / 2, hist / hist.sum()

    def distance_interval(self, level=0.95):
        """[lo, hi] km from the first site: the shortest interval of distances holding
        ``level`` of the posterior (on the sub-grid; it reaches the candidates' last
        distance when the posterior piles there, where equal tails would stop short)."""
        e, n, mass = self._subsamples()
        d = np.hypot(e, n)
        order = np.argsort(d, kind="stable")
        d = d[order]
        before = np.concatenate([[0.0], np.cumsum(mass[order]) / mass.sum()])
        ends = np.searchsorted(before, before[:-1] + level - 1e-12)   # one past the last
        starts = np.flatnonzero(ends < len(before))
        widths = d[ends[starts] - 1] - d[starts]
        k = starts[int(np.argmin(widths))]
        return [float(d[k]), float(d[ends[k] - 1])]

    def marginal(self, key):
        """{value: probability} over slices' ``key`` (mechanism, depth_km, mw)."""
        per_slice = self.probability.sum(axis=(1, 2))
        out = {}
        for s, p in zip(self.slices, per_slice):
            out[s[key]] = out.get(s[key], 0.0) + float(p)
        return out

    def strike_marginal(self):
        return self.strikes_deg, self.probability.sum(axis=(0, 2))

    # -------------------------------------------------------------- regions
    def epicentre_region(self, level):
        """Bool mask of the cells of the HPD region and the density threshold."""
        order = np.argsort(-self.epicentre, kind="stable")
        cum = np.cumsum(self.epicentre[order])
        count = int(np.searchsorted(cum, level - 1e-12) + 1)
        mask = np.zeros(self.epicentre.shape, bool)
        mask[order[:count]] = True
        return mask, float(self.epicentre[order[count - 1]])

    def cell_of(self, east_km, north_km):
        return int(np.argmin(np.hypot(self.east_km - east_km, self.north_km - north_km)))

    def contains(self, east_km, north_km, level=0.95):
        """Whether the cell holding (east, north) lies in the HPD region (False outside the
        candidate lattice)."""
        k = self.cell_of(east_km, north_km)
        if max(abs(self.east_km[k] - east_km), abs(self.north_km[k] - north_km)) > \
                self.step_km / 2 + 1e-9:
            return False
        return bool(self.epicentre_region(level)[0][k])

    def within_reach(self, east_km, north_km):
        """Whether (east, north) km lies where candidates may lie (:func:`within_reach`;
        True when the posterior does not know its sites)."""
        if self.info.get("sites_km") is None:
            return True
        return within_reach(east_km, north_km, self.info["sites_km"],
                            self.info["table_last_ring_km"], self.info["grid"]["radius_km"])

    # -------------------------------------------------------------- outputs
    def summary(self):
        centres, mass = self.back_azimuth_marginal()
        best = int(np.argmax(self.epicentre))
        joint = np.unravel_index(int(np.argmax(self.probability)), self.probability.shape)
        s = self.slices[joint[0]]
        out = {
            "map_epicentre_km": [float(self.east_km[best]), float(self.north_km[best])],
            "back_azimuth_map_deg": float(centres[int(np.argmax(mass))]),
        }
        for level in LEVELS:
            tag = int(round(level * 100))
            arc, arcs = circular_credible(mass, BAZ_BIN_DEG, level)
            out[f"back_azimuth_ci{tag}_deg"] = arc
            out[f"back_azimuth_ci{tag}_width_deg"] = arc_width(arc)
            out[f"back_azimuth_hpd{tag}_arcs_deg"] = arcs
        out["distance_ci95_km"] = self.distance_interval(0.95)
        out["mechanism_posterior"] = self.marginal("mechanism")
        out["depth_posterior"] = {f"{k:g}": v for k, v in self.marginal("depth_km").items()}
        out["magnitude_posterior"] = {f"{k:g}": v for k, v in self.marginal("mw").items()}
        out["magnitude_ci95"] = magnitude_interval(self.marginal("mw"), 0.95)
        mws = [s["mw"] for s in self.slices]
        out["magnitude_range"] = [float(min(mws)), float(max(mws))]
        strikes, pstrike = self.strike_marginal()
        out["strike_posterior"] = {f"{k:g}": float(v) for k, v in zip(strikes, pstrike)}
        for level in LEVELS:
            mask, _ = self.epicentre_region(level)
            out[f"credible_area_{int(round(level * 100))}_km2"] = float(
                mask.sum() * self.step_km ** 2)
        out["map_candidate"] = {"mechanism": s["mechanism"], "dip_deg": s["dip_deg"],
                                "rake_deg": s["rake_deg"], "depth_km": s["depth_km"],
                                "mw": s["mw"], "strike_deg": float(self.strikes_deg[joint[1]]),
                                "epicentre_km": [float(self.east_km[joint[2]]),
                                                 float(self.north_km[joint[2]])]}
        out.update(self.reach_summary())
        out["direction_reliable"] = out["reach_warning"] is None
        if not out["direction_reliable"]:      # the reach's edge would decide the direction
            keys = [k for k in out if k.startswith("back_azimuth_")]
            out["back_azimuth_within_reach"] = {k: out[k] for k in keys}
            for level in LEVELS:
                tag = int(round(level * 100))
                out[f"back_azimuth_ci{tag}_deg"] = [0.0, 360.0]
                out[f"back_azimuth_ci{tag}_width_deg"] = 360.0
                out[f"back_azimuth_hpd{tag}_arcs_deg"] = [[0.0, 360.0]]
            out["back_azimuth_map_deg"] = None
        out["log_evidence"] = self.log_evidence
        out["candidates"] = int(self.probability.size)
        return out

    def reach_summary(self):
        """The inversion's reach (km from a site where the candidates end, and what ends
        them), the posterior's and the prior's mass in the outermost cells, their Bayes
        factor, the fit check's p-value (:mod:`pipeline.inversion.fit`) and a warning line
        (None) when the factor passes EDGE_BAYES_FACTOR or the fit check warns."""
        reach = self.info.get("reach_km")
        if self.edge is None or reach is None:
            return {"reach_km": reach, "reach_limit": None, "reach_edge_fraction": None,
                    "reach_edge_prior_fraction": None, "reach_edge_bayes_factor": None,
                    "reach_edge_warning": False, "fit_p_value": None, "fit_warning": None,
                    "reach_warning": None}
        prior = np.exp(self.log_prior - logsumexp(self.log_prior)).sum(axis=(0, 1))
        fraction = float(self.epicentre[self.edge].sum())
        prior_fraction = float(prior[self.edge].sum())
        factor = edge_bayes_factor(fraction, prior_fraction)
        warning, fit = None, self.info.get("fit") or {}
        if factor > EDGE_BAYES_FACTOR:
            warning = (f"{fraction:.0%} of the posterior lies in the outermost candidate "
                       f"cells, {reach:g} km from a site ({self.info.get('reach_limit')}), "
                       f"against {prior_fraction:.0%} of the prior (odds {factor:.3g} times "
                       "the prior's): the source may lie farther than this inversion can "
                       "tell, and its direction from the first site is not known either")
        if fit.get("fit_warning"):
            warning = fit["fit_warning"] if warning is None else \
                f"{warning}; and {fit['fit_warning']}"
        return {"reach_km": float(reach), "reach_limit": self.info.get("reach_limit"),
                "reach_edge_fraction": fraction,
                "reach_edge_prior_fraction": prior_fraction,
                "reach_edge_bayes_factor": factor,
                "reach_edge_warning": bool(factor > EDGE_BAYES_FACTOR),
                "fit_p_value": fit.get("fit_p_value"),
                "fit_warning": fit.get("fit_warning"), "reach_warning": warning}

    def frame(self):
        """One row per candidate: posterior.csv."""
        ns, nphi, ne = self.probability.shape
        s_idx, f_idx, e_idx = np.meshgrid(np.arange(ns), np.arange(nphi), np.arange(ne),
                                          indexing="ij")
        s_idx, f_idx, e_idx = s_idx.ravel(), f_idx.ravel(), e_idx.ravel()
        east, north = self.east_km[e_idx], self.north_km[e_idx]
        return pd.DataFrame({
            "mechanism": [self.slices[k]["mechanism"] for k in s_idx],
            "dip_deg": [self.slices[k]["dip_deg"] for k in s_idx],
            "rake_deg": [self.slices[k]["rake_deg"] for k in s_idx],
            "depth_km": [self.slices[k]["depth_km"] for k in s_idx],
            "mw": [self.slices[k]["mw"] for k in s_idx],
            "strike_deg": self.strikes_deg[f_idx],
            "east_km": np.round(east, 6), "north_km": np.round(north, 6),
            "distance_km": np.round(np.hypot(east, north), 6),
            "back_azimuth_deg": np.round(azimuth_deg(east, north), 4),
            "log_prior": self.log_prior.ravel() if self.log_prior.size == s_idx.size else
            np.broadcast_to(self.log_prior, self.probability.shape).ravel(),
            "log_likelihood": self.log_likelihood.ravel(),
            "posterior": self.probability.ravel()})


def edge_bayes_factor(fraction, prior_fraction):
    """(f / (1 - f)) / (p / (1 - p)): how much more the posterior than the prior favours
    the outermost cells; finite (f and p held within 1e-12 of 0 and 1, a JSON number), and
    1 when every candidate cell is an outermost one (the data cannot favour them)."""
    tiny = 1e-12
    p = min(max(float(prior_fraction), tiny), 1.0 - tiny)
    if float(prior_fraction) >= 1.0 - tiny:
        return 1.0
    f = min(max(float(fraction), 0.0), 1.0 - tiny)
    return float((f / (1.0 - f)) / (p / (1.0 - p)))


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


def magnitude_set(posterior, level=0.95):
    """The smallest set of magnitudes (strings as in the summary) holding ``level`` of the
    magnitude posterior ({"6.5": p, ...})."""
    chosen, total = [], 0.0
    for mw, p in sorted(posterior.items(), key=lambda kv: -kv[1]):
        chosen.append(mw)
        total += p
        if total >= level - 1e-12:
            break
    return chosen


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


def invert(model, observations, grid):
    """Posterior of ``observations`` over the candidates of ``grid`` (a CandidateGrid) with
    the forward model ``model`` (a likelihood.ForwardModel)."""
    keep = grid.slice_mask(model.table)
    if not keep.all():
        model = ForwardModel(model.table.select_slices(keep), model.kernel_deg, model.floor,
                             model.likelihood, model.mw_step, model.site_columns)
    for column in observations.column_types():
        model.column_index(column)
    last_ring = float(model.table.distances_km[-1])
    requested, _ = grid.lattice(observations)
    east, north = reached_lattice(observations, last_ring, grid)
    strikes = grid.strikes_deg
    loglike = model.log_likelihood(observations, east, north, strikes)
    log_prior_slice = grid.log_prior_slices(model.sources)
    log_prior = (log_prior_slice[:, None, None] - math.log(len(strikes)) - math.log(east.size)
                 + np.zeros(loglike.shape))
    farthest = max(np.hypot(s.east_km - east, s.north_km - north).max()
                   for s in observations.sites)
    info = {"grid": grid.as_dict(), "prior": grid.prior_statement(),
            "kernel_deg": model.kernel_deg, "floor": model.floor,
            "likelihood": model.likelihood, "table_last_ring_km": last_ring,
            "reach_km": min(last_ring, grid.radius_km),
            "reach_limit": "the forward table's last ring" if last_ring <= grid.radius_km
            else "--radius",
            # the share of the epicentres within --radius of a site that lie beyond the
            # table's last ring from some site: left out, the table cannot speak for them
            "beyond_table_fraction": 1.0 - east.size / requested.size,
            "farthest_candidate_km": float(farthest),
            "sites_km": [[s.east_km, s.north_km] for s in observations.sites],
            "table_slices": model.table.slices}
    post = Posterior(model.sources, strikes, east, north, grid.step_km, log_prior,
                     loglike, info=info, edge=grid.edge_cells(east, north))
    post.info["fit"] = fit_check(model, observations, post)
    return post


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
