"""Report sections of the ensembles: probabilities per record (campaign ensemble), the
paper's question pooled over records, and the model's convergence judged on
distributions (azimuths in deg clockwise from North)."""
import json
from pathlib import Path

import pandas as pd

from pipeline.report.common import _figure, _fmt, _p, _table


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
