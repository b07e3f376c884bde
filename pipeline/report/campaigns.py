"""Report sections of the campaigns: verification, sweeps, ensembles, fragility, real
columns, the shake-table check, speed."""
import json
import math
import re
from pathlib import Path

import pandas as pd

from pipeline.hazard.fragility_file import read_fragility_file
from pipeline.motion import RECORD_CLOCK
from pipeline.report.common import _figure, _fmt, _p, _read_csv, _spread, _table


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
                 "model dissipated more at impacts (pipeline.rocking.impact_friction_demand).\n")
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
    return "\n".join(lines)


def contact_stiffness_section(results):
    """The contact stiffness alone at x1, x3, x10 (make contact-convergence): the rock on
    its tests, Housner free rocking of a block and a column, the twin model's ensembles."""
    path = Path(results) / "contact-convergence" / "convergence.json"
    title = "## Contact stiffness\n"
    if not path.exists():
        return title + "\nNot run yet (`make contact-convergence`).\n"
    conv = json.loads(path.read_text())
    lines = [title, "What the contact work changed: a mesh specimen's contact spheres near "
             "its base now start touching the table, none inside it (one started loaded and "
             "threw the rock at a stiff contact); released starts for free rocking and the "
             "contact file are new inputs.  The contact law and a column's rims are as "
             "before, so the column model's checks against rocking theory (the Verification "
             "section: Housner free rocking, one-sine pulses, rocking and sliding) are those "
             "of the same model.\n",
             "The contact springs' stiffness kn is a numerical parameter: each part "
             "below runs at kn x1, x3 and x10 with the physical parameters fixed (damping "
             "ratio, friction, geometry); the time step follows the stiffness "
             "(dt proportional to 1 / sqrt(kn)).\n"]
    if "factors" in conv:
        lines += _stiffness_rock_tests(conv)
    for body, table in conv.get("free_rocking", {}).items():
        lines += _stiffness_free_rocking(body, table)
    if conv.get("twin"):
        lines += _stiffness_twin(conv["twin"])
    if conv.get("rock_restitution"):
        lines += _stiffness_rock_restitution(conv["rock_restitution"])
    return "\n".join(lines)


def _stiffness_cost(row, wall="wall_s_per_run"):
    """A factor's time step and wall time, as table cells."""
    return {"time step (s)": f"{row['time_step_s']:.3g}" if row.get("time_step_s")
            else "-",
            "wall per run (s)": _fmt(row.get(wall), 1),
            "wall vs x1": "-" if row.get("wall_vs_x1") is None
            else f"{row['wall_vs_x1']:.2f}"}


def _stiffness_rock_tests(conv):
    """The rock SP1 on its fixed shake-table tests at each factor (lines)."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)", "tests": r["n"],
             "accuracy [95 %]": f"{r['accuracy']:.2f} [{r['accuracy_95'][0]:.2f}, "
             f"{r['accuracy_95'][1]:.2f}]",
             "predicted overturned (observed)": f"{r['predicted_overturned']} "
             f"({r['observed_overturned']})", "as at x1": r["same_as_x1"],
             **_stiffness_cost(r)} for k, r in conv["factors"].items()]
    fixed = re.sub(r"[,;]?\s*kn=[^,;]*", "", conv["grid_point"]).strip(",; ")
    return [f"The rock SP1 on {len(conv['tests'])} fixed shake-table tests (`{fixed}`):\n",
            _text_table(rows) + "\n"]


def _stiffness_free_rocking(body, table):
    """Housner free rocking of one body at each factor, and at other damping ratios."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)",
             "restitution per impact": " ".join(f"{e:.4f}" for e in
                                                r["restitution_per_impact"]),
             "max diff. from x1": _fmt(r["max_abs_restitution_minus_x1"], 4),
             "impact times vs Housner": f"{100 * r['max_rel_error_impact_times_housner']:.1f} %",
             "impact times vs x1 (ms)": _fmt(1e3 * r["max_abs_impact_time_minus_x1_s"], 1),
             **_stiffness_cost(r, "wall_s")} for k, r in table["factors"].items()]
    size = f"{table['height_m']:g} m x {table['width_m']:.3g} m"
    lines = [f"Housner free rocking of {table.get('body', body)} ({table['shape']}, "
             f"{size}, released at "
             f"{table['theta0_ratio']:g} alpha, damping ratio "
             f"{table['contact']['damping']:g}); Housner's restitution "
             f"{table['housner_restitution']:.4f}:\n", _text_table(rows) + "\n"]
    other = [{"damping ratio": f"{entry['damping']:g}",
              **{f"restitution {k}": f"{r['restitution']:.4f}"
                 for k, r in entry["factors"].items()},
              "largest diff. of an impact's from x1": _fmt(max(
                  r["max_abs_restitution_minus_x1"] or 0.0
                  for r in entry["factors"].values()), 4)}
             for entry in table.get("at_damping", [])]
    if other:
        lines += ["The same body at other damping ratios (restitution, mean over the "
                  "impacts):\n", _text_table(other) + "\n"]
    return lines


def _stiffness_twin(twin):
    """The twin model's ensembles at each factor (lines)."""
    rows = []
    for k, r in twin["factors"].items():
        for column, c in r["columns"].items():
            ci = c["p_toppled_ci95"]
            rows.append({"kn": k, "column": column, "members": c["members"],
                         "P(toppled) [95 %]": f"{c['p_toppled']:.2f} [{ci[0]:.2f}, "
                         f"{ci[1]:.2f}]",
                         "mean downfall (deg), R": "-" if c["mean_downfall_azimuth_deg"]
                         is None else f"{c['mean_downfall_azimuth_deg']:.0f}, "
                         f"{c['resultant_length']:.2f}",
                         "outcome as at x1": f"{c['same_outcome_as_x1']}/"
                         f"{c['paired_with_x1']}",
                         "P vs x1 (McNemar p)": _fmt(c.get("p_value_vs_x1"), 2),
                         "median turn vs x1 (deg)": _fmt(c["median_turn_vs_x1_deg"]),
                         **_stiffness_cost(r)})
    return [f"The twin model's ensembles on {twin['record']} (the same sampled members "
            "at every factor):\n", _text_table(rows) + "\n"]


def _stiffness_rock_restitution(rock):
    """The rock's free-rocking restitution at each factor and damping ratio (lines)."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)", "damping ratio": f"{rock['damping']:g}",
             "restitution": f"{r['restitution']:.4f}"} for k, r in rock["factors"].items()]
    rows += [{"kn": "x1", "damping ratio": f"{r['damping']:g}",
              "restitution": f"{r['restitution']:.4f}"} for r in rock["by_damping"]]
    return [f"The rock {rock['specimen']} rocking freely in the same model (footprint "
            f"tolerance {rock['footprint_tolerance_m']:g} m, released toward "
            f"{rock['azimuth_deg']:g} deg; median over three releases): the rocking "
            "restitution a damping ratio stands for.  Housner's restitution for a "
            f"block of its critical angle that way ({rock['critical_angle_along_deg']:.1f} "
            f"deg) is {rock['housner_block_restitution']:.4f}.\n", _text_table(rows) + "\n"]


def _text_table(rows):
    """A Markdown table of rows whose cells are written as given (0.9450 keeps its 0)."""
    return pd.DataFrame(rows).to_markdown(index=False, disable_numparse=True)


def fragility_section(results):
    """Lognormal fragility medians per column model and intensity measure (campaign
    fragility), when it has run."""
    path = results / "fragility" / "fragility.json"
    if not path.exists():
        return ("## Fragility\n\nNot run yet (`python -m pipeline campaign fragility`: "
                "P(toppled) against PGA, PGV and PGV/PGA from scaled records, beside a 2D "
                "rigid block).\n")
    summary = read_fragility_file(path)
    if summary.pulse_grid is not None:
        return rock_fragility_section(results, "fragility")
    rows = []
    for name, entry in summary.columns.items():
        row = {"model": name if entry.description is None else entry.description,
               "runs (toppled)": f"{entry.runs} ({entry.toppled})"}
        for im, fit in entry.fits.items():
            lo_hi = fit.get("median_ci95") or [None, None]
            row[f"{im} median [95 %] {fit.get('unit', '')}".strip()] = (
                "-" if fit["median"] is None else
                f"{fit['median']:.3g} [{_fmt(lo_hi[0], 2)}, {_fmt(lo_hi[1], 2)}], "
                f"beta {_fmt(fit.get('beta'), 2)}")
        rows.append(row)
    lines = ["## Fragility (campaign fragility)\n",
             f"Records {', '.join(map(str, summary.records))}; "
             f"{summary.members} members per record and level; lognormal "
             "maximum-likelihood fits P(toppled | IM) = Phi(ln(IM / median) / beta).\n",
             _table(pd.DataFrame(rows)) + "\n"]
    for fig in ("fragility_curves.png", "fragility_2d_vs_3d.png", "fragility_surface.png"):
        lines.append(_figure(results, results / "fragility" / fig, fig[:-4].replace("_", " ")))
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


MAX_ROSES = 6     # an ensemble section shows the roses of this many records at most


def ensemble_section(results):
    """Ensemble table: probabilities of toppling and of the fall direction per record."""
    base = results / "ensemble"
    if not base.exists():               # run-all's ensembles: those of the paper's question
        base = results / PAPER_QUESTION_DIR
    many, one = base / "ensemble_summaries.json", base / "ensemble_summary.json"
    if many.exists():
        summaries = json.loads(many.read_text())
    elif one.exists():
        summaries = [json.loads(one.read_text())]
    else:
        return ("## Ensembles\n\nNot run yet (`python -m pipeline campaign ensemble "
                "--record ID`).\n")
    rows = []
    for summary in summaries:
        for col in summary["columns"]:
            ci = col["p_toppled_ci95"]
            az_ci = col["mean_azimuth_ci95_deg"]
            rows.append({
                "record": summary["record"], "column": col["column"],
                "members": col["members"],
                "P(toppled) [95 %]": f"{col['p_toppled']:.2f} [{ci[0]:.2f}, {ci[1]:.2f}]",
                "mean downfall (deg) [95 %]": "-" if col["mean_downfall_azimuth_deg"] is None
                else f"{col['mean_downfall_azimuth_deg']:.0f}"
                + ("" if not az_ci else f" [{az_ci[0]:.0f}, {az_ci[1]:.0f}]"),
                "R": _fmt(col["resultant_length"], 2),
                "toward/away/transverse": "-" if col["fraction_toward"] is None else
                f"{col['fraction_toward']:.2f}/{col['fraction_away']:.2f}/"
                f"{col['fraction_transverse']:.2f}",
                "nominal run": "stands" if not col["nominal_toppled"] else
                f"{col['nominal_downfall_azimuth_deg']:.0f} deg",
                "back azimuth": _fmt(summary["back_azimuth_deg"])})
    seed = summaries[0]["seed"]
    lines = ["## Ensembles: probabilities instead of single runs\n",
             f"Members sample static friction, contact damping and stiffness, column "
             f"height and diameter tolerances, an out-of-plumb tilt, drum offsets and the "
             f"rim's angular phase (Latin hypercube, seed {seed}); P(toppled) with its Wilson 95 % interval, the mean downfall "
             "azimuth of the toppled members with a bootstrap 95 % interval (clockwise from "
             "the first to the second value), its resultant length R (1: all members fall "
             "the same way) and the fractions toward / away from / across the epicentre. "
             "Where the nominal run and the ensemble disagree, the single run was a "
             "coin toss.\n", _table(pd.DataFrame(rows)) + "\n"]
    if len(summaries) > MAX_ROSES:
        lines.append(f"Roses of the fall directions per record: `{base.relative_to(results)}/"
                     "<record>/rose.png`.\n")
        return "\n".join(lines)
    for summary in summaries:
        sub = base if len(summaries) == 1 else base / summary["record"]
        lines.append(_figure(results, sub / "rose.png", f"ensemble {summary['record']}"))
    return "\n".join(lines)


PAPER_QUESTION_DIR = "paper-question"     # make paper-question / run-all's reduced size
POOLED_NAMES = {"p_toppled": "P(toppled) per record", "fraction_toward": "toward (0.25)",
                "fraction_away": "away (0.25)", "fraction_transverse": "transverse (0.5)",
                "polarity": "polarity (0)", "radial_alignment": "radial alignment (0)"}


def paper_question_section(results):
    """The paper's question from ensembles over the near-source records (the ensemble
    campaign in results/paper-question): pooled numbers with intervals over records and
    members, the Monte Carlo error of each, the answer per column and the figure."""
    base = Path(results) / PAPER_QUESTION_DIR
    title = "## The paper's question from ensembles\n"
    path = base / "pooled_summary.json"
    if not path.exists():
        return (title + "\nNot run yet (`make run-all` at a reduced size, `make paper-question` "
                "at full precision).\n")
    pooled = json.loads(path.read_text())
    sizes = sorted(set(pooled["members_per_record"].values()))
    summaries = base / "ensemble_summaries.json"
    sizing = [s.get("sizing") for s in json.loads(summaries.read_text())] \
        if summaries.exists() else []
    capped = sum(1 for s in sizing if s and s.get("stopped_by") == "member cap")
    precision = next((s["precision"] for s in sizing if s), None)
    fixed = bool(sizing) and all(s and s["max_members"] == s["batch"] for s in sizing)
    size = (f"{sizes[0]}" if len(sizes) == 1 else f"{sizes[0]}-{sizes[-1]}")
    plural = "" if size == "1" else "s"
    if fixed:
        how = ("; a fixed ensemble, run-all's reduced size (`make paper-question` sizes every "
               "record's ensemble by its error)")
    elif precision is not None:
        how = (f"; members were added until P(toppled)'s 95 % interval was within "
               f"+-{precision:g} ({capped} of {len(sizing)} records stopped by the member "
               "cap instead)")
    else:
        how = ""
    lines = [title, f"{pooled['question']}  {pooled['records']} near-source records with a back "
             f"azimuth, {size} member{plural} per record (plus the nominal run, left out)"
             + how + ".  Every record weighs alike; the 95 % intervals are a "
             "two-stage bootstrap (records drawn again, then their members), so they hold both "
             "the choice of records and the ensembles' Monte Carlo error (MC error: the "
             "bootstrap's standard deviation).  In brackets: the value of falls that ignore "
             "the epicentre.\n"]
    rows = []
    for col in pooled["columns"]:
        row = {"column": col["column"], "falls (records)": f"{col['falls']} "
               f"({col['records_with_falls']})"}
        for name, label in POOLED_NAMES.items():
            st = col["statistics"][name]
            row[label] = "-" if st["ci95"] is None else (
                f"{st['estimate']:.2f} [{st['ci95'][0]:.2f}, {st['ci95'][1]:.2f}] "
                f"+-{st['mc_error']:.2f}")
        rows.append(row)
    lines.append(_table(pd.DataFrame(rows)) + "\n")
    for col in pooled["columns"]:
        lines.append(f"- **{col['column']}**: {col['answer']}.")
    cost = pooled.get("cost")
    if cost:
        lines.append(f"\nCost: {cost['runs']} YADE runs (the nominal runs among them), "
                     f"{cost['yade_wall_s_total'] / 3600:.1f} process-hours (the runs' wall "
                     "times summed; on N parallel YADE processes the campaign takes about "
                     "1/N of that).")
    lines.append("\nSingle runs per record (campaign records, below) are samples of these "
                 "distributions.\n")
    lines.append(_figure(results, base / "pooled.png", "the paper's question from ensembles"))
    return "\n".join(lines)


def convergence_section(results):
    """The model's convergence judged on distributions (make convergence)."""
    path = Path(results) / "convergence" / "convergence.json"
    title = "## Convergence on distributions\n"
    if not path.exists():
        return title + "\nNot run yet (`make convergence`).\n"
    conv = json.loads(path.read_text())
    rows = []
    for r in conv["rows"]:
        ci = r["p_toppled_ci95"]
        rows.append({"record": r["record"], "column": r["column"], "setting": r["variant"],
                     "members": r["members"],
                     "P(toppled) [95 %]": f"{r['p_toppled']:.2f} [{ci[0]:.2f}, {ci[1]:.2f}]",
                     "mean downfall (deg), R": "-" if r["mean_downfall_azimuth_deg"] is None
                     else f"{r['mean_downfall_azimuth_deg']:.0f}, {r['resultant_length']:.2f}",
                     "Fisher p": _p(r.get("fisher_p")), "Kuiper p": _p(r.get("kuiper_p"))})
    cost = conv.get("cost_vs_default") or {}
    lines = [title, "The twin model's ensembles (independent Latin-hypercube samples per "
             "setting) at the default numerics (16 rim points, time step factor 0.3 or the "
             "stability limit at the member's damping) and at 32 and 64 rim points and time "
             "step factor 0.15; each setting against the defaults: Fisher's exact test on "
             "P(toppled), Kuiper's two-sample test on the fall directions, Holm's correction "
             f"over all {conv['comparisons']} comparisons at {conv['alpha']:g}.\n",
             f"**{conv['verdict']}.**  " + _untested(conv.get("p_toppled_untested"))
             + "Cost per member relative to the defaults: "
             + ", ".join(f"{k} {v:.2f}x" for k, v in cost.items()) + ".\n",
             _table(pd.DataFrame(rows)) + "\n",
             _figure(results, Path(results) / "convergence" / "convergence.png",
                     "convergence on distributions")]
    return "\n".join(lines)


def _untested(pairs):
    """The sentence on records and columns whose P(toppled) no setting put to the test."""
    if not pairs:
        return ""
    return (f"P(toppled) is not tested for {', '.join(pairs)}: every member of every "
            "setting fell there (or none did), so Fisher's test cannot tell settings "
            "apart; only the fall directions are compared.  ")


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
            "error), fragility (4 levels, one member; `campaign fragility`: 8 x 4) and the "
            "inversion (the quick grid; `make invert-demo`, `make invert-study`).  Runs "
            "finished earlier are reused, so a second run-all costs far less.\n\n"
            + _table(frame[["step", "wall (min)", "exit"]]) + "\n")


ROCK_FRAGILITY = {
    "rock-fragility": ("Scanned rock fragility (pulse grid)",
                       "SP1's P(overturn) over the pulse grid vsr, from directions sampled "
                       "over 360 deg"),
    "rock-fragility-table": ("Scanned rock fragility along the table",
                             "SP1's P(overturn) over pulses in the range of its shake-table "
                             "tests, along the table's axis, against the tests")}


def rock_fragility_section(results, name="rock-fragility"):
    """A specimen's fragility over the pulse grid (campaign fragility --pulses; ``make
    rock-fragility`` writes results/rock-fragility and results/rock-fragility-table):
    contours, logistic surface, the 2D block and the check against experiments, when it
    has run."""
    heading, what = ROCK_FRAGILITY.get(name, (f"Fragility over a pulse grid ({name})", ""))
    path = results / name / "fragility.json"
    summary = read_fragility_file(path) if path.exists() else None
    section = None if summary is None else summary.pulse_grid
    if section is None:
        return f"## {heading}\n\nNot run yet (`make rock-fragility`: {what}).\n"
    block = section.block2d
    lines = [f"## {heading}\n",
             f"{summary.specimen}: one-cosine displacement pulses over PGA "
             f"{min(section.pga_g):g}-{max(section.pga_g):g} g x PGV/PGA "
             f"{min(section.pgv_pga_s):g}-{max(section.pgv_pga_s):g} s "
             f"({len(section.pga_g)} x {len(section.pgv_pga_s)} cells); "
             f"{section.members} parameter sets drawn from `{section.ranges}` x "
             f"{section.headings} direction(s); direction: {section.direction}. "
             f"{section.runs_finished} of {section.runs} runs finished. The 2D rigid "
             f"block (the toolkit's Housner integrator) has the specimen's critical angle "
             f"({math.degrees(block.alpha_rad):.1f} deg, median over the runs) and pivot "
             f"distance ({block.R_m:.3f} m).\n",
             "PGA (g) where P(overturn) crosses each level, per PGV/PGA (linear between "
             "cells; in brackets where the Wilson 95 % bounds cross it, the Monte Carlo "
             "band; - beyond the grid):\n"]
    rows = []
    for model, entry in section.models.items():
        for level, contour in entry.contours.items():
            row = {"model": model, "P": level}
            for r in contour:
                lo, hi = r["pga_g_band"]
                row[f"PGV/PGA {r['pgv_pga_s']:g} s"] = (
                    f"{_fmt(r['pga_g'], 2)} [{_fmt(lo, 2)}, {_fmt(hi, 2)}]")
            rows.append(row)
    lines.append(_table(pd.DataFrame(rows)) + "\n")
    lines += [f"Warning: {w}.\n" for w in section.warnings]
    for model, entry in section.models.items():
        per_set = [r for r in entry.contours.get("0.5", []) if r.get("pga_g_per_set")]
        shown = [f"{r['pgv_pga_s']:g} s: " + ", ".join(_fmt(v, 2) for v in
                                                      r["pga_g_per_set"].values())
                 for r in per_set]
        if shown:
            lines.append(f"P = 0.5 of each parameter set ({model}; the members' spread): "
                         + "; ".join(shown) + ".\n")
    spread = [c["set_sd"] for e in section.models.values() for c in e.cells
              if c["set_sd"] is not None]
    if spread:
        lines.append(f"Spread of P across the parameter sets (sd per cell): up to "
                     f"{max(spread):.2f}, mean {sum(spread) / len(spread):.2f}.\n")
    for model, entry in section.models.items():
        d = (entry.logistic or {}).get("dimensionless")
        if d:
            lines.append(f"Logistic surface ({model}): logit P = {d['c0']:.2f} + "
                         f"{d['b1']:.2f} ln(PGA / (g tan alpha)) + {d['b2']:.2f} ln(p PGV/PGA)"
                         + (" (Firth-penalised: separable outcomes)"
                            if entry.logistic.get("separated") else "") + ".\n")
    check = section.experiments
    if check:
        def score_row(label, score):
            return {"prediction": label,
                    "log-likelihood per test": _fmt(score["log_likelihood_per_test"], 3),
                    "Brier": _fmt(score["brier"], 3), "tests": score["n"]}

        rows = [score_row(label, s) for label, s in check["baselines"].items()]
        for model, result in check["models"].items():
            rows.append(score_row(f"{model}: pulse fragility (grid; {result['grid']['outside_grid']}"
                                  " tests outside it, nearest edge)", result["grid"]))
            if "logistic" in result:
                rows.append(score_row(f"{model}: its logistic surface", result["logistic"]))
        lines.append(f"Against the {check['tests']} shake-table tests ({check['overturned']} "
                     f"overturned; {check['note']}):\n")
        lines.append(_table(pd.DataFrame(rows)) + "\n")
    lines.append(_figure(results, results / name / "fragility_pulse_grid.png",
                         "P(overturn) over the pulse grid, contours, 2D block, observed rates"))
    return "\n".join(lines)
