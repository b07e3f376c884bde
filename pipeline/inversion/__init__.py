"""Source inversion: from fallen (and standing) columns to a posterior over earthquake sources.

    observations.json ──observations──▶ sites, columns (km from the first site)
    forward grid ──forward (pyprop8 + campaign inversion-forward)──▶ ForwardTable
    ForwardTable ──likelihood──▶ log L per candidate ──posterior──▶ posterior.csv,
        inversion_summary.json, posterior_map.png, marginals.png

Modules: :mod:`~pipeline.inversion.observations` (the file's schema and checks),
:mod:`~pipeline.inversion.grid` (the grid and its pyprop8 motions),
:mod:`~pipeline.inversion.forward` (the symmetries, the campaign),
:mod:`~pipeline.inversion.table` (the forward table),
:mod:`~pipeline.inversion.likelihood`, :mod:`~pipeline.inversion.candidates` (candidates,
prior, reach), :mod:`~pipeline.inversion.posterior` (the posterior and its summary),
:mod:`~pipeline.inversion.credible` (credible regions), :mod:`~pipeline.inversion.demo`
(synthetic truth tests and the paper's scenario).  docs/inversion.md.
"""
import math
import time
from pathlib import Path

from pipeline.files import DirectoryLock, write_csv, write_json
from pipeline.inversion.likelihood import DEFAULT_FLOOR, DEFAULT_KERNEL_DEG, DEFAULT_LIKELIHOOD, \
    ForwardModel
from pipeline.inversion.credible import in_arc
from pipeline.inversion.posterior import invert

EXAMPLES_DIR = Path(__file__).resolve().parent / "examples"


def write_outputs(post, observations, out_dir, forward_info=None, truth=None, title=None,
                  site_motion=None):
    """posterior.csv, inversion_summary.json, posterior_map.png and marginals.png in
    ``out_dir`` (and site_motion.json with ``site_motion``, also under the summary's
    ``site_motion``); returns the summary dict."""
    from pipeline.figures.inversion import plot_marginals, plot_posterior_map  # lazy: matplotlib, not imported by a run or after Ctrl-C
    out_dir = Path(out_dir)
    write_csv(out_dir / "posterior.csv", post.frame())
    figures = [plot_posterior_map(post, observations, out_dir / "posterior_map.png",
                                  truth_km=None if truth is None else truth.get("epicentre_km"),
                                  title=title),
               plot_marginals(post, out_dir / "marginals.png", truth=truth)]
    summary = {**post.summary(),
               "frame": f"km East/North of the first site ({observations.sites[0].name}); "
                        "back azimuth: from the first site to the epicentre, deg clockwise "
                        "from North",
               "first_site": observations.sites[0].name,
               "prior": post.info.get("prior"),
               "likelihood": {"kind": post.info.get("likelihood"),
                              "kernel_deg": post.info.get("kernel_deg"),
                              "floor": post.info.get("floor"),
                              "p_toppled": "(k + 1/2) / (n + 1) per node"},
               "candidate_grid": post.info.get("grid"),
               "beyond_table_fraction": post.info.get("beyond_table_fraction"),
               "table_last_ring_km": post.info.get("table_last_ring_km"),
               "observations": observations.as_dict(),
               "n_columns": observations.n_columns, "n_fallen": observations.n_fallen,
               "forward_table": forward_info or {},
               "outputs": ["posterior.csv", "inversion_summary.json"]
               + [Path(f).name for f in figures]}
    if truth is not None:
        summary["truth"] = truth
    if site_motion is not None:
        write_json(out_dir / "site_motion.json", site_motion)
        summary["site_motion"] = site_motion
        summary["outputs"].append("site_motion.json")
    write_json(out_dir / "inversion_summary.json", summary)
    return summary


def run_inversion(observations, out_dir, table, candidates, kernel_deg=None, floor=None,
                  forward_info=None, likelihood=DEFAULT_LIKELIHOOD, truth=None,
                  site_motion=None):
    """Invert ``observations`` with the forward ``table`` over ``candidates`` and write the
    outputs into ``out_dir`` (locked while writing); return the summary dict.  ``truth``
    (a hidden-truth test's source: :meth:`pipeline.inversion.truth.HiddenTruth.as_truth`)
    is marked in the figures and checked against the credible regions (``truth.check``)."""
    started = time.monotonic()
    model = ForwardModel(table, DEFAULT_KERNEL_DEG if kernel_deg is None else kernel_deg,
                         DEFAULT_FLOOR if floor is None else floor,
                         likelihood)
    post = invert(model, observations, candidates)
    if truth is not None:
        truth = {**truth, "check": truth_check(post, truth)}
    with DirectoryLock(out_dir, wait=False):
        summary = write_outputs(post, observations, out_dir, forward_info, truth=truth,
                                site_motion=site_motion)
    summary["inversion_s"] = round(time.monotonic() - started, 2)
    return summary


def truth_check(post, truth, summary=None):
    """Whether the posterior's credible regions hold a known source (``truth``: epicentre_km
    in the inversion's frame, back_azimuth_deg, distance_km, mechanism, mw), whether the
    source lies within the inversion's reach, and whether the outputs warn that it may lie
    beyond (``*_or_warned``: the region holds the truth or the warning is there).  The
    magnitude: in the 95 % interval (``mw_in_95``; above it when the interval is open above:
    the shell beyond the reach in the 95 % region), a table slice's (``mw_in_table``),
    within the table's range of magnitudes (``mw_in_table_range``: beyond it the
    inversion cannot answer).
    ``summary``: ``post.summary()`` when computed already."""
    summary = post.summary() if summary is None else summary
    east, north = truth["epicentre_km"]
    lo, hi = summary["distance_ci95_km"]
    map_e, map_n = summary["map_epicentre_km"]
    mw = float(truth["mw"])
    mw_lo, mw_hi = summary["magnitude_ci95"]
    low, high = summary["magnitude_range"]
    warned = summary["reach_warning"] is not None
    epicentre_in_95 = post.contains(east, north, level=0.95)
    distance_in_95 = bool(lo <= truth["distance_km"] <= (math.inf if hi is None else hi))
    return {"within_reach": post.within_reach(east, north),
            "reach_warning": warned,
            "epicentre_in_95_or_warned": epicentre_in_95 or warned,
            "distance_in_95_or_warned": distance_in_95 or warned,
            "epicentre_in_95": epicentre_in_95,
            "epicentre_in_68": post.contains(east, north, level=0.68),
            "back_azimuth_in_95": in_arc(truth["back_azimuth_deg"],
                                         summary["back_azimuth_ci95_deg"]),
            "distance_in_95": distance_in_95,
            "map_epicentre_error_km": float(math.hypot(map_e - east, map_n - north)),
            "reach_edge_fraction": summary["reach_edge_fraction"],
            "reach_edge_bayes_factor": summary["reach_edge_bayes_factor"],
            "mw_in_95": bool(mw_lo - 1e-9 <= mw and (
                mw <= mw_hi + 1e-9 or summary["magnitude_ci95_open_above"])),
            "p_beyond": summary["p_beyond"],
            "mw_in_table": f"{mw:g}" in {f"{s['mw']:g}" for s in post.info.get(
                "table_slices", post.slices)},
            "mw_in_table_range": bool(low - 1e-9 <= mw <= high + 1e-9),
            "p_true_mechanism": summary["mechanism_posterior"].get(truth["mechanism"], 0.0)}
