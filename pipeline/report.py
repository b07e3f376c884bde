"""Report stage: results/REPORT.md from the campaigns' tables and figures.

    python -m pipeline report

Sections for campaigns that have not run say so instead of inventing numbers.
"""
import datetime
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import RESULTS_DIR, __version__
from pipeline.files import write_text


def _read_csv(path):
    return pd.read_csv(path) if Path(path).exists() and Path(path).stat().st_size > 1 else None


def _fmt(value, digits=0):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}f}"


def _figure(results, path, caption):
    return f"![{caption}]({Path(path).relative_to(results)})\n" if Path(path).exists() else ""


def _spread(azimuths):
    """Axial spread (deg) of downfall azimuths: circular std of doubled angles, halved."""
    from pipeline.stats.circular import circular_summary
    values = np.asarray([a for a in azimuths if math.isfinite(a)])
    if len(values) < 2:
        return None
    return circular_summary(values, axial=True)["circular_std_deg"]


def _table(frame):
    return frame.to_markdown(index=False) if frame is not None and not frame.empty else "(none)"


def sweep_section(results, name, parameter, paper_notes):
    runs = _read_csv(results / name / "runs.csv")
    if runs is None:
        return f"## {name.capitalize()}\n\nNot run yet (`python -m pipeline campaign {name}`).\n"
    lines = [f"## {name.capitalize()} sweep ({parameter})\n"]
    rows = []
    for (record, column), g in runs.groupby(["record_id", "column"]):
        g = g.sort_values(parameter)
        fell = g[g["toppled"].astype(bool)]
        rows.append({"record": record, "column": column,
                     f"{parameter} toppled": ", ".join(f"{v:g}" for v in fell[parameter]) or "none",
                     f"{parameter} standing": ", ".join(
                         f"{v:g}" for v in g[~g["toppled"].astype(bool)][parameter]) or "none",
                     "downfall azimuths (deg)": ", ".join(
                         f"{a:.0f}" for a in fell["downfall_azimuth_deg"]) or "-",
                     "axial spread (deg)": _fmt(_spread(fell["downfall_azimuth_deg"])),
                     "impact times (s)": (f"{fell['impact_time_s'].min():.1f}-"
                                          f"{fell['impact_time_s'].max():.1f}") if len(fell) else "-"})
    lines.append(_table(pd.DataFrame(rows)) + "\n")
    for record in sorted(runs["record_id"].unique()):
        lines.append(_figure(results, results / name / f"impact_map_{record}.png",
                             f"{name} {record}"))
    lines.append(f"\n**Paper:** {paper_notes}\n")
    return "\n".join(lines)


def records_section(results):
    runs = _read_csv(results / "records" / "runs.csv")
    if runs is None:
        return "## All records\n\nNot run yet (`python -m pipeline campaign records`).\n"
    counts = runs.groupby("column")["toppled"].agg(lambda s: f"{int(s.astype(bool).sum())}/{len(s)}")
    lines = ["## All records (h/d 6, mu_s 0.7, mu_k 0.6)\n",
             "Toppled: " + ", ".join(f"{c} {v}" for c, v in counts.items()) +
             " (paper: 13 of 29 records toppled the drum column, 7 also the monolith).\n"]
    for column, g in runs.groupby("column"):
        fell = g[g["toppled"].astype(bool)]
        stood = g[~g["toppled"].astype(bool)]
        if len(fell) and len(stood):
            lines.append(f"- {column}: median PGA of toppling records {fell['pga_h'].median():.2f} "
                         f"m/s^2 vs {stood['pga_h'].median():.2f} for the others; median PGV/PGA "
                         f"{fell['pgv_pga_h'].median():.3f} vs {stood['pgv_pga_h'].median():.3f} s.")
    stats = _read_csv(results / "records" / "direction_statistics.csv")
    if stats is not None:
        keep = ["column", "reference", "n", "mean_difference_deg", "resultant_length",
                "rayleigh_p", "axial_mean_difference_deg", "axial_resultant_length",
                "axial_rayleigh_p", "circcorr", "axial_circcorr"]
        stats = stats[stats["record_id"] == "all"][[c for c in keep if c in stats.columns]]
        stats = stats.round(2)
    lines.append("\nDownfall directions of all toppled runs against back azimuth and the "
                 "directions of the largest motions (differences downfall - reference, deg; "
                 "per-record rows in records/direction_statistics.csv):\n\n" + _table(stats) + "\n")
    for fname, caption in (("rose.png", "rose diagrams"),
                           ("toppling_vs_parameters.png", "toppling vs PGA, PGV, PGD, PGV/PGA"),
                           ("downfall_vs_directions.png", "downfall vs directions")):
        lines.append(_figure(results, results / "records" / fname, caption))
    lines.append("\nOnly the Ridgecrest and Napa records have real back azimuths; the FEMA "
                 "near-field pairs are fault-normal/fault-parallel rotations of unknown polarity "
                 "(records/README.md), so their directions are not compass directions.\n")
    return "\n".join(lines)


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


def verification_section(results):
    path = results / "verification" / "verification.json"
    if not path.exists():
        return "## Verification\n\nNot run yet (`python -m pipeline campaign verification`).\n"
    summary = json.loads(path.read_text())
    lines = ["## Verification against rocking theory\n"] + [f"- {x}" for x in summary["lines"]]
    lines.append("\nThe paper reports sliding from mu_s ~ 0.3 for this block; rigid-block theory "
                 "(Augusti & Sinopoli, eq. 8) and this model put the onset near 0.15: the paper's "
                 "model dissipated more at impacts (pipeline.rocking.impact_friction_demand).\n")
    for fig, caption in (("fig4_housner.png", "Fig. 4"), ("fig5_sine_pulse.png", "Fig. 5"),
                         ("fig6_sliding.png", "Fig. 6")):
        lines.append(_figure(results, results / "verification" / fig, caption))
    return "\n".join(lines)


def speed_section(results):
    path = results / "bench" / "bench.json"
    if not path.exists():
        return "## Speed\n\nRun `make bench` for speed figures.\n"
    bench = json.loads(path.read_text())["speed"]
    rows = [{"scene": k, "us/step": _fmt(v["us_per_step"], 1), "x still": _fmt(v["cost_vs_still"], 2),
             "simulated s per wall s": _fmt(v["sim_s_per_wall_s"], 2)}
            for k, v in bench["scenes"].items()]
    return "## Speed (make bench)\n\n" + _table(pd.DataFrame(rows)) + "\n"


def build_report(results=RESULTS_DIR):
    results = Path(results)
    campaigns = {}
    for name in ("verification", "slenderness", "friction", "records", "synthetic"):
        meta = results / name / "campaign.json"
        if meta.exists():
            campaigns[name] = json.loads(meta.read_text())
    head = ["# Toppling columns: results report\n",
            f"Generated {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC by "
            f"toppling-columns {__version__}, after Hinzen (2009), BSSA 99(5).\n",
            "Campaigns: " + (", ".join(f"{n} ({c.get('runs', '?')} runs)"
                                       for n, c in campaigns.items()) or "none") + "\n"]
    body = [
        verification_section(results),
        sweep_section(results, "slenderness", "hd",
                      "GM20 toppled the drum column for h/d >= 3.5 and the monolith for "
                      "h/d >= 4.0; the drum column's downfall directions varied strongly with "
                      "h/d, the monolith's grouped NNE and SSE within 30 deg. The pulse record "
                      "(paper GM23) toppled both columns toward one direction (42 deg cone), "
                      "transverse to the back azimuth."),
        sweep_section(results, "friction", "mu_s",
                      "friction had a minor influence on downfall directions; with mu_s = 0.1 "
                      "neither column toppled (they slid instead)."),
        records_section(results), synthetic_section(results), speed_section(results)]
    text = "\n".join(head + body)
    write_text(results / "REPORT.md", text)
    return results / "REPORT.md"
