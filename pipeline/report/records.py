"""Report sections on records: do toppled columns point to the source (one run per
record), processing against PEER's records, synthetic sources."""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.files import csv_number, csv_true, csv_true_column
from pipeline.report.common import _figure, _fmt, _p, _percent, _read_csv, _table
from pipeline.stats.ensemble import wilson_interval
from pipeline import paper
from pipeline.records.catalog import catalog_row
from pipeline.motion import Motion
from pipeline.stats.circular import (direction_class, direction_differences, direction_statistics,
                                     direction_table)
from pipeline.records import peer_check


REFERENCE_NAMES = {"back_azimuth": "back azimuth", "max_acc": "largest acceleration",
                   "max_vel": "largest velocity", "max_disp": "largest displacement"}
ALPHA = 0.05                     # significance level of the plain-language statements
COLUMN_NAMES = {"drums": "Drum column", "monolithic": "Monolithic column"}
MIN_FALLS = 5                    # fewer falls with a back azimuth: no statement on concentration
FEMA_SOURCE_FILE = "fema_p695.npz"


def toppled_fractions(runs):
    """Per column type: records toppled / run, fraction and Wilson 95 % interval, beside the
    paper's (``paper.RECORDS_TOPPLED_*``)."""
    papers = {"drums": paper.RECORDS_TOPPLED_DRUMS, "monolithic": paper.RECORDS_TOPPLED_MONOLITH}
    rows = []
    for column, group in runs.groupby("column", sort=True):
        k, n = int(group["toppled"].astype(bool).sum()), len(group)
        low, high = wilson_interval(k, n)
        row = {"column": column, "toppled": k, "records": n, "fraction": k / n if n else math.nan,
               "ci_low": low, "ci_high": high}
        if column in papers:
            pk, pn = papers[column]
            plow, phigh = wilson_interval(pk, pn)
            row.update(paper_toppled=pk, paper_records=pn, paper_fraction=pk / pn,
                       paper_ci_low=plow, paper_ci_high=phigh)
        rows.append(row)
    return pd.DataFrame(rows)


def record_orientation(record_id, motion_file=None):
    """(compass, fema) of a run's record: whether its horizontals are compass azimuths and
    whether it is a FEMA P695 pair (catalogue row, else the motion's meta; unknown: True,
    False)."""
    row = catalog_row(str(record_id))
    if row is not None:
        compass = csv_true(str(row.get("horizontals_compass")))
        return compass, row.get("source_file") == FEMA_SOURCE_FILE
    if isinstance(motion_file, str) and Path(motion_file).is_file():
        meta = Motion.load(motion_file).meta
        compass = meta.get("horizontals_compass", True)
        return csv_true(compass if isinstance(compass, bool) else str(compass)), \
            str(meta.get("source_file", "")).endswith(FEMA_SOURCE_FILE)
    return True, False


def with_back_azimuth(runs):
    """The runs whose downfall azimuth can be compared with a back azimuth: known back
    azimuth, compass horizontals, never a FEMA pair.  Adds ``compass`` and ``fema``."""
    runs = runs.copy()
    runs["toppled"] = csv_true_column(runs["toppled"].astype(str))
    files = runs["motion_file"] if "motion_file" in runs.columns else [None] * len(runs)
    cache = {}
    flags = [cache.setdefault(r, record_orientation(r, f)) for r, f in zip(runs["record_id"], files)]
    runs["compass"] = [c for c, _ in flags]
    runs["fema"] = [f for _, f in flags]
    known = np.isfinite(pd.to_numeric(runs["back_azimuth_deg"], errors="coerce").to_numpy(float))
    return runs[known & runs["compass"] & ~runs["fema"]]


def back_azimuth_table(runs):
    """Per column type: toward / away / transverse counts relative to the back azimuth, the
    counts uniform directions would give (1/4, 1/4, 1/2), directional and axial mean
    difference, resultant length and Rayleigh p (``direction_table``)."""
    subset = with_back_azimuth(runs)
    if subset.empty:
        return pd.DataFrame()
    table = direction_table(subset.drop(columns=[c for c in ("source",) if c in subset]))
    table["uniform_toward"] = table["n_toppled"] / 4.0
    table["uniform_away"] = table["n_toppled"] / 4.0
    table["uniform_transverse"] = table["n_toppled"] / 2.0
    return table


def correlation_table(runs):
    """Per column type and reference (back azimuth, largest acceleration, velocity,
    displacement): pairs, mean difference, Rayleigh p (directional and axial) and the
    circular-circular correlation (``direction_statistics``, all records together)."""
    subset = with_back_azimuth(runs)
    if subset.empty:
        return pd.DataFrame()
    if "campaign" not in subset.columns:
        subset = subset.assign(campaign="records")
    stats = direction_statistics(subset.drop(columns=["compass", "fema"]))
    several = stats["record_id"] == "all"
    stats = stats[several] if several.any() else stats
    keep = ["column", "reference", "n", "mean_difference_deg", "resultant_length", "rayleigh_p",
            "axial_mean_difference_deg", "axial_resultant_length", "axial_rayleigh_p",
            "circcorr", "axial_circcorr"]
    return stats[keep].reset_index(drop=True)


def per_record_table(runs):
    """One row per record: id, distance, back azimuth, PGA, and per column type the downfall
    azimuth (or "stands") and its class relative to the back azimuth."""
    runs = runs.copy()
    runs["toppled"] = csv_true_column(runs["toppled"].astype(str))
    comparable = set(with_back_azimuth(runs).index)
    classes = direction_differences(runs)["direction_class"]
    rows = {}
    for index, run in runs.iterrows():
        record = str(run["record_id"])
        row = rows.setdefault(record, {
            "record": record,
            "distance (km)": _fmt(csv_number(run.get("epicentral_distance_km")), 1),
            "back azimuth (deg)": _fmt(csv_number(run.get("back_azimuth_deg"))),
            "PGA (m/s^2)": _fmt(csv_number(run.get("pga_h")), 2)})
        column = run["column"]
        azimuth = csv_number(run.get("downfall_azimuth_deg"))
        row[f"{column} (deg)"] = (_fmt(azimuth) if run["toppled"] and math.isfinite(azimuth)
                                  else "toppled" if run["toppled"] else "stands")
        if not run["toppled"]:
            row[f"{column} class"] = ""
        elif index in comparable:
            row[f"{column} class"] = str(classes.loc[index])
        else:
            row[f"{column} class"] = "no back azimuth"
    return pd.DataFrame(list(rows.values()))


def records_statements(fractions, directions, correlations):
    """Plain-language findings generated from the three tables (a list of paragraphs)."""
    out, answers, tested = [], [], []
    for column in sorted(set(fractions["column"]) if not fractions.empty else []):
        text, answer = _column_statement(column, fractions, directions, correlations)
        out.append(text)
        if answer is not None:
            tested.append(column)
            if answer:
                answers.append((column, *answer))
    out += _paper_answer(fractions, tested, answers)
    return out


def _column_statement(column, fractions, directions, correlations):
    """(paragraph, answer) of one column type: answer None when its falls are too few to
    test, () when tested without a finding, else (findings, whether transverse)."""
    f = fractions[fractions["column"] == column].iloc[0]
    text = (f"**{COLUMN_NAMES.get(column, column)}.** {f['toppled']} of {f['records']} records "
            f"toppled it in one run each ({_percent(f['fraction'])}, 95 % interval "
            f"{_percent(f['ci_low'])}-{_percent(f['ci_high'])}; each run is a sample: a "
            f"record near its threshold can flip with a CPU's last bits, so the count is "
            f"known to its interval, not exactly)")
    if "paper_toppled" in f and math.isfinite(csv_number(f.get("paper_fraction"))):
        inside = f["ci_low"] <= f["paper_fraction"] <= f["ci_high"]
        text += (f"; the paper: {int(f['paper_toppled'])} of {int(f['paper_records'])} "
                 f"({_percent(f['paper_fraction'])}, {_percent(f['paper_ci_low'])}-"
                 f"{_percent(f['paper_ci_high'])}), "
                 + ("inside" if inside else "outside") + " our interval")
    text += "."
    d = directions[directions["column"] == column] if not directions.empty else directions
    if d.empty or int(d.iloc[0]["n_toppled"]) == 0:
        return text + " No fall of this column has a back azimuth to compare with.", None
    d = d.iloc[0]
    n = int(d["n_toppled"])
    text += (f" Of the {n} {'fall' if n == 1 else 'falls'} with a known back azimuth, "
             f"{int(d['toward'])} "
             f"{'was' if int(d['toward']) == 1 else 'were'} toward "
             f"the epicentre (within 45 deg of the back azimuth), {int(d['away'])} away and "
             f"{int(d['transverse'])} transverse; directions independent of the source "
             f"would give about {n / 4:.1f}, {n / 4:.1f} and {n / 2:.1f}.")
    p_dir, p_ax = csv_number(d.get("rayleigh_p")), csv_number(d.get("axial_rayleigh_p"))
    if n < MIN_FALLS:
        return text + (f" Too few falls (fewer than {MIN_FALLS}) to test whether they are "
                       "concentrated relative to the back azimuth."), None
    text += (f" Rayleigh test of downfall minus back azimuth: p = {_p(p_dir)} (as an axis: "
             f"p = {_p(p_ax)}): ")
    findings = []
    if math.isfinite(p_dir) and p_dir < ALPHA:
        where = str(direction_class(d["mean_diff_deg"]))
        findings.append(f"the falls are concentrated {where} (mean difference "
                        f"{d['mean_diff_deg']:+.0f} deg, R = {d['resultant_length']:.2f})")
    if math.isfinite(p_ax) and p_ax < ALPHA:
        axis = ("along the line to the epicentre" if abs(d["axial_mean_diff_deg"]) <= 45
                else "transverse to the line to the epicentre")
        findings.append(f"the fall axes group {axis} (axial mean difference "
                        f"{d['axial_mean_diff_deg']:+.0f} deg, R = "
                        f"{d['axial_resultant_length']:.2f})")
    answer = ()
    if findings:
        text += "; ".join(findings) + f" at the {100 * ALPHA:g} % level."
        answer = ("; ".join(findings), "transverse" in " ".join(findings))
    else:
        text += (f"the directions are not concentrated relative to the back azimuth at the "
                 f"{100 * ALPHA:g} % level.")
    text += _correlation_text(column, correlations, n)
    return text, answer


def _correlation_text(column, correlations, n):
    """The circular correlations of one column type's falls, and which reference leads."""
    text = ""
    c = correlations[correlations["column"] == column] if not correlations.empty else None
    if c is not None and not c.empty:
        parts = []
        for _, r in c.iterrows():
            value = csv_number(r["circcorr"])
            if math.isfinite(value):
                parts.append(f"{REFERENCE_NAMES.get(r['reference'], r['reference'])} "
                             f"{value:+.2f}")
        finite = c[np.isfinite(c["circcorr"].astype(float))]
        if parts:
            text += " Circular correlation of the downfall azimuths with the " + ", ".join(
                parts)
        else:
            text += (" Circular correlations need at least 3 falls and varying reference "
                     "directions: not defined here")
        if not finite.empty:
            strength = finite["circcorr"].astype(float).abs().sort_values(ascending=False)
            best = finite.loc[strength.index[0]]
            error = 1.0 / math.sqrt(n)         # standard error of a correlation of n falls
            if len(strength) > 1 and strength.iloc[0] - strength.iloc[1] < error:
                text += (f"; no reference stands out: the largest |r| "
                         f"({abs(float(best['circcorr'])):.2f}, "
                         f"{REFERENCE_NAMES.get(best['reference'])}) exceeds the next by "
                         f"less than the standard error 1/sqrt({n}) = {error:.2f}, so "
                         "another CPU's single runs may rank them otherwise")
            else:
                text += (f"; strongest with the {REFERENCE_NAMES.get(best['reference'])} "
                         f"(|r| = {abs(float(best['circcorr'])):.2f}, standard error "
                         f"{error:.2f})")
        text += "."
    return text


def _paper_answer(fractions, tested, answers):
    """The answer to the paper's question over both column types."""
    out = []
    question = ("**Answer to the paper's question** (do toppled columns point to the "
                "source?): ")
    if not tested:
        if not fractions.empty:
            out.append(question + f"not yet: fewer than {MIN_FALLS} falls with a back azimuth "
                       "per column type.")
    elif answers:
        text = (question + "the fall directions depend on the back azimuth for the "
                + "; for the ".join(f"{COLUMN_NAMES.get(c, c).lower()} ({a})"
                                    for c, a, _ in answers) + ".")
        if any(across for _, _, across in answers):
            text += (" Falls transverse to the line to the epicentre would mislead a reading "
                     "that takes them to point toward or away from the source.")
        untested = [c for c in tested if c not in {a[0] for a in answers}]
        if untested:
            text += (" No preferred direction for the "
                     + " and the ".join(COLUMN_NAMES.get(c, c).lower() for c in untested) + ".")
        text += (" Even then, one fall tells little unless the resultant length R is close "
                 "to 1.")
        out.append(text)
    else:
        out.append(question + "no. " + ("Neither column type falls" if len(tested) > 1 else
                                        f"The {COLUMN_NAMES.get(tested[0], tested[0]).lower()} "
                                        "does not fall")
                   + " preferentially toward, away from or transverse to the epicentre in these "
                   "records, in line with the paper (little correlation between downfall "
                   "directions and back azimuth).")
    return out


def records_section(results):
    runs = _read_csv(results / "records" / "runs.csv")
    if runs is None:
        return "## Measured records\n\nNot run yet (`python -m pipeline campaign records`).\n"
    runs = runs.copy()
    runs["toppled"] = csv_true_column(runs["toppled"].astype(str))
    n_records = runs["record_id"].nunique()
    comparable = with_back_azimuth(runs)
    fractions = toppled_fractions(runs)
    directions = back_azimuth_table(runs)
    correlations = correlation_table(runs)
    lines = [("## Measured records: do toppled columns point to the source? "
              "(h/d 6, mu_s 0.7, mu_k 0.6)\n"),
             (f"{n_records} records (`results/records/runs.csv`), "
              f"{comparable['record_id'].nunique()} of them with a back azimuth and compass "
              "horizontals; FEMA P695 pairs, records without coordinates and records whose "
              "horizontals are not compass azimuths are never compared with a back azimuth. "
              "Classes: toward = within 45 deg of the back azimuth, away = within 45 deg of "
              "its opposite, transverse otherwise.\n"),
             ("**One run per record: a sample.** Each record here is one trajectory of a "
              "chaotic system; another CPU's last bits move single falls and can turn a "
              "marginal column. The fractions below count records, not probabilities per "
              "record: those, with their Monte Carlo error, are in the Ensembles section.\n")]
    lines += [t + "\n" for t in records_statements(fractions, directions, correlations)]
    shown = fractions.copy()
    if not shown.empty:
        shown = pd.DataFrame({
            "column": shown["column"],
            "toppled": [f"{k}/{n}" for k, n in zip(shown["toppled"], shown["records"])],
            "fraction (95 % Wilson)": [f"{_percent(f)} ({_percent(lo)}-{_percent(hi)})"
                                       for f, lo, hi in zip(shown["fraction"], shown["ci_low"],
                                                            shown["ci_high"])],
            "paper": [f"{int(k)}/{int(n)}" if math.isfinite(csv_number(k)) else "-"
                      for k, n in zip(shown.get("paper_toppled", [math.nan] * len(shown)),
                                      shown.get("paper_records", [math.nan] * len(shown)))],
            "paper fraction (95 % Wilson)": [
                f"{_percent(f)} ({_percent(lo)}-{_percent(hi)})" if math.isfinite(csv_number(f))
                else "-" for f, lo, hi in zip(*(shown.get(c, [math.nan] * len(shown)) for c in (
                    "paper_fraction", "paper_ci_low", "paper_ci_high")))]})
    lines.append("Toppled records:\n\n" + _table(shown) + "\n")
    lines.append("Downfall minus back azimuth (deg; axial: the fall axis, 0 = along the line "
                 "to the epicentre, +-90 = transverse):\n\n" + _table(
                     directions.round(3) if not directions.empty else None) + "\n")
    lines.append("Downfall azimuths against the back azimuth and the directions of the largest "
                 "horizontal acceleration, velocity and displacement (same records; circcorr: "
                 "circular-circular correlation, axial_circcorr: of the doubled angles; per-"
                 "record rows in records/direction_statistics.csv):\n\n" + _table(
                     correlations.round(3) if not correlations.empty else None) + "\n")
    for column, g in runs.groupby("column"):
        fell = g[g["toppled"]]
        stood = g[~g["toppled"]]
        if len(fell) and len(stood) and {"pga_h", "pgv_pga_h"} <= set(g.columns):
            lines.append(f"- {column}: median PGA of toppling records {fell['pga_h'].median():.2f} "
                         f"m/s^2 vs {stood['pga_h'].median():.2f} for the others; median PGV/PGA "
                         f"{fell['pgv_pga_h'].median():.3f} vs {stood['pgv_pga_h'].median():.3f} s.")
    per_record = per_record_table(runs)
    lines.append("\nPer record (downfall azimuth in deg, or stands; class relative to the back "
                 "azimuth):\n\n" + (per_record.to_markdown(index=False, disable_numparse=True)
                                     if not per_record.empty else "(none)") + "\n")
    for fname, caption in (("rose.png", "rose diagrams"),
                           ("toppling_vs_parameters.png", "toppling vs PGA, PGV, PGD, PGV/PGA"),
                           ("downfall_vs_directions.png", "downfall vs directions")):
        lines.append(_figure(results, results / "records" / fname, caption))
    return "\n".join(lines)


def processing_section(results):
    """The processing checked against PEER's own records (results/records/peer_check.csv,
    written by ``records``): median and worst ratios, pulse-like records listed."""
    table = _read_csv(results / "records" / "peer_check.csv")
    if table is None or table.empty:
        return "## Processing against PEER's records\n\nNot run yet (`python -m pipeline records --all`).\n"
    lines = ["## Processing against PEER's records\n",
             "PEER's records are processed already: re-processed here (cut with the filter's "
             "transient, offsets fitted to the quiet samples, 0.1-25 Hz zero-phase band-pass "
             "within the record's usable band, baseline), their RotD50 PGA and PGV against "
             "PEER's record as given (`--processing none`) and, for NGA-West2, the "
             "flatfile's values (`results/records/peer_check.csv`).\n"]
    names = {"pga_ratio_given": "PGA / PEER's record", "pgv_ratio_given": "PGV / PEER's record",
             "pga_ratio_flatfile": "PGA / flatfile", "pgv_ratio_flatfile": "PGV / flatfile"}
    rows = []
    for label, stats in peer_check.summary(table).items():
        for key, st in stats.items():
            if key != "records":
                rows.append({"records": label.replace("_", "-"), "ratio": names[key],
                             "n": st["records"], "median": f"{st['median']:.3f}",
                             "worst": f"{st['worst']:.3f} ({st['worst_id']})"})
    lines.append(_table(pd.DataFrame(rows)))
    pulses = table[csv_true_column(table["pulse_like"])]
    if not pulses.empty:
        inside = int((abs(pulses["pgv_ratio_given"] - 1.0) <= 0.10).sum())
        lines.append(f"\nFEMA P695's pulse-like records: {inside} of {len(pulses)} keep their "
                     "PGV within 10 % of PEER's record; a record whose velocity lies partly "
                     "below its lowest usable frequency loses that part.\n")
    return "\n".join(lines) + "\n"


def synthetic_section(results):
    table = _read_csv(results / "synthetic" / "direction_table.csv")
    if table is None:
        return "## Synthetic sources\n\nNot run yet (`python -m pipeline campaign synthetic`).\n"
    location = _read_csv(results / "synthetic" / "source_location.csv")
    lines = ["## Synthetic ground motions around two sources\n",
             "Downfall azimuth minus back azimuth (toward: within 45 deg of the epicentre "
             "direction; away: within 45 deg of the opposite; transverse otherwise):\n",
             _table(table) + "\n",
             "**Can the source be located from the fall directions?** Grid search for the point "
             "whose directions (axial) best explain the falls:\n", _table(location) + "\n"]
    for path in sorted((results / "synthetic").glob("map_*.png")):
        lines.append(_figure(results, path, path.stem))
    gmm = _read_csv(results / "synthetics" / "gmm_check.csv")
    if gmm is not None:
        lines.append("\nSynthetics against a ground-motion model (ratio to the median):\n\n" +
                     _table(gmm) + "\n")
    return "\n".join(lines)
