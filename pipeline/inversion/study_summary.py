"""The member study's tables (:mod:`pipeline.inversion.study`): per configuration and per
placement the coverages of the 95 % regions with their Wilson intervals, the widths and
areas, the reach warning's false alarms and hits, and the study's answer in words."""
import numpy as np
import pandas as pd

from pipeline.inversion.demo import BOUND_DEG, BOUND_TEXT, BOUNDED_FRACTION_KEY
from pipeline.inversion.study import BEYOND_PLACEMENTS, PLACEMENTS
from pipeline.stats.ensemble import wilson_interval


def study_summary(trials):
    """Per (likelihood, L, S, K): coverages with Wilson intervals, widths, areas, Mw, and
    per placement the trials and the coverages (a warning counted as an answer for the
    epicentre and the distance)."""
    rows = []
    keys = ["likelihood", "likelihood_members", "sites", "fallen_per_site"]
    for key, g in trials.groupby(keys):
        n = len(g)
        hit = int(g["back_azimuth_in_95"].sum())
        ci = wilson_interval(hit, n)
        inside = g["within_reach"].astype(bool)
        beyond = g[~inside]
        per_placement = {}
        for placement in PLACEMENTS:
            part = g[g["placement"] == placement]
            per_placement[f"trials_{placement}"] = len(part)
            for column in ("back_azimuth_in_95", "epicentre_in_95_or_warned",
                           "distance_in_95_or_warned", "mw_in_95"):
                name = "coverage_" + column.replace("_in_", "_")
                per_placement[f"{name}_{placement}"] = \
                    float(part[column].mean()) if len(part) else np.nan
            per_placement[f"warned_{placement}"] = \
                float(part["reach_warning"].mean()) if len(part) else np.nan
        for column in ("back_azimuth_in_95", "epicentre_in_95", "distance_in_95", "mw_in_95"):
            name = "coverage_" + column.replace("_in_", "_") + "_within_reach"
            per_placement[name] = float(g[inside][column].mean()) if inside.any() else np.nan
        rows.append({**dict(zip(keys, key)), "fallen_total": key[2] * key[3], "trials": n,
                     "coverage_back_azimuth_95": hit / n, "coverage_ci95": ci,
                     "calibrated": bool(ci[0] <= 0.95 <= ci[1]),
                     "width_median_deg": float(g["width95_deg"].median()),
                     **_directed(g["width95_deg"]),
                     BOUNDED_FRACTION_KEY: float((g["width95_deg"] <= BOUND_DEG).mean()),
                     "coverage_epicentre_95": float(g["epicentre_in_95"].mean()),
                     "coverage_epicentre_ci95": wilson_interval(int(g["epicentre_in_95"].sum()),
                                                                n),
                     "credible_area_95_km2_median": float(g["credible_area_95_km2"].median()),
                     "coverage_distance_95": float(g["distance_in_95"].mean()),
                     "coverage_distance_ci95": wilson_interval(int(g["distance_in_95"].sum()),
                                                               n),
                     "coverage_epicentre_95_or_warned":
                         float(g["epicentre_in_95_or_warned"].mean()),
                     "coverage_distance_95_or_warned":
                         float(g["distance_in_95_or_warned"].mean()),
                     "beyond_reach_fraction": len(beyond) / n,
                     "beyond_reach_warned": float(beyond["reach_warning"].mean())
                     if len(beyond) else np.nan,
                     "reach_warning_fraction": float(g["reach_warning"].mean()),
                     "warned_within_reach": float(g[inside]["reach_warning"].mean())
                     if inside.any() else np.nan,
                     "coverage_mw_95": float(g["mw_in_95"].mean()),
                     "coverage_mw_ci95": wilson_interval(int(g["mw_in_95"].sum()), n),
                     "p_true_mw_median": float(g["p_true_mw"].median()),
                     "p_true_mechanism_median": float(g["p_true_mechanism"].median()),
                     **per_placement})
    return pd.DataFrame(rows)


PLACEMENT_COLUMNS = ("back_azimuth_in_95", "distance_in_95", "epicentre_in_95", "mw_in_95",
                     "reach_warning", "fit_warning", "beyond_warning")
WELL_WITHIN = "well within the reach"
REACH_PARTS = ((WELL_WITHIN, "false_alarm"), ("at the reach's edge", "edge"),
               ("beyond the reach", "hit"))      # (placement label, warning_rates' name)


def placement_summary(trials):
    """Per likelihood, likelihood members and placement, pooled over S and K: trials,
    how many lie within the reach, the coverages of back azimuth, distance, epicentre and
    magnitude (Wilson intervals), the reach warning's rate and the share refused for want
    of a candidate within reach of every site (``no_candidate``, counted as warned), the
    fit check's share of it (``fit_warning``); the same for each placement's sources well
    within the reach, and for all sources ``well within the reach`` (every site nearer
    than the likelihood's last ring less a cell: the warning's false alarms), ``at the
    reach's edge`` and ``beyond the reach`` (its hits), and these three per number of
    sites (``..., 1 site(s)``, their number in ``sites``; None for the others)."""
    rows = []
    keys = ["likelihood", "likelihood_members"]
    for key, g in trials.groupby(keys):
        inside = g["within_reach"].astype(bool)
        edge = g["at_reach_edge"].astype(bool)
        parts = [(placement, None, g[g["placement"] == placement]) for placement in PLACEMENTS]
        parts += [(f"{placement}, {WELL_WITHIN}", None,
                   g[(g["placement"] == placement) & inside & ~edge])
                  for placement in PLACEMENTS if placement not in BEYOND_PLACEMENTS]
        reach = [(WELL_WITHIN, inside & ~edge), ("at the reach's edge", inside & edge),
                 ("beyond the reach", ~inside)]
        parts += [(label, None, g[mask]) for label, mask in reach]
        parts += [(f"{label}, {sites} site(s)", int(sites), g[mask & (g["sites"] == sites)])
                  for sites in sorted(g["sites"].unique()) for label, mask in reach]
        for placement, sites, part in parts:
            if part.empty:
                continue
            row = {**dict(zip(keys, key)), "placement": placement, "sites": sites,
                   "trials": len(part),
                   "within_reach": int(part["within_reach"].astype(bool).sum())}
            for column in PLACEMENT_COLUMNS:
                if column not in part:
                    continue
                hits = int(part[column].astype(bool).sum())
                name = column if column.endswith("_warning") else \
                    "coverage_" + column.replace("_in_", "_")
                row[name] = hits / len(part)
                row[f"{name}_ci95"] = wilson_interval(hits, len(part))
            row["width_median_deg"] = float(part["width95_deg"].median())
            row["no_candidate"] = float(part["no_candidate"].astype(bool).mean())
            rows.append(row)
    return pd.DataFrame(rows)


def warning_rates(placements):
    """{likelihood: {members, false_alarm_rate, edge_rate, hit_rate, with Wilson intervals,
    trials, the share refused for want of a candidate, the fit check's and the test of
    the sources beyond's shares, and ``by_sites``: the same per number of sites}} at each
    likelihood's largest member count: the reach warning well within the reach, at its
    edge and beyond it."""
    out = {}
    for kind, g in placements.groupby("likelihood"):
        g = g[g["likelihood_members"] == g["likelihood_members"].max()].set_index("placement")
        entry = {"likelihood_members": int(g["likelihood_members"].iloc[0]),
                 **_rates(g, "")}
        sites = sorted(int(n) for n in g["sites"].dropna().unique())
        entry["by_sites"] = {str(n): _rates(g, f", {n} site(s)") for n in sites}
        out[kind] = entry
    return out


def _rates(g, suffix):
    entry = {}
    for label, name in REACH_PARTS:
        label += suffix
        if label not in g.index:
            continue
        entry[f"{name}_rate"] = float(g.loc[label, "reach_warning"])
        entry[f"{name}_rate_ci95"] = list(g.loc[label, "reach_warning_ci95"])
        entry[f"{name}_trials"] = int(g.loc[label, "trials"])
        entry[f"{name}_no_candidate"] = float(g.loc[label, "no_candidate"])
        for column, key in (("fit_warning", "fit"), ("beyond_warning", "beyond_test")):
            if column in g.columns:
                entry[f"{name}_{key}_rate"] = float(g.loc[label, column])
    return entry


def study_answer(summary):
    """The sentence per likelihood at its largest L: the fewest columns (S sites x K fallen
    per site) whose median 95 % arc is at most BOUND_DEG wide with calibrated coverage, or what
    the largest configuration reaches instead."""
    out = {}
    for kind, g in summary.groupby("likelihood"):
        size = int(g["likelihood_members"].max())
        at = g[g["likelihood_members"] == size].sort_values(["fallen_total", "sites"])
        ok = at[(at["width_median_deg"] <= BOUND_DEG) & at["calibrated"]]
        smallest = g[g["likelihood_members"] == g["likelihood_members"].min()]
        big = at.iloc[-1]
        trend = smallest[(smallest["sites"] == big["sites"])
                         & (smallest["fallen_per_site"] == big["fallen_per_site"])]
        if not ok.empty:
            first = ok.iloc[0]
            text = (f"{kind} likelihood, {size} members per node: {int(first['sites'])} site(s) "
                    f"with {int(first['fallen_per_site'])} fallen column(s) each bound the back "
                    f"azimuth to {BOUND_TEXT} (median 95 % arc {first['width_median_deg']:.0f} deg, "
                    f"coverage {first['coverage_back_azimuth_95']:.2f} "
                    f"[{first['coverage_ci95'][0]:.2f}, {first['coverage_ci95'][1]:.2f}])")
        else:
            text = (f"{kind} likelihood, {size} members per node: no tested configuration "
                    f"bounds the back azimuth to {BOUND_TEXT} with calibrated coverage")
            narrow = at[at["width_median_deg"] <= BOUND_DEG]
            if not narrow.empty:
                first = narrow.iloc[0]
                text += (f" ({int(first['sites'])} site(s) x {int(first['fallen_per_site'])} "
                         f"fallen narrow the median 95 % arc to "
                         f"{first['width_median_deg']:.0f} deg, but it holds the truth in "
                         f"{first['coverage_back_azimuth_95']:.2f} "
                         f"[{first['coverage_ci95'][0]:.2f}, {first['coverage_ci95'][1]:.2f}] "
                         f"of the trials)")
            else:
                text += f" (the most columns: coverage {big['coverage_back_azimuth_95']:.2f})"
        text += (f"; with the most columns tested ({int(big['sites'])} site(s) x "
                 f"{int(big['fallen_per_site'])} fallen) the median arc is "
                 f"{big['width_median_deg']:.0f} deg, coverage "
                 f"{big['coverage_back_azimuth_95']:.2f}")
        if big.get("directed_fraction", 1.0) < 1.0 and big["directed_fraction"] > 0:
            text += (f" ({100 * big['directed_fraction']:.0f} % of the trials give a direction, "
                     f"their median arc {big['width_median_directed_deg']:.0f} deg)")
        if not trend.empty and int(trend.iloc[0]["likelihood_members"]) != size:
            text += (f" ({trend.iloc[0]['width_median_deg']:.0f} deg, coverage "
                     f"{trend.iloc[0]['coverage_back_azimuth_95']:.2f} with "
                     f"{int(trend.iloc[0]['likelihood_members'])} members)")
        text += (f", the epicentre's 95 % area {big['credible_area_95_km2_median']:.0f} km^2 "
                 f"(coverage {big['coverage_epicentre_95']:.2f}), the distance's 95 % "
                 f"interval holds the truth in {big['coverage_distance_95']:.2f} of the trials")
        if "coverage_epicentre_95_or_warned" in big:
            text += (f" (the truth or a warning that the source may lie beyond the reach: "
                     f"epicentre {big['coverage_epicentre_95_or_warned']:.2f}, distance "
                     f"{big['coverage_distance_95_or_warned']:.2f})")
        text += (f" and the true magnitude lies in the 95 % set in "
                 f"{big['coverage_mw_95']:.2f} of the trials")
        out[kind] = text
    return out


def _directed(widths_deg):
    """The share of trials that give a direction (a 95 % arc under 360 deg: a warned
    trial gives the whole circle) and their median arc (deg; NaN when none does)."""
    directed = widths_deg[widths_deg < 360.0]
    return {"directed_fraction": float(len(directed) / len(widths_deg)) if len(widths_deg)
            else float("nan"),
            "width_median_directed_deg": float(directed.median()) if len(directed)
            else float("nan")}


REGIONS = ("distance_in_95", "epicentre_in_95", "mw_in_95")


def beyond_hypothesis(trials):
    """{likelihood: {likelihood_members, beyond: {sites: {sites beyond the reach: ...}},
    just_beyond: {...}, well_within: {sites: ...}}} at each likelihood's largest member
    count: for the sources beyond the reach (``just_beyond``: those of that placement
    alone: every site within ``JUST_BEYOND_FACTOR`` times the reach), the coverage of the distance,
    epicentre and magnitude regions (a region holds the truth or the inversion refuses:
    ``coverage_*``, Wilson intervals) and P(beyond) (``p_beyond_*``, refusals left out),
    per number of sites and per number of those beyond the reach (``all`` pooled); for the
    sources well within it, the same, P(beyond)'s 90th percentile and the share whose 95 %
    region holds the shell."""
    if "p_beyond" not in trials.columns:
        return {}
    out = {}
    for kind, g in trials.groupby("likelihood"):
        g = g[g["likelihood_members"] == g["likelihood_members"].max()]
        inside = g["within_reach"].astype(bool)
        well = g[inside & ~g["at_reach_edge"].astype(bool)]
        within = {}
        for sites, part in well.groupby("sites"):
            p = part["p_beyond"].dropna()
            within[str(int(sites))] = {
                **_covered(part), "p_beyond_p90": float(p.quantile(0.9)) if len(p) else None,
                "beyond_in_95": float(part["beyond_in_95"].astype(bool).mean())}
        out[kind] = {"likelihood_members": int(g["likelihood_members"].iloc[0]),
                     "beyond": _by_sites(g[~inside]),
                     "just_beyond": _by_sites(g[~inside & (g["placement"] == "just_beyond")]),
                     "well_within": within}
    return out


def _by_sites(part):
    """{sites: {"all" | sites beyond the reach: :func:`_covered`}}."""
    return {str(int(sites)): {"all": _covered(q), **{
        str(int(n)): _covered(r) for n, r in q.groupby("sites_beyond")}}
        for sites, q in part.groupby("sites")}


def _covered(part):
    """Trials, the share refused, P(beyond)'s mean and median (refusals left out) and each
    region's coverage (held or refused)."""
    refused = part["no_candidate"].astype(bool)
    p = part["p_beyond"].dropna()
    entry = {"trials": len(part), "refused": float(refused.mean()),
             "p_beyond_mean": float(p.mean()) if len(p) else None,
             "p_beyond_median": float(p.median()) if len(p) else None}
    for column in REGIONS:
        hits = int((part[column].astype(bool) | refused).sum())
        name = "coverage_" + column.replace("_in_", "_")
        entry[name] = hits / len(part)
        entry[f"{name}_ci95"] = list(wilson_interval(hits, len(part)))
    return entry
