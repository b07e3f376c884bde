"""The REPORT's member-study section (``invert --member-study``, ``make invert-study``):
the answer per likelihood, the coverages per configuration and per placement of the
source, the reach warning's rates, and the shell beyond the reach in the posterior."""
import json
from pathlib import Path

import pandas as pd

from pipeline.inversion.beyond import PRIOR_BEYOND, SHELL_FACTOR
from pipeline.inversion.study import JUST_BEYOND_FACTOR
from pipeline.report.common import _figure, _fmt, _table
from pipeline.report.inversion import _table_provenance, _toppled_by_slice


def member_study_section(results):
    """How many fallen columns bound the source (invert --member-study, make invert-study):
    the answer per likelihood, the table at the largest likelihood size and the figure."""
    base = Path(results) / "inversion" / "member-study"
    title = "## How many fallen columns bound the earthquake's direction?\n"
    path = base / "member_study.json"
    if not path.exists():
        return title + ("\nNot run yet (`make invert-study`: truth tests at 3-48 likelihood "
                        "members per node, 3,072 YADE runs).\n")
    study = json.loads(path.read_text())
    summary = pd.read_csv(base / "member_study_summary.csv")
    grid = (study.get("forward_table") or {}).get("grid") or {}
    lines = [title, f"Truth tests on a forward table of {grid.get('members', '?')} members per "
             f"node ({', '.join(m[0] for m in grid.get('mechanisms', []))}; Mw "
             f"{', '.join(f'{v:g}' for v in grid.get('magnitudes', []))}; rings "
             f"{', '.join(f'{v:g}' for v in grid.get('distances_km', []))} km every "
             f"{_fmt(grid.get('azimuth_step_deg'))} deg): the observed columns come from the "
             f"last {study['observation_members']} members, which no likelihood uses; the "
             f"likelihood from the first {', '.join(map(str, study['likelihood_members']))}; "
             f"{study['trials']} trials per configuration, the same draws for every size"
             + (f"; the predictive likelihood counts a site's columns as m = "
                f"{study['site_columns']:g} site columns' worth of its node's (chosen on "
                f"draws of another seed than these trials' {study['seed']})" if "site_columns" in study
                else "") + ".\n"]
    lines.append(_table_provenance(study.get("forward_table") or {}))
    lines.append(_toppled_by_slice(study.get("toppled_fraction_by_slice") or []))
    if "trials_beyond" in summary.columns:
        spokes = "trials_between_spokes" in summary.columns
        lines.append("The trials' sources lie as sources come, off the table's nodes: the "
                     "strike anywhere between the candidates' steps; the sites, in equal "
                     "shares of the trials, on the nodes of the likelihood's table, between "
                     "the rings it keeps (its inner rings left out), "
                     + ("halfway between its spokes (every other node azimuth left out), "
                        "the magnitude between two slices (each observed column one of the "
                        "upper slice's with the source's weight between them, the mixture "
                        "the likelihood assumes between slices), " if spokes else "")
                     + "or the first of them beyond its last ring (left out: the source "
                     "lies beyond the inversion's reach, and the answer wanted is regions "
                     "that hold it beyond the reach, or a warning that it may lie "
                     "farther).\n")
    lines += [f"- {text}." for text in study["answer"].values()]
    largest = summary[summary["likelihood_members"] == summary["likelihood_members"].max()]
    names = {"fallen_per_site": "fallen per site",
             "coverage_back_azimuth_95": "back-azimuth coverage",
             "width_median_deg": "median 95 % arc (deg)",
             "coverage_distance_95": "distance coverage",
             "coverage_epicentre_95": "epicentre coverage",
             "coverage_epicentre_95_or_warned": "epicentre covered or warned",
             "coverage_distance_95_or_warned": "distance covered or warned",
             "beyond_reach_warned": "beyond the reach: warned",
             "warned_within_reach": "within the reach: warned",
             "credible_area_95_km2_median": "median 95 % area (km^2)",
             "coverage_mw_95": "Mw coverage"}
    table = largest[["likelihood", "sites", "fallen_per_site", "trials"]
                    + [c for c in list(names)[1:] if c in largest.columns]].rename(columns=names)
    lines += ["", f"At {int(summary['likelihood_members'].max())} likelihood members per node:",
              "", _table(table.round(2)) + "\n"]
    lines += _placement_lines(base, study)
    lines += _beyond_lines(study)
    lines += [_figure(results, base / "member_study.png", "member study"),
              "\nThe same truth tests for the epicentre, the distance and the magnitude (the "
              "standing columns take part in the likelihood as much as the fallen ones):\n",
              _figure(results, base / "member_study_source.png",
                      "member study: epicentre and magnitude")]
    return "\n".join(lines)


def _placement_lines(base, study):
    """Per placement of the source (member_study_placements.csv, at the largest likelihood
    size, pooled over sites and columns): the coverages and the reach warning's rates
    (member_study.json ``reach_warning``); nothing for older studies."""
    path = base / "member_study_placements.csv"
    if not path.exists():
        return []
    placements = pd.read_csv(path)
    largest = placements[placements["likelihood_members"]
                         == placements["likelihood_members"].max()]
    names = {"placement": "source", "coverage_back_azimuth_95": "back azimuth",
             "coverage_distance_95": "distance", "coverage_epicentre_95": "epicentre",
             "coverage_mw_95": "Mw", "reach_warning": "warned",
             "fit_warning": "by the fit check", "beyond_warning": "by the test beyond",
             "no_candidate": "no candidate", "width_median_deg": "median arc (deg)"}
    words = {"node": "on the nodes", "between": "between the rings",
             "between_spokes": "between the spokes", "between_magnitudes":
             "between the magnitudes", "beyond": "beyond the last ring",
             "just_beyond": "just beyond the last ring"}
    table = largest[["likelihood", "trials"] + [c for c in names if c in largest.columns]]
    table = table.rename(columns=names)
    table["source"] = table["source"].map(
        lambda v: ", ".join(words.get(part, part) for part in v.split(", ")))
    lines = ["By where the source lies (all sites and columns together; a warning gives "
             "the whole circle for the back azimuth, and \"no candidate\": sites too far "
             "apart for the reach, refused and counted as warned):", "",
             _table(table.round(2)) + "\n"]
    for kind, rates in (study.get("reach_warning") or {}).items():
        if "false_alarm_rate" not in rates or "hit_rate" not in rates:
            continue
        fa, hit = rates["false_alarm_rate_ci95"], rates["hit_rate_ci95"]
        lines.append(
            f"The reach warning, {kind} likelihood: given for {rates['false_alarm_rate']:.2f} "
            f"[{fa[0]:.2f}, {fa[1]:.2f}] of {rates['false_alarm_trials']} sources well "
            f"within the reach, {rates.get('edge_rate', float('nan')):.2f} of those at its "
            f"edge, and {rates['hit_rate']:.2f} [{hit[0]:.2f}, {hit[1]:.2f}] of "
            f"{rates['hit_trials']} beyond it ({rates['hit_no_candidate']:.2f} of those had "
            "no candidate within reach of every site and were refused"
            + (f"; the fit check gave it for {rates['false_alarm_fit_rate']:.2f} of the "
               f"sources well within and {rates['hit_fit_rate']:.2f} of those beyond"
               if {"hit_fit_rate", "false_alarm_fit_rate"} <= set(rates) else "")
            + (f"; the test of the sources beyond gave it for "
               f"{rates['false_alarm_beyond_test_rate']:.2f} and {rates['hit_beyond_test_rate']:.2f}"
               if {"hit_beyond_test_rate", "false_alarm_beyond_test_rate"} <= set(rates)
               else "")
            + ")." + _by_sites(rates.get("by_sites") or {}) + "\n")
    return lines


def _by_sites(by_sites):
    """The reach warning's rates per number of sites, in words."""
    said = [f"{n} site(s): {r['false_alarm_rate']:.2f} of {r['false_alarm_trials']} well "
            f"within, {r['hit_rate']:.2f} of {r['hit_trials']} beyond"
            for n, r in by_sites.items() if {"false_alarm_rate", "hit_rate"} <= set(r)]
    if not said:
        return ""
    return (" By the number of sites: " + "; ".join(said) + "." + (
        " One site cannot tell a source beyond the reach from a nearer, smaller one (the "
        "test of the sources beyond cannot either), so every one-site inversion says so in "
        "a note instead; its direction does not depend on it (the table above: the back "
        "azimuth's coverage beyond the reach with one site)." if "1" in by_sites else ""))


def _beyond_lines(study):
    """The shell beyond the reach in the posterior (member_study.json
    ``beyond_hypothesis``): for the sources beyond the reach, the coverage of the
    distance, epicentre and magnitude regions (held or refused) by number of sites and of
    those beyond the reach; for those well within it, the mass put beyond and the same
    coverages; nothing for older studies."""
    rows, within = [], []
    for kind, entry in (study.get("beyond_hypothesis") or {}).items():
        for which, label in (("beyond", "all"), ("just_beyond", "just beyond")):
            for sites, parts in entry.get(which, {}).items():
                for beyond, r in parts.items():
                    rows.append({"likelihood": kind, "sources": label, "sites": sites,
                                 "sites beyond": "any" if beyond == "all" else beyond,
                                 **_coverages(r),
                                 "mean P(beyond)": r.get("p_beyond_mean")})
        for sites, r in entry["well_within"].items():
            within.append({"likelihood": kind, "sites": sites, **_coverages(r),
                           "mean P(beyond)": r["p_beyond_mean"],
                           "median P(beyond)": r["p_beyond_median"],
                           "90th pct P(beyond)": r["p_beyond_p90"],
                           "shell in 95 % region": r["beyond_in_95"]})
    if not rows:
        return []
    return [f"The posterior carries the sources beyond the reach (a shell of epicentres out "
            f"to {SHELL_FACTOR:g} times the last ring, its likelihood extrapolated by the "
            f"table's decay, prior {PRIOR_BEYOND:g}).  Sources beyond the reach (all, and "
            "just beyond: every site within "
            f"{JUST_BEYOND_FACTOR:g} times the reach), "
            "by number of sites and of those beyond the reach (covered: the 95 % region holds the "
            "truth, the distance interval open above and the magnitude's reaching the "
            "table's largest where the shell lies in the region, or the inversion refuses):",
            "", _table(pd.DataFrame(rows).round(2)) + "\n",
            "Sources well within the reach: the posterior's mass put beyond it and the "
            "coverages:", "", _table(pd.DataFrame(within).round(3)) + "\n"]


def _coverages(entry):
    return {"trials": entry["trials"], "refused": entry["refused"],
            "distance": entry["coverage_distance_95"],
            "epicentre": entry["coverage_epicentre_95"], "Mw": entry["coverage_mw_95"]}
