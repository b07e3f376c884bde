"""The inversion demo: synthetic truth tests and the paper's own scenario.

Synthetic truth tests.  The forward table's members are split in two halves: even member
indices give the likelihood, odd ones the "observed" columns, so observations never come
from the runs that explain them.  A trial picks a mechanism, a true strike (on the
candidate strike grid) and S sites at table nodes of that source (distinct nodes, each
where the observation half has at least one fall); at each site columns are drawn (column
type and member at random, with replacement) until K have fallen, the standing ones drawn
on the way being observed too; each fall is the member's downfall azimuth turned by the
strike plus a measurement error (normal, ``uncertainty_deg``).  The inversion then reports
whether the truth lies inside the 95 % regions (epicentre cell, back-azimuth arc) and how
wide the back-azimuth arcs are, for K = 1, 3, 10, 30 fallen columns per site and S = 1, 3
sites, each configuration ``trials`` times.

Paper scenario.  The two sources of :data:`pipeline.motion.synthetics.SOURCES` (Mw 6.5
strike-slip at 8 km, thrust at 10 km) at the paper's sites (rings 5, 10, 20 km, every
30 deg): the nominal twin run at each site (a drum column and a monolith with the paper's
values) is what the site shows; each site is inverted alone (what one site with the
paper's twin columns could have told) and all 36 together, with the whole ensemble as the
likelihood.  The nominal run is never an ensemble member.
"""
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import paper
from pipeline.files import InputError, write_csv, write_json
from pipeline.inversion.likelihood import (DEFAULT_FLOOR, DEFAULT_KERNEL_DEG, LIKELIHOODS,
                                           ForwardModel)
from pipeline.inversion import truth_check
from pipeline.inversion.candidates import OutOfReach, within_reach
from pipeline.inversion.credible import in_arc
from pipeline.inversion.paper_scenario import paper_outputs
from pipeline.inversion.posterior import invert
from pipeline.inversion.sites import OBS_UNCERTAINTY_DEG, draw_site_columns, map_azimuth_error, \
    site_frame, site_position
from pipeline.stats.circular import azimuth_deg
from pipeline.inversion import write_outputs
from pipeline.inversion.options import DEMO_TRIALS as DEFAULT_TRIALS   # declared with --trials

FALLEN_PER_SITE = (1, 3, 10, 30)
SITE_COUNTS = (1, 3)
DEMO_SEED = 2009
# the paper's question: a 95 % back-azimuth arc no wider than BOUND_DEG (deg), and its
# words and result keys
BOUND_DEG = 2 * paper.BACK_AZIMUTH_BOUND_DEG
BOUND_TEXT = f"+-{paper.BACK_AZIMUTH_BOUND_DEG:g} deg"
BOUNDED_FRACTION_KEY = f"bounded_{paper.BACK_AZIMUTH_BOUND_DEG:g}_fraction"
BOUND_ANSWER_KEY = f"bound_{paper.BACK_AZIMUTH_BOUND_DEG:g}_deg"
SITES_WITHIN_KEY = f"sites_within_{paper.BACK_AZIMUTH_BOUND_DEG:g}_deg"


def split_members(table):
    """(likelihood half: even member indices, observation half: odd ones)."""
    even = table.members % 2 == 0
    return table.select_members(even), table.select_members(~even)


def truth_trial(model, pool, mechanism, n_sites, fallen, candidates, rng):
    """One synthetic truth test; a dict of what it found."""
    table = model.table
    s = table.slice_index(mechanism)
    strike = float(rng.choice(candidates.strikes_deg))
    nodes = [(i, j) for i in range(len(table.distances_km))
             for j in range(len(table.azimuths_deg)) if pool.toppled[s, i, j].any()]
    if not nodes:
        return None, None           # no column of the observation half ever fell
    picks = rng.choice(len(nodes), size=min(n_sites, len(nodes)), replace=False)
    sites = []
    for k, pick in enumerate(picks):
        i, j = nodes[pick]
        alpha = (table.azimuths_deg[j] + strike) % 360.0
        e, n = site_position(table.distances_km[i], alpha)
        cols = draw_site_columns(pool, s, i, j, strike, fallen, rng)
        sites.append((f"S{k + 1}", e, n, cols))
    observations, truth = site_frame(sites)
    true_baz = azimuth_deg(truth[0], truth[1])
    d = math.hypot(*truth)
    row = {"mechanism": mechanism, "sites": len(sites), "fallen_per_site": fallen,
           "strike_deg": strike, "true_back_azimuth_deg": true_baz, "true_distance_km": d,
           "site_distances_km": " ".join(f"{math.hypot(e, n):g}" for _, e, n, _ in sites),
           "standing_observed": sum(not c.fallen for _, _, _, cols in sites for c in cols),
           "fallen_observed": sum(c.fallen for _, _, _, cols in sites for c in cols),
           "no_candidate": False}
    try:
        post = invert(model, observations, candidates)
    except OutOfReach:
        return {**row, **out_of_reach_row(truth, observations, table, candidates)}, None
    summary = post.summary()
    map_error = map_azimuth_error(summary, true_baz)
    check = truth_check(post, {"epicentre_km": truth, "back_azimuth_deg": true_baz,
                               "distance_km": d, "mechanism": mechanism,
                               "mw": table.slices[s]["mw"]}, summary)
    return {**row,
            "epicentre_in_95": check["epicentre_in_95"],
            "epicentre_in_68": check["epicentre_in_68"],
            "back_azimuth_in_95": check["back_azimuth_in_95"],
            "back_azimuth_in_68": in_arc(true_baz, summary["back_azimuth_ci68_deg"]),
            "back_azimuth_in_hpd95": any(in_arc(true_baz, a)
                                         for a in summary["back_azimuth_hpd95_arcs_deg"]),
            "width95_deg": summary["back_azimuth_ci95_width_deg"],
            "width68_deg": summary["back_azimuth_ci68_width_deg"],
            "hpd95_total_deg": sum((a[1] - a[0]) % 360.0 or 360.0
                                   for a in summary["back_azimuth_hpd95_arcs_deg"]),
            "map_back_azimuth_error_deg": map_error,
            "distance_in_95": check["distance_in_95"],
            **{k: check[k] for k in REACH_KEYS},
            "credible_area_95_km2": summary["credible_area_95_km2"],
            "p_true_mechanism": summary["mechanism_posterior"].get(mechanism, 0.0)}, \
        (post, observations, truth)


REACH_KEYS = ("within_reach", "reach_warning", "reach_edge_fraction",
              "epicentre_in_95_or_warned", "distance_in_95_or_warned")


def out_of_reach_row(truth, observations, table, candidates):
    """What a truth test records when no candidate lies within the forward table's reach
    of every site (the inversion refuses: it cannot tell): no region holds the truth,
    the back azimuth is unbounded, and the answer counts as "beyond the reach"."""
    sites = [(site.east_km, site.north_km) for site in observations.sites]
    inside = within_reach(*truth, sites, float(table.distances_km[-1]), candidates.radius_km)
    return {"epicentre_in_95": False, "epicentre_in_68": False, "back_azimuth_in_95": False,
            "back_azimuth_in_68": False, "back_azimuth_in_hpd95": False,
            "width95_deg": 360.0, "width68_deg": 360.0, "hpd95_total_deg": 360.0,
            "map_back_azimuth_error_deg": np.nan, "distance_in_95": False,
            "within_reach": inside, "reach_warning": True, "reach_edge_fraction": np.nan,
            "epicentre_in_95_or_warned": True, "distance_in_95_or_warned": True,
            "credible_area_95_km2": np.nan, "p_true_mechanism": np.nan, "no_candidate": True}


def truth_tests(model, pool, candidates, trials=DEFAULT_TRIALS, seed=DEMO_SEED,
                fallen_per_site=FALLEN_PER_SITE, site_counts=SITE_COUNTS, examples=None):
    """Every trial of every configuration: DataFrame (one row per trial)."""
    rows = []
    mechanisms = list(dict.fromkeys(s["mechanism"] for s in model.table.slices))
    for m, mechanism in enumerate(mechanisms):
        for n_sites in site_counts:
            for fallen in fallen_per_site:
                for trial in range(trials):
                    rng = np.random.default_rng([seed, m, n_sites, fallen, trial])
                    row, detail = truth_trial(model, pool, mechanism, n_sites, fallen,
                                              candidates, rng)
                    if row is None:
                        break
                    rows.append({"likelihood": model.likelihood, **row, "trial": trial})
                    if examples is not None and trial == 0 and detail is not None:
                        examples[(mechanism, n_sites, fallen)] = detail
    return pd.DataFrame(rows)


def narrowing(trials):
    """Per (mechanism, sites, fallen per site): coverage and back-azimuth widths."""
    rows = []
    for (kind, mech, sites, fallen), g in trials.groupby(["likelihood", "mechanism", "sites",
                                                          "fallen_per_site"]):
        w = g["width95_deg"]
        rows.append({"likelihood": kind, "mechanism": mech, "sites": sites,
                     "fallen_per_site": fallen,
                     "fallen_total": fallen * sites, "trials": len(g),
                     "width_median_deg": float(w.median()),
                     "width_q25_deg": float(w.quantile(0.25)),
                     "width_q75_deg": float(w.quantile(0.75)),
                     "width68_median_deg": float(g["width68_deg"].median()),
                     "coverage_back_azimuth_95": float(g["back_azimuth_in_95"].mean()),
                     "coverage_epicentre_95": float(g["epicentre_in_95"].mean()),
                     "coverage_distance_95": float(g["distance_in_95"].mean()),
                     "coverage_epicentre_95_or_warned":
                         float(g["epicentre_in_95_or_warned"].mean()),
                     "coverage_distance_95_or_warned":
                         float(g["distance_in_95_or_warned"].mean()),
                     "reach_warning_fraction": float(g["reach_warning"].mean()),
                     "coverage_back_azimuth_68": float(g["back_azimuth_in_68"].mean()),
                     BOUNDED_FRACTION_KEY: float((w <= BOUND_DEG).mean()),
                     "median_abs_map_error_deg": float(
                         g["map_back_azimuth_error_deg"].abs().median()),
                     "credible_area_95_km2_median": float(g["credible_area_95_km2"].median()),
                     "p_true_mechanism_median": float(g["p_true_mechanism"].median())})
    return pd.DataFrame(rows)


def bound_answer(narrow):
    """The paper's question: per (mechanism, sites) the fewest fallen columns per site whose
    median 95 % back-azimuth arc is at most BOUND_DEG wide (None: not reached)."""
    out = []
    for (kind, mech, sites), g in narrow.groupby(["likelihood", "mechanism", "sites"]):
        g = g.sort_values("fallen_per_site")
        ok = g[g["width_median_deg"] <= BOUND_DEG]
        first = None if ok.empty else ok.iloc[0]
        out.append({"likelihood": kind, "mechanism": mech, "sites": int(sites),
                    "fallen_per_site": None if first is None else int(first["fallen_per_site"]),
                    "fallen_total": None if first is None else int(first["fallen_total"]),
                    "coverage_back_azimuth_95": None if first is None else
                    float(first["coverage_back_azimuth_95"]),
                    "width_median_deg": None if first is None else
                    float(first["width_median_deg"]),
                    "largest_tested_width_median_deg": float(g["width_median_deg"].iloc[-1])})
    return out


# ---------------------------------------------------------------- paper scenario
# ---------------------------------------------------------------- the whole demo
def run_demo(table, out_dir, candidates, paper_tables=None, trials=DEFAULT_TRIALS,
             kernel_deg=DEFAULT_KERNEL_DEG, floor=DEFAULT_FLOOR, forward_info=None,
             likelihoods=LIKELIHOODS):
    """Truth tests (with each likelihood of ``likelihoods``) and the paper scenario on
    ``table``; writes into ``out_dir``: truth_tests.csv, narrowing.csv,
    paper_scenario_sites.csv, demo_summary.json and figures.  ``paper_tables``: {source
    name: table holding the nominal runs at the paper's sites}."""
    out_dir = Path(out_dir)
    started = time.monotonic()
    likelihood_half, pool = split_members(table)
    if len(likelihood_half.members) == 0 or len(pool.members) == 0:
        raise InputError("the demo needs at least two ensemble members (--members 2)")
    trials_frame, narrow, figures = _truth_test_outputs(
        likelihood_half, pool, candidates, trials, kernel_deg, floor, likelihoods, out_dir,
        forward_info)
    coverage = _coverage(trials_frame)
    # one column per type and site: both likelihoods give the same paper-scenario numbers
    paper_sites, paper_joint, paper_figures = paper_outputs(
        ForwardModel(table, kernel_deg, floor), paper_tables, candidates, out_dir,
        forward_info)
    figures += paper_figures
    summary = {
        "forward_table": forward_info or {},
        "likelihood": {"kinds": list(likelihoods), "kernel_deg": kernel_deg, "floor": floor,
                       "members_likelihood": likelihood_half.members.tolist(),
                       "members_observations": pool.members.tolist()},
        "candidate_grid": candidates.as_dict(), "prior": candidates.prior_statement(),
        "observation_uncertainty_deg": OBS_UNCERTAINTY_DEG,
        "trials_per_configuration": trials, "coverage": coverage,
        # a configuration whose trials all gave no direction has no MAP error: null
        "narrowing": narrow.astype(object).where(narrow.notna(), None).to_dict(
            orient="records"),
        BOUND_ANSWER_KEY: bound_answer(narrow),
        "paper_scenario": {"joint": paper_joint,
                           "per_source": _paper_per_source(paper_sites)},
        "figures": [str(Path(f).relative_to(out_dir)) for f in figures],
        "demo_s": round(time.monotonic() - started, 1)}
    write_json(out_dir / "demo_summary.json", summary)
    return summary


def _truth_test_outputs(likelihood_half, pool, candidates, trials, kernel_deg, floor,
                        likelihoods, out_dir, forward_info):
    """The truth tests with each likelihood: truth_tests.csv, narrowing.csv and its figure,
    the example inversions; returns (trials, narrowing, figure paths)."""
    from pipeline.figures.inversion import plot_interval_widths  # lazy: matplotlib, not imported by a run or after Ctrl-C
    examples, frames = {}, []
    for kind in likelihoods:
        model = ForwardModel(likelihood_half, kernel_deg, floor, kind)
        found = {}
        frames.append(truth_tests(model, pool, candidates, trials, examples=found))
        examples.update({(kind,) + key: value for key, value in found.items()})
    trials_frame = pd.concat(frames, ignore_index=True)
    if trials_frame.empty:
        raise InputError("no column of the table's observation half ever fell: nothing to "
                         "test (a grid with stronger shaking: closer rings, higher Mw)")
    write_csv(out_dir / "truth_tests.csv", trials_frame)
    narrow = narrowing(trials_frame)
    write_csv(out_dir / "narrowing.csv", narrow)
    figures = [plot_interval_widths(narrow, out_dir / "narrowing.png")]
    for (kind, mech, n_sites, fallen), (post, observations, truth) in examples.items():
        if n_sites == max(SITE_COUNTS) and fallen == 10:
            sub = out_dir / f"example_{kind}_{mech}_{n_sites}sites_{fallen}fallen"
            write_outputs(post, observations, sub, forward_info,
                          truth={"epicentre_km": list(truth), "mechanism": mech,
                                 "back_azimuth_deg": math.degrees(math.atan2(*truth)) % 360,
                                 "distance_km": math.hypot(*truth)},
                          title=f"Synthetic truth test ({kind} likelihood): {mech}, "
                                f"{n_sites} sites, {fallen} fallen columns each")
            figures += [sub / "posterior_map.png", sub / "marginals.png"]
    return trials_frame, narrow, figures


def _coverage(trials_frame):
    """Per likelihood: the trials and the fraction whose truth lies in each region."""
    return {kind: {
        "trials": int(len(g)),
        "back_azimuth_95": float(g["back_azimuth_in_95"].mean()),
        "back_azimuth_hpd95": float(g["back_azimuth_in_hpd95"].mean()),
        "epicentre_95": float(g["epicentre_in_95"].mean()),
        "back_azimuth_68": float(g["back_azimuth_in_68"].mean()),
        "epicentre_68": float(g["epicentre_in_68"].mean()),
        "distance_95": float(g["distance_in_95"].mean()),
        "epicentre_95_or_warned": float(g["epicentre_in_95_or_warned"].mean()),
        "distance_95_or_warned": float(g["distance_in_95_or_warned"].mean()),
        "within_reach": float(g["within_reach"].mean()),
        "reach_warning": float(g["reach_warning"].mean())}
        for kind, g in trials_frame.groupby("likelihood", sort=False)}


def _paper_per_source(sites):
    out = []
    if sites.empty:
        return out
    for source, g in sites.groupby("source"):
        fell = g[g["fallen"] > 0]
        out.append({"source": source, "sites": int(len(g)),
                    "sites_with_a_fall": int(len(fell)),
                    "sites_both_fell": int((g["fallen"] == 2).sum()),
                    "width95_median_deg_sites_with_falls":
                        None if fell.empty else float(fell["width95_deg"].median()),
                    "width95_median_deg_sites_without":
                        None if len(fell) == len(g) else
                        float(g[g["fallen"] == 0]["width95_deg"].median()),
                    "back_azimuth_in_95_sites_with_falls":
                        None if fell.empty else float(fell["back_azimuth_in_95"].mean()),
                    SITES_WITHIN_KEY: int((g["width95_deg"] <= BOUND_DEG).sum()),
                    "sites_reach_warning": int(g["reach_warning"].sum()),
                    "median_abs_map_error_deg_sites_with_falls":
                        None if fell.empty else float(fell["map_error_deg"].abs().median())})
    return out
