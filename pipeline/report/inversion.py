"""Report section of the source inversion (make invert-demo)."""
import json
from pathlib import Path

import pandas as pd

from pipeline.report.common import _figure, _fmt, _pct, _table
from pipeline.inversion.demo import (BOUND_ANSWER_KEY, BOUND_DEG, BOUND_TEXT,
                                     BOUNDED_FRACTION_KEY, SITES_WITHIN_KEY)
from pipeline.inversion.presets import GRIDS
from pipeline.simulate import run_code_version


def inversion_section(results):
    """The source inversion demo (make invert-demo): coverage of the synthetic truth tests,
    how the back azimuth narrows with the evidence, the paper's question in numbers and what
    the paper's twin columns could have told."""
    path = Path(results) / "inversion" / "demo_summary.json"
    title = "## Inverting fallen columns for the source\n"
    if not path.exists():
        return title + "\nNot run yet (`make invert-demo`).\n"
    demo = json.loads(path.read_text())
    inv = Path(results) / "inversion"
    lines = [title]
    for part in (_forward_table_lines, _likelihood_lines, _coverage_lines, _narrowing_lines,
                 _paper_scenario_lines, _example_lines):
        lines += part(demo)
    for fig in demo.get("figures", []):
        lines.append(_figure(results, inv / fig, Path(fig).parent.name or Path(fig).stem))
    return "\n".join(lines)


def _forward_table_lines(demo):
    """The forward table's grid and cost, and what the default grid would cost."""
    lines = []
    forward = demo.get("forward_table", {})
    grid = forward.get("grid") or {}
    costs = forward.get("costs", {})
    runs = sum((c.get("runs") or 0) for c in costs.values())
    wall = sum((c.get("yade_wall_s") or 0) for c in costs.values())
    mechs = ", ".join(m[0] for m in grid.get("mechanisms", []))
    lines.append(
        f"Forward table (preset `{forward.get('preset', '?')}`): {mechs or '?'}; depth "
        f"{', '.join(f'{v:g}' for v in grid.get('depths_km', []))} km; Mw "
        f"{', '.join(f'{v:g}' for v in grid.get('magnitudes', []))}; rings "
        f"{', '.join(f'{v:g}' for v in grid.get('distances_km', []))} km every "
        f"{_fmt(grid.get('azimuth_step_deg'))} deg from the strike; "
        f"{grid.get('members', '?')} members + the nominal run per node; motions "
        f"{_fmt(grid.get('duration_s'))} s to {_fmt(grid.get('fmax_hz'))} Hz.  {runs} YADE runs "
        f"(with the paper scenario's), {wall / 3600:.1f} h of YADE wall time in total"
        + (f" ({wall / runs:.0f} s per run on a shared 2-core machine)" if runs else "")
        + (".  The table was computed from a snapshot of the code (version "
           f"{forward.get('code_version')}) and read with `--table`."
           if forward.get("reused_file") else ".") + "\n")
    if runs:
        full = GRIDS["full"]
        lines.append(f"The default (`full`) grid, {len(full.mechanisms)} mechanisms x "
                     f"{len(full.depths_km)} depths x {len(full.magnitudes)} magnitudes x "
                     f"{len(full.distances_km)} rings x {int(360 / full.azimuth_step_deg)} "
                     f"azimuths x {full.members + 1} runs = {full.n_runs()} runs, would take "
                     f"about {full.n_runs() * wall / runs / 2 / 3600:.0f} h on 2 cores at "
                     "that rate: the demo runs the smaller grid above.\n")
    return lines


def _likelihood_lines(demo):
    lines = []
    like = demo.get("likelihood", {})
    lines.append(
        f"Likelihood from members {like.get('members_likelihood')}, \"observed\" columns drawn "
        f"from members {like.get('members_observations')} (never the same runs); kernel "
        f"{_fmt(like.get('kernel_deg'))} deg, floor {_fmt(like.get('floor'), 2)}, observed "
        f"azimuths with {_fmt(demo.get('observation_uncertainty_deg'))} deg (1 sigma) errors. "
        f"Candidates: {demo.get('prior', '')}.\n")
    return lines


def _coverage_lines(demo):
    """(a) coverage of the truth tests per likelihood."""
    lines = []
    coverage = demo.get("coverage", {})
    if coverage and "trials" in coverage:            # one likelihood (older summaries)
        coverage = {"independent": coverage}
    lines.append(f"**(a) Coverage** of the synthetic truth tests ("
                 f"{demo.get('trials_per_configuration', '?')} trials for each configuration of "
                 "the table below):\n")
    for kind, cov in coverage.items():
        lines.append(
            f"- {kind} likelihood, {cov.get('trials', 0)} inversions: the 95 % back-azimuth "
            f"arc holds the true back azimuth in {_pct(cov.get('back_azimuth_95'))}, the 95 % "
            f"epicentre region the true epicentre in {_pct(cov.get('epicentre_95'))}, the 95 % "
            f"distance interval the true distance in {_pct(cov.get('distance_95'))}; the 68 % "
            f"arc in {_pct(cov.get('back_azimuth_68'))}." + _reach_coverage(cov))
    lines.append("")
    return lines


def _reach_coverage(cov):
    """What the truth tests' sources beyond the inversion's reach meant: the regions that
    held the truth or a warning that it may lie farther (older summaries: nothing)."""
    if cov.get("epicentre_95_or_warned") is None:
        return ""
    return (f"  The true source lay within the forward table's reach of every site in "
            f"{_pct(cov.get('within_reach'))} of them; the 95 % region held it or the "
            f"inversion warned that it may lie farther in "
            f"{_pct(cov.get('epicentre_95_or_warned'))} (the distance: "
            f"{_pct(cov.get('distance_95_or_warned'))}; a warning in "
            f"{_pct(cov.get('reach_warning'))} of all).")


def _narrowing_lines(demo):
    """(b) how the back azimuth narrows, (c) how many columns bound it, the findings."""
    lines = []
    narrow = pd.DataFrame(demo.get("narrowing", []))
    if not narrow.empty:
        if "likelihood" not in narrow.columns:
            narrow.insert(0, "likelihood", "independent")
        table = pd.DataFrame({
            "likelihood": narrow["likelihood"],
            "mechanism": narrow["mechanism"], "sites": narrow["sites"],
            "fallen per site": narrow["fallen_per_site"],
            "95 % arc, median (IQR) deg": [
                f"{m:.0f} ({a:.0f}-{b:.0f})" for m, a, b in
                zip(narrow["width_median_deg"], narrow["width_q25_deg"],
                    narrow["width_q75_deg"])],
            f"within {BOUND_TEXT}": [_pct(v) for v in narrow[BOUNDED_FRACTION_KEY]],
            "truth in 95 % arc": [_pct(v) for v in narrow["coverage_back_azimuth_95"]],
            "truth in 95 % region": [_pct(v) for v in narrow["coverage_epicentre_95"]],
            "95 % area km^2": [f"{v:.0f}" for v in narrow["credible_area_95_km2_median"]],
            "P(true mechanism)": [f"{v:.2f}" for v in narrow["p_true_mechanism_median"]]})
        lines.append("**(b) How the back azimuth narrows** with the number of fallen columns "
                     "per site and of sites:\n\n" + _table(table) + "\n")
    answers = []
    for row in demo.get(BOUND_ANSWER_KEY, []):
        who = f"{row.get('likelihood', 'independent')} likelihood, {row['mechanism']}, " \
              f"{row['sites']} site(s)"
        if row["fallen_per_site"]:
            answers.append(f"{who}: {row['fallen_per_site']} fallen column(s) per site "
                           f"({row['fallen_total']} in all; median arc "
                           f"{row['width_median_deg']:.0f} deg, truth inside in "
                           f"{_pct(row['coverage_back_azimuth_95'])})")
        else:
            answers.append(f"{who}: not reached (median arc "
                           f"{row['largest_tested_width_median_deg']:.0f} deg at the most "
                           "columns tried)")
    if answers:
        lines.append("**(c) The paper's question in numbers** - how many fallen columns bound "
                     f"the back azimuth to {BOUND_TEXT} (median 95 % arc <= {BOUND_DEG:g} deg)?\n\n"
                     + "\n".join(f"- {a}" for a in answers) + "\n")
        lines.append(_inversion_findings(demo, narrow) + "\n")
    return lines


def _paper_scenario_lines(demo):
    """The paper's scenario inverted site by site and jointly."""
    lines = []
    paper = demo.get("paper_scenario", {})
    per = paper.get("per_source", [])
    if per:
        rows = []
        for p in per:
            rows.append({"source": p["source"], "sites": p["sites"],
                         "a column fell": p["sites_with_a_fall"],
                         "both fell": p["sites_both_fell"],
                         "95 % arc where a column fell (median deg)":
                             _fmt(p["width95_median_deg_sites_with_falls"]),
                         "truth in the 95 % arc": _pct(
                             p["back_azimuth_in_95_sites_with_falls"]),
                         f"sites within {BOUND_TEXT}": p[SITES_WITHIN_KEY],
                         "MAP error (median deg)":
                             _fmt(p["median_abs_map_error_deg_sites_with_falls"]),
                         **({"warned: may lie farther": p["sites_reach_warning"]}
                            if "sites_reach_warning" in p else {})})
        lines.append("**The paper's scenario.** Each of the paper's sites (rings 5, 10, 20 km, "
                     "every 30 deg) inverted alone from what its twin columns (nominal "
                     "parameters) show:\n\n" + _table(pd.DataFrame(rows)) + "\n")
        for j in paper.get("joint", []):
            mech = max(j["mechanism_posterior"], key=j["mechanism_posterior"].get)
            which = (f"the {j['sites']} sites within {j['sites_within_km']:g} km (half the "
                     f"forward table's last ring: every candidate that near the source is "
                     f"within the table's reach of every site)" if "sites_within_km" in j
                     else f"all {j['sites']} sites")
            lines.append(
                f"- {j['source']}, {which} together ({j['fallen']} of "
                f"{j['columns']} columns fell): most probable epicentre "
                f"{j['epicentre_error_km']:.1f} km from the truth, inside the 95 % region: "
                f"{'yes' if j['epicentre_in_95'] else 'no'} ({j['credible_area_95_km2']:.0f} "
                f"km^2); most probable mechanism {mech} "
                f"({j['mechanism_posterior'][mech]:.2f})."
                + (f"  Warning: {j['reach_warning']}." if j.get("reach_warning") else ""))
        lines.append("")
    return lines


def _example_lines(demo):
    lines = []
    example = demo.get("example")
    if example:
        lo, hi = example["back_azimuth_ci95_deg"]
        direction = ("not known (the source may lie beyond the reach)"
                     if example["back_azimuth_map_deg"] is None else
                     f"{example['back_azimuth_map_deg']:.0f} deg, 95 % arc [{lo:.0f}, {hi:.0f}]")
        lines.append(f"Example file `{example['file']}`: back azimuth from site A {direction}"
                     f", 95 % area {example['credible_area_95_km2']:.0f} km^2"
                     + _reach_sentence(example) + ".\n")
    return lines


def _reach_sentence(summary):
    """'; the candidates end R km from the sites (what ends them), F of the posterior in
    their outermost cells' and the warning, from an inversion summary (older: nothing)."""
    if summary.get("reach_km") is None:
        return ""
    text = (f"; the candidates end {summary['reach_km']:g} km from the sites "
            f"({summary.get('reach_limit')}), {_pct(summary.get('reach_edge_fraction'))} of "
            "the posterior in their outermost cells")
    if summary.get("reach_warning"):
        text += ": the source may lie farther than the inversion can tell"
    return text


def _inversion_findings(demo, narrow):
    """Plain-language reading of the truth tests, from their numbers."""
    if narrow.empty or "likelihood" not in narrow.columns:
        return ""
    most = narrow[(narrow["sites"] == narrow["sites"].max())
                  & (narrow["fallen_per_site"] == narrow["fallen_per_site"].max())]
    parts = []
    for kind, g in most.groupby("likelihood", sort=False):
        parts.append(f"with the {kind} likelihood, {int(g['fallen_per_site'].iloc[0])} fallen "
                     f"columns at each of {int(g['sites'].iloc[0])} sites give median 95 % arcs "
                     f"of {', '.join(f'{w:.0f}' for w in g['width_median_deg'])} deg "
                     f"({', '.join(g['mechanism'])}) that hold the truth in "
                     f"{', '.join(_pct(c) for c in g['coverage_back_azimuth_95'])} of the trials")
    members = demo.get("likelihood", {}).get("members_likelihood", [])
    reading = "; ".join(parts)
    return ("**Reading.** " + reading[:1].upper() + reading[1:] + ".  The likelihood knows "
            "each node's fall "
            f"distribution from {len(members)} members; the independent product treats the "
            "columns of a site as independent given that estimate, so it narrows with every "
            "column even where the estimate is wrong, while the predictive (Polya-urn) "
            "likelihood lets a site's columns inform each other and stays calibrated.  Where "
            "the two disagree, the ensemble, not the number of columns, limits what the falls "
            "can tell.")


def _table_provenance(info):
    """One sentence on the forward table a study used: runs, YADE time, file, model code
    (and whether it is this checkout's)."""
    if info.get("runs") is None:
        return ""
    text = f"The forward table: {info['runs']} runs"
    if info.get("yade_wall_s") is not None:
        text += f", {info['yade_wall_s'] / 3600:.1f} h of YADE time"
    if info.get("reused_file"):
        text += f", read from `{Path(info['table']).name}`"
    code = info.get("code_version")
    if code:
        here = run_code_version()
        text += f", model code {code}" + ("" if code == here else
                                          f" (this checkout's is {here}: the table was "
                                          "computed by another version of the code that "
                                          "defines a run)")
    return text + ".\n"


def _toppled_by_slice(slices):
    """One sentence: the share of the table's columns that toppled per slice, and what a
    slice where none toppled means for the magnitude."""
    if not slices:
        return ""
    parts = [f"{s['mechanism']} Mw {s['mw']:g} at {s['depth_km']:g} km: {s['fraction']:.2f}"
             for s in slices]
    text = "Columns toppled in the table (all nodes and members): " + "; ".join(parts) + "."
    if any(s["fraction"] == 0 for s in slices):
        text += (" A slice where no column topples is excluded by a single fallen column, so "
                 "the magnitude's coverage below tells only that.")
    return text + "\n"
