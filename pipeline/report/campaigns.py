"""Report sections of the campaigns: verification, sweeps, real columns, the shake-table
check, speed and what run-all cost (wall times in s and min).  Ensembles:
:mod:`pipeline.report.ensembles`; contact stiffness:
:mod:`pipeline.report.contact_stiffness`; fragility: :mod:`pipeline.report.fragility`."""
import json
from pathlib import Path

import pandas as pd

from pipeline.motion import RECORD_CLOCK
from pipeline.report.common import _figure, _fmt, _read_csv, _spread, _table


def sweep_section(results, name, parameter, paper_notes):
    runs = _read_csv(results / name / "runs.csv")
    if runs is None:
        return f"## {name.capitalize()}\n\nNot run yet (`python -m pipeline campaign {name}`).\n"
    lines = [f"## {name.capitalize()} sweep ({parameter})\n"]
    # a table written before runs.csv said its clock holds the processed motion's times
    clock = RECORD_CLOCK if "start_in_file_s" in runs else "s, processed motion's clock"
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
                     f"impact times ({clock})": (f"{fell['impact_time_s'].min():.1f}-"
                                                 f"{fell['impact_time_s'].max():.1f}")
                     if len(fell) else "-"})
    lines.append(_table(pd.DataFrame(rows)) + "\n")
    for record in sorted(runs["record_id"].unique()):
        lines.append(_figure(results, results / name / f"impact_map_{record}.png",
                             f"{name} {record}"))
    lines.append(f"\n**Paper:** {paper_notes}\n")
    return "\n".join(lines)


# ---------------------------------------------------------------- records campaign


def verification_section(results):
    path = results / "verification" / "verification.json"
    if not path.exists():
        return "## Verification\n\nNot run yet (`python -m pipeline campaign verification`).\n"
    summary = json.loads(path.read_text())
    lines = ["## Verification against rocking theory\n"] + [f"- {x}" for x in summary["lines"]]
    lines.append("\nThe paper reports sliding from mu_s ~ 0.3 for this block; rigid-block theory "
                 "(Augusti & Sinopoli, eq. 8) and this model put the onset near 0.15: the paper's "
                 "model dissipated more at impacts "
                 "(pipeline.rocking.housner.impact_friction_demand).\n")
    for fig, caption in (("fig4_housner.png", "Fig. 4"), ("fig5_sine_pulse.png", "Fig. 5"),
                         ("fig6_sliding.png", "Fig. 6"),
                         ("fig_one_cosine.png", "One-cosine pulse against Makris & Roussos "
                          "(2000)")):
        lines.append(_figure(results, results / "verification" / fig, caption))
    return "\n".join(lines)


def columns_section(results):
    """Real columns on the same records (campaign columns), when it has run."""
    path = results / "columns" / "columns.md"
    if not path.exists():
        return ("## Real columns\n\nNot run yet (`python -m pipeline campaign columns`: the "
                "shipped column descriptions, each with a monolith of its outline, on the "
                "same records).\n")
    text = path.read_text().split("\n", 1)[1]          # below the file's own title
    return "## Real columns on the same records (campaign columns)\n" + text


def shake_table_section(results):
    """The specimen against the shake-table experiments (campaign shake-table)."""
    path = results / "shake-table" / "shake_table.json"
    title = "## Checked against experiments: the granite rock SP1 on a shake table\n"
    if not path.exists():
        return title + "\nNot run yet (`make shake-table`).\n"
    summary = json.loads(path.read_text())
    lines = [title, "Campaign shake-table: one YADE run per test of the scanned rock SP1 "
             "(Chen et al. 2024; records/shake_table). Parameters chosen on the tests before "
             f"{summary['validate_from']} among `{summary['grid']}`; the later tests are "
             "held out for validation. SP2's outcomes are not used.\n"]
    rows = []
    for split, s in summary["splits"].items():
        for name, key in (("YADE model", "model"), ("never overturns", "never_overturns"),
                          (f"PGA >= {summary['pga_threshold_g']:.2f} g", "pga_threshold")):
            sc = s[key]
            if not sc["n"]:
                continue
            rows.append({"tests": split, "predictor": name, "n": sc["n"],
                         "accuracy": _fmt(sc["accuracy"], 3),
                         "precision": _fmt(sc["precision"], 3),
                         "recall": _fmt(sc["recall"], 3), "F1": _fmt(sc["f1"], 3)})
    lines.append(pd.DataFrame(rows).to_markdown(index=False, disable_numparse=True) + "\n")
    lines += [f"- {x}" for x in summary["lines"]]
    calibration = [{"parameters": label, "n": sc["n"], "accuracy": _fmt(sc["accuracy"], 3),
                    "precision": _fmt(sc["precision"], 3), "recall": _fmt(sc["recall"], 3)}
                   for label, sc in summary.get("calibration_scores", {}).items()]
    if calibration:
        lines.append("\nEvery parameter set on the calibration tests (the validation tests "
                     "ran the chosen one only):\n")
        lines.append(pd.DataFrame(calibration).to_markdown(index=False,
                                                          disable_numparse=True) + "\n")
    lines.append("")
    lines.append(_figure(results, results / "shake-table" / "shake_table_rates.png",
                         "Observed and predicted overturning rate per PGA x PGV/PGA bin"))
    lines.append(_figure(results, results / "shake-table" / "shake_table_motion.png",
                         "What the shipped 200 Hz table motions lose against the 800 Hz "
                         "records, per test"))
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


def run_all_steps(path):
    """The steps of the last `make run-all` (``run-all-steps.tsv``, written by the
    Makefile: step, wall_s, exit) with their wall minutes; None before the first."""
    path = Path(path)
    if not path.exists() or path.stat().st_size <= 1:
        return None
    frame = pd.read_csv(path, sep="\t")
    frame["wall (min)"] = (frame["wall_s"] / 60).round(1)
    return frame


def run_all_section(results):
    """What the last `make run-all` cost: its steps' wall times, including what was
    reduced to fit."""
    path = Path(results) / "run-all-steps.tsv"
    frame = run_all_steps(path)
    if frame is None:
        return ""
    total = float(frame["wall_s"].sum())
    return ("## What this run-all cost\n\n"
            f"Wall time of the last `make run-all`'s steps on this machine (from "
            f"`{path.relative_to(results)}`): {total / 60:.1f} min in all, the venv and the "
            "report not counted.  Reduced in size: the paper's question (one member per "
            "record beside the nominal run; `make paper-question` sizes every record by its "
            "error), fragility (4 levels, one member; `campaign fragility`: 8 x 4), the "
            "colonnade (three records, one run each; `campaign ensemble --column-file` "
            "gives probabilities) and the "
            "inversion (the quick grid; `make invert-demo`, `make invert-study`).  Runs "
            "finished earlier are reused, so a second run-all costs far less.\n\n"
            + _table(frame[["step", "wall (min)", "exit"]]) + "\n")
