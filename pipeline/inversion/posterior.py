"""The posterior over the candidates (:mod:`pipeline.inversion.candidates`): marginals,
credible regions (:mod:`pipeline.inversion.credible`) and the outputs.

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

from pipeline.inversion.beyond import BEYOND_BAYES_FACTOR, ONE_SITE_NOTE, beyond_test
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
        """Whether the cell holding (east, north) lies in the HPD region.  A point within
        the reach whose lattice cell is not a candidate (its centre beyond the last ring
        of a site: a sliver between the outermost centres and the reach's boundary)
        belongs to the nearest candidate cell; a point beyond the reach or off the
        lattice is in no cell (False)."""
        k = self.cell_of(east_km, north_km)
        if max(abs(self.east_km[k] - east_km), abs(self.north_km[k] - north_km)) > \
                self.step_km / 2 + 1e-9 and not (
                    self.within_reach(east_km, north_km)
                    and math.hypot(self.east_km[k] - east_km, self.north_km[k] - north_km)
                    <= 2.0 * self.step_km + 1e-9):
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
        beyond = self.info.get("beyond") or {}
        beyond_factor = beyond.get("beyond_bayes_factor")
        beyond_warning = beyond_factor is not None and beyond_factor > BEYOND_BAYES_FACTOR
        one_site = len(self.info.get("sites_km") or ()) == 1 and reach is not None
        tested = {"beyond_bayes_factor": beyond_factor,
                  "beyond_shell_km": beyond.get("beyond_shell_km"),
                  "beyond_warning": bool(beyond_warning),
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
        if beyond_warning:
            lo, hi = beyond["beyond_shell_km"]
            said = (f"the falls are {beyond_factor:.3g} times as likely from a source beyond "
                    f"the reach (farthest site {lo:g}-{hi:g} km, the table's decay with "
                    "distance carried on) as from one within it: the source may lie farther "
                    "than this inversion can tell, and its direction from the first site is "
                    "not known either")
            warning = said if warning is None else f"{warning}; and {said}"
        if fit.get("fit_warning"):
            warning = fit["fit_warning"] if warning is None else \
                f"{warning}; and {fit['fit_warning']}"
        return {"reach_km": float(reach), "reach_limit": self.info.get("reach_limit"),
                "reach_edge_fraction": fraction,
                "reach_edge_prior_fraction": prior_fraction,
                "reach_edge_bayes_factor": factor,
                "reach_edge_warning": bool(factor > EDGE_BAYES_FACTOR),
                "fit_p_value": fit.get("fit_p_value"),
                "fit_warning": fit.get("fit_warning"), **tested, "reach_warning": warning}

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
    post.info["beyond"] = beyond_test(model, observations, grid, log_prior_slice, loglike)
    return post


