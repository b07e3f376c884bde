"""The posterior over the candidates (:mod:`pipeline.inversion.candidates`): marginals,
credible regions (:mod:`pipeline.inversion.credible`) and the outputs.

The posterior carries the sources beyond the reach too: a shell of epicentres whose
likelihood extrapolates the table past its last ring (:mod:`pipeline.inversion.beyond`,
``beyond``), with probability ``p_beyond``.  ``probability`` and ``epicentre`` are the
candidates' posterior given the source lies within the reach; the marginals, the regions
and the summary are of the whole (candidates and shell).  Where the shell's cells lie in
the 95 % epicentre region, the distance interval is open above (``None``) and the
magnitude interval reaches the table's largest magnitude, or more
(``magnitude_ci95_open_above``: the shell's falls are those of sources farther out, the
larger the farther).

The posterior's mass in the outermost cells of the candidates (``reach_edge_fraction``,
f) against the prior's there (p) says when the answer is "farther than the candidates
reach": the Bayes factor of "the source lies in the outermost cells" against "inside
them", (f / (1 - f)) / (p / (1 - p)) (``reach_edge_bayes_factor``), above
``EDGE_BAYES_FACTOR`` puts a ``reach_warning`` in the summary, and then the back azimuth,
which the reach's edge would decide, is given as unknown (the whole circle; the arcs
within the reach are kept apart).  The magnitudes are the likelihood's sources
(:func:`pipeline.inversion.likelihood.magnitude_sources`: every 0.1 between the table's
slices).

Frames: km East/North of the first site; the back azimuth is the azimuth from the first
site to the epicentre.  Credible regions are highest-posterior-density (HPD) sets: for the
epicentre, the fewest cells holding the level; for the back azimuth and the magnitude as
:mod:`pipeline.inversion.credible` gives them.  Marginals of back azimuth and distance
spread each cell's mass over a 5 x 5 sub-grid, so that cells near the site cover their
true span of azimuths.
"""
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from pipeline.inversion.beyond import ONE_SITE_NOTE, Beyond, beyond_shell
from pipeline.inversion.candidates import reached_lattice, within_reach
from pipeline.inversion.credible import arc_width, circular_credible, magnitude_interval
from pipeline.inversion.fit import fit_check
from pipeline.inversion.likelihood import ForwardModel
from pipeline.stats.circular import azimuth_deg

BAZ_BIN_DEG = 2.0
SUBGRID = 5
LEVELS = (0.68, 0.95)
EDGE_BAYES_FACTOR = 3.0   # the outermost cells' posterior odds over their prior odds above
#                           which the source may lie beyond the reach (the member study
#                           measures the false alarms and the hits of this threshold)


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
    beyond: Beyond = None             # the shell beyond the reach (None: P(beyond) 0)

    def __post_init__(self):
        log_post = self.log_prior + self.log_likelihood
        self.log_evidence = float(logsumexp(log_post))
        self.probability = np.exp(log_post - self.log_evidence)
        self.epicentre = self.probability.sum(axis=(0, 1))
        self.p_beyond = 0.0 if self.beyond is None else self.beyond.p_beyond
        self._sub = None

    # -------------------------------------------------------------- marginals
    def cells(self):
        """(east km, north km, area km^2, posterior mass, in the shell) of every cell: the
        candidates' and then the shell's (:mod:`pipeline.inversion.beyond`)."""
        p = self.p_beyond
        n = self.east_km.size
        parts = [(self.east_km, self.north_km, np.full(n, self.step_km ** 2),
                  self.epicentre * (1.0 - p), np.zeros(n, bool))]
        if self.beyond is not None and self.beyond.east_km.size:
            shell = self.beyond
            m = shell.east_km.size
            parts.append((shell.east_km, shell.north_km, np.full(m, shell.step_km ** 2),
                          shell.cell_mass * p, np.ones(m, bool)))
        return tuple(np.concatenate(column) for column in zip(*parts))

    def _subsamples(self):
        if self._sub is None:
            east, north, area, mass, _ = self.cells()
            unit = (np.arange(SUBGRID) + 0.5) / SUBGRID - 0.5
            oe, on = (o.ravel() for o in np.meshgrid(unit, unit))
            side = np.sqrt(area)[:, None]
            self._sub = ((east[:, None] + side * oe[None, :]).ravel(),
                         (north[:, None] + side * on[None, :]).ravel(),
                         np.repeat(mass / SUBGRID ** 2, SUBGRID ** 2))
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

    def distance_interval(self, level=0.95, open_above=False):
        """[lo, hi] km from the first site: the shortest interval of distances holding
        ``level`` of the posterior (on the sub-grid; it reaches the candidates' last
        distance when the posterior piles there, where equal tails would stop short);
        ``open_above``: [lo, None], lo the distance of the nearest point of the cells of
        the epicentre's HPD region at ``level`` (which holds the shell's cells)."""
        e, n, mass = self._subsamples()
        d = np.hypot(e, n)
        order = np.argsort(d, kind="stable")
        d = d[order]
        before = np.concatenate([[0.0], np.cumsum(mass[order]) / mass.sum()])
        if open_above:          # the nearest point of the epicentre region's cells
            east, north, area, _, _ = self.cells()
            near = np.hypot(east, north) - np.sqrt(area / 2.0)
            return [float(max(near[self.region(level)[0]].min(), 0.0)), None]
        ends = np.searchsorted(before, before[:-1] + level - 1e-12)   # one past the last
        starts = np.flatnonzero(ends < len(before))
        widths = d[ends[starts] - 1] - d[starts]
        k = starts[int(np.argmin(widths))]
        return [float(d[k]), float(d[ends[k] - 1])]

    def _mixed(self, axis):
        """The posterior over sources (axis (1, 2)) or strikes (axis (0, 2)), shell in."""
        out = self.probability.sum(axis=axis) * (1.0 - self.p_beyond)
        if self.beyond is not None and self.beyond.east_km.size:
            out = out + self.beyond.probability.sum(axis=axis) * self.p_beyond
        return out

    def marginal(self, key):
        """{value: probability} over slices' ``key`` (mechanism, depth_km, mw)."""
        out = {}
        for s, p in zip(self.slices, self._mixed((1, 2))):
            out[s[key]] = out.get(s[key], 0.0) + float(p)
        return out

    def strike_marginal(self):
        return self.strikes_deg, self._mixed((0, 2))

    # -------------------------------------------------------------- regions
    def region(self, level):
        """(bool over :meth:`cells`: the HPD region of the epicentre, the fewest cells of
        the highest density holding ``level``; its least density, per km^2)."""
        _, _, area, mass, _ = self.cells()
        density = mass / area
        order = np.argsort(-density, kind="stable")
        cum = np.cumsum(mass[order])
        count = min(int(np.searchsorted(cum, level * cum[-1] - 1e-12) + 1), order.size)
        mask = np.zeros(mass.shape, bool)
        mask[order[:count]] = True
        return mask, float(density[order[count - 1]])

    def epicentre_region(self, level):
        """Bool mask of the candidate cells of the HPD region and its threshold as a
        candidate cell's ``epicentre`` (the shell's cells: :meth:`region`)."""
        mask, density = self.region(level)
        scale = self.step_km ** 2 / max(1.0 - self.p_beyond, 1e-300)
        return mask[:self.east_km.size], density * scale

    def cell_of(self, east_km, north_km):
        return int(np.argmin(np.hypot(self.east_km - east_km, self.north_km - north_km)))

    def contains(self, east_km, north_km, level=0.95):
        """Whether a cell holding (east, north) lies in the HPD region.  A point within
        the reach whose lattice cell is not a candidate (its centre beyond the last ring
        of a site: a sliver between the outermost centres and the reach's boundary)
        belongs to the nearest candidate cell; a point beyond the reach to the shell's
        cell holding it (:meth:`pipeline.inversion.beyond.Beyond.cell_of`); a point
        beyond both, or off the lattice, is in no cell (False)."""
        mask, _ = self.region(level)
        k = self.cell_of(east_km, north_km)
        held = max(abs(self.east_km[k] - east_km), abs(self.north_km[k] - north_km)) <= \
            self.step_km / 2 + 1e-9 or (
                self.within_reach(east_km, north_km)
                and math.hypot(self.east_km[k] - east_km, self.north_km[k] - north_km)
                <= 2.0 * self.step_km + 1e-9)
        if held and mask[k]:
            return True
        j = None if self.beyond is None else self.beyond.cell_of(east_km, north_km)
        return j is not None and bool(mask[self.east_km.size + j])

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
        east, north, area, cell_mass, shell = self.cells()
        best = int(np.argmax(cell_mass / area))
        joint = np.unravel_index(int(np.argmax(self.probability)), self.probability.shape)
        s = self.slices[joint[0]]
        in_95, _ = self.region(0.95)
        open_above = bool((in_95 & shell).any())       # the shell in the 95 % region
        out = {
            "map_epicentre_km": [float(east[best]), float(north[best])],
            "map_beyond_reach": bool(shell[best]),
            "back_azimuth_map_deg": float(centres[int(np.argmax(mass))]),
        }
        for level in LEVELS:
            tag = int(round(level * 100))
            arc, arcs = circular_credible(mass, BAZ_BIN_DEG, level)
            out[f"back_azimuth_ci{tag}_deg"] = arc
            out[f"back_azimuth_ci{tag}_width_deg"] = arc_width(arc)
            out[f"back_azimuth_hpd{tag}_arcs_deg"] = arcs
        out["distance_ci95_km"] = self.distance_interval(0.95, open_above)
        out["distance_ci95_unbounded"] = open_above
        out["mechanism_posterior"] = self.marginal("mechanism")
        out["depth_posterior"] = {f"{k:g}": v for k, v in self.marginal("depth_km").items()}
        out["magnitude_posterior"] = {f"{k:g}": v for k, v in self.marginal("mw").items()}
        mws = [s["mw"] for s in self.slices]
        lo, hi = magnitude_interval(self.marginal("mw"), 0.95)
        out["magnitude_ci95"] = [lo, float(max(mws)) if open_above else hi]
        out["magnitude_ci95_open_above"] = open_above
        out["magnitude_range"] = [float(min(mws)), float(max(mws))]
        strikes, pstrike = self.strike_marginal()
        out["strike_posterior"] = {f"{k:g}": float(v) for k, v in zip(strikes, pstrike)}
        for level in LEVELS:
            mask, _ = self.region(level)
            out[f"credible_area_{int(round(level * 100))}_km2"] = float(area[mask].sum())
        out["beyond_in_95"] = open_above
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
        one_site = len(self.info.get("sites_km") or ()) == 1 and reach is not None
        tested = {**(self.beyond.summary() if self.beyond is not None else
                     {"beyond_bayes_factor": None, "beyond_shell_km": None,
                      "beyond_warning": False, "p_beyond": 0.0, "beyond_cells": 0,
                      "beyond_prior": None, "beyond_extrapolated": None}),
                  "reach_note": ONE_SITE_NOTE.format(reach=reach) if one_site else None}
        if self.edge is None or reach is None:
            return {"reach_km": reach, "reach_limit": None, "reach_edge_fraction": None,
                    "reach_edge_prior_fraction": None, "reach_edge_bayes_factor": None,
                    "reach_edge_warning": False, "fit_p_value": None, "fit_warning": None,
                    **tested, "reach_warning": None}
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
        if tested["beyond_warning"]:
            lo, hi = tested["beyond_shell_km"]
            said = (f"the falls are {tested['beyond_bayes_factor']:.3g} times as likely from "
                    f"a source beyond the reach (farthest site {lo:g}-{hi:g} km, the table's "
                    "decay with distance carried on) as from one within it: the source may "
                    "lie farther than this inversion can tell, and its direction from the "
                    "first site is not known either")
            warning = said if warning is None else f"{warning}; and {said}"
        if fit.get("fit_warning"):
            warning = fit["fit_warning"] if warning is None else \
                f"{warning}; and {fit['fit_warning']}"
        if warning is not None and self.beyond is not None and self.beyond.east_km.size:
            warning = (f"P(beyond the reach) {self.p_beyond:.2f} (the posterior's mass "
                       f"beyond the last ring): {warning}")
        return {"reach_km": float(reach), "reach_limit": self.info.get("reach_limit"),
                "reach_edge_fraction": fraction,
                "reach_edge_prior_fraction": prior_fraction,
                "reach_edge_bayes_factor": factor,
                "reach_edge_warning": bool(factor > EDGE_BAYES_FACTOR),
                "fit_p_value": fit.get("fit_p_value"),
                "fit_warning": fit.get("fit_warning"), **tested, "reach_warning": warning}

    def frame(self):
        """One row per candidate and per cell of the shell beyond the reach (``beyond_reach``,
        its likelihood extrapolated, its log prior and likelihood not written): the
        posterior of the whole (summing to 1 over both): posterior.csv."""
        log_prior = np.broadcast_to(self.log_prior, self.probability.shape)
        parts = [_rows(self, self.probability * (1.0 - self.p_beyond), self.east_km,
                       self.north_km, log_prior, self.log_likelihood, False)]
        if self.beyond is not None and self.beyond.east_km.size:
            shell = self.beyond
            nan = np.full(shell.probability.shape, np.nan)
            parts.append(_rows(self, shell.probability * self.p_beyond, shell.east_km,
                               shell.north_km, nan, nan, True))
        return pd.concat(parts, ignore_index=True)


def _rows(post, probability, east_km, north_km, log_prior, log_likelihood, beyond):
    ns, nphi, ne = probability.shape
    s_idx, f_idx, e_idx = (i.ravel() for i in np.meshgrid(
        np.arange(ns), np.arange(nphi), np.arange(ne), indexing="ij"))
    east, north = east_km[e_idx], north_km[e_idx]
    return pd.DataFrame({
        **{key: [post.slices[k][key] for k in s_idx]
           for key in ("mechanism", "dip_deg", "rake_deg", "depth_km", "mw")},
        "strike_deg": post.strikes_deg[f_idx],
        "east_km": np.round(east, 6), "north_km": np.round(north, 6),
        "distance_km": np.round(np.hypot(east, north), 6),
        "back_azimuth_deg": np.round(azimuth_deg(east, north), 4),
        "beyond_reach": np.full(s_idx.size, beyond),
        "log_prior": log_prior.ravel(), "log_likelihood": log_likelihood.ravel(),
        "posterior": probability.ravel()})


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
                     loglike, info=info, edge=grid.edge_cells(east, north),
                     beyond=beyond_shell(model, observations, grid, log_prior_slice, loglike))
    post.info["fit"] = fit_check(model, observations, post)
    return post


