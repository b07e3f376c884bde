"""REPORT section of the members mode of ``campaign shake-table``: each laboratory test
as a probability, scored as a forecast (``shake_table_members.json`` of ``make
shake-table-scores``, or of ``make shake-table-scores-quick`` / ``make run-all`` at a
reduced size)."""
import json

import pandas as pd

from pipeline.campaign.shake_table_disagreement_file import FILE, DisagreementTable
from pipeline.campaign.shake_table_disagreements import FIGURE, SLIDE_RATIO, UPLIFT_RATIO
from pipeline.campaign.shake_table_regions import DisagreementSummary
from pipeline.report.common import _figure, _table

FULL = "shake-table-scores"
QUICK = "shake-table-scores-quick"
SPLITS = (("validation", "held out"), ("calibration", "calibration"), ("all", "all"))
BASELINES = (("members", "members (P with its Monte Carlo error)"),
             ("single_set", "one parameter set (the calibration's choice)"),
             ("never_overturns", "never overturns"),
             ("pga_threshold", "overturns when PGA >= g tan(critical angle)"))
HELD_OUT_ACCURACY_GOAL = 0.90   # accuracy of P > 0.5 on the held-out tests the model aims at


def shake_table_scores_section(results, name=FULL):
    """The scores per split of the members, the single set, the baselines and the
    providers' best in-sample model, and the reliability diagram; says when not run."""
    path = results / name / "shake_table_members.json"
    quick = name == QUICK
    heading = "Shake-table tests as probabilities" + (" (reduced)" if quick else
                                                         " (full scoring)")
    command = "`make shake-table-scores-quick` (run by `make run-all`)" if quick \
        else "`make shake-table-scores`"
    lines = [f"## {heading}\n"]
    if not path.is_file():
        return "\n".join(lines + [f"Not run yet ({command}).\n"])
    summary = json.loads(path.read_text())
    lines.append(_intro(summary, quick))
    if summary.get("ranges_choice"):
        lines.append(_choice(summary["ranges_choice"]))
        lines.append(_figure(results, results / name / "shake_table_folds_reliability.png",
                             "Reliability per fold of test days: the ranges chosen without "
                             "the fold, scored on it (P = 0 and P = 1 bins apart)"))
    for split, label in SPLITS:
        part = summary.get("splits", {}).get(split)
        if part:
            lines.append(f"**{label.capitalize()}** ({part.get('tests', '?')} tests, "
                         f"{part.get('member_runs', '?')} member runs):\n")
            lines.append(_table(_score_rows(part)) + "\n")
    held_out = summary.get("splits", {}).get("validation")
    if held_out:
        lines.append(_verdict(held_out))
    lines.append(_figure(results, results / name / "shake_table_reliability.png",
                         "Reliability diagram: observed overturning rate against the "
                         "predicted P, per bin, with Wilson 95 % intervals"))
    lines.append(_disagreements(results, results / name))
    return "\n".join(lines)


def _disagreements(results, directory):
    """Where the members' majority and the laboratory disagree, from disagreements.csv:
    the summary's lines, the error rate per region and the figure; "" without the file."""
    if not (directory / FILE).is_file():
        return ""
    table = DisagreementTable.load(directory / FILE)
    summary = DisagreementSummary.of(table)
    rows = pd.DataFrame([{"region": f"{r.kind.label} {r.label}", "tests": r.wrong.of,
                          "wrong": r.wrong.count,
                          "error rate [Wilson 95 %]": f"{r.wrong.p:.2f} [{r.wrong.ci95[0]:.2f}, "
                                                      f"{r.wrong.ci95[1]:.2f}]",
                          "missed overturns": r.missed, "false overturns": r.false}
                         for r in summary.regions])
    return ("**Where the members and the laboratory disagree** (`" + FILE + "`: per test "
            "its region, the members' verdict and what decided their runs; a run uplifted "
            f"when theta_max/alpha reached {UPLIFT_RATIO:g}, slid when its residual base "
            f"slide reached {SLIDE_RATIO:g} of the base width, the damage states' first "
            "limits):\n\n"
            + "\n".join(f"- {line.strip()}" for line in summary.lines) + "\n\n"
            + _table(rows) + "\n\n"
            + _figure(results, directory / FIGURE, "Tests in the PGA x PGV/PGA plane, right "
                      "or wrong by kind (filled: calibration, open: held out), and the "
                      "error rate per region with its Wilson 95 % interval"))


def _intro(summary, quick):
    size = (f"A reduced run ({summary.get('runs', '?')} runs); the full scoring is `make "
            "shake-table-scores`: its numbers are the model's, these the method's. "
            if quick else f"{summary.get('runs', '?')} runs. ")
    return (f"The specimen {summary.get('specimen', '?')} on every named test with the "
            f"fragility's members (at most {summary.get('members', '?')} a test, stopped early "
            "when they agree), each test's P scored as a forecast against what the laboratory "
            f"saw; tests from {summary.get('validate_from', '?')} on are held out from the "
            f"calibration. {size}Log-likelihood per test (higher is better; {_rule(summary)}), "
            "Brier score (lower is better) = reliability - resolution + uncertainty, and the "
            "accuracy of P > 0.5. The providers' models are their own in-sample 0/1 "
            "predictions, the best of them by log-likelihood shown.\n")


def _choice(choice):
    """The candidate ranges as scored on the calibration tests, the chosen one marked;
    with folds, each fold's score of the choice made without it."""
    chosen = choice.get("chosen") or None
    rows = [{"members' ranges (over the defaults)": c.get("ranges") or "default",
             "chosen": "yes" if c.get("ranges") == chosen else "",
             "log-likelihood / test": f"{c['log_likelihood_per_test']:.3f}",
             "Brier": f"{c['brier']:.3f}", "accuracy": f"{c['accuracy']:.3f}",
             "tests": c.get("tests", "?"), "member runs": c.get("member_runs", "?"),
             **({"worst fold": f"{c['worst_fold_log_likelihood']:.3f}"}
                if "worst_fold_log_likelihood" in c else {})}
            for c in choice.get("candidates", [])]
    folds = choice.get("folds") or []
    if not folds:
        return ("The members' ranges were chosen before any held-out test was run: each "
                "candidate's members on the calibration tests alone, the highest "
                "log-likelihood per test chosen and frozen, then run on the held-out "
                "tests:\n\n" + _table(pd.DataFrame(rows)) + "\n")
    per_fold = [{"fold": f["fold"], "days": " to ".join(f.get("days") or []),
                 "chosen without it": f.get("chosen_without") or "default",
                 "tests": f["held_out"]["tests"],
                 "log-likelihood / test": f"{f['held_out']['log_likelihood_per_test']:.3f}",
                 "Brier": f"{f['held_out']['brier']:.3f}",
                 "accuracy": f"{f['held_out']['accuracy']:.3f}",
                 "bins whose interval misses P": ", ".join(
                     r["label"] for r in f["reliability"] if not r["covers"]) or "none"}
                for f in folds]
    cv = choice.get("cross_validated_log_likelihood_per_test")
    return (f"The members' ranges were chosen before any held-out test was run, out of "
            f"sample over the calibration tests' days ({len(folds)} blocks of consecutive "
            "test days): each candidate's members on the calibration tests alone, the "
            "candidate whose worst block scores best by log-likelihood chosen and frozen, "
            "then run on the held-out tests:\n\n" + _table(pd.DataFrame(rows))
            + "\n\nEach block scores the choice the same rule makes on the other blocks "
            "(cross-validated log-likelihood "
            + ("n/a" if cv is None else f"{cv:.3f}") + " per test; `folds.csv` and "
            "`shake_table_folds_reliability.png` give each block's reliability bins, P = 0 "
            "and P = 1 apart):\n\n" + _table(pd.DataFrame(per_fold)) + "\n")


def _rule(summary):
    rule = summary.get("rules", "")
    return rule.split(";")[0] if rule else "P held away from 0 and 1"


def _score_rows(part):
    rows = []
    for key, label in BASELINES:
        if key in part:
            rows.append(_row(label, part[key]))
    providers = part.get("providers") or {}
    if providers:
        best = max(providers, key=lambda k: providers[k]["log_likelihood_per_test"])
        rows.append(_row(f"providers' best in-sample model ({best})", providers[best]))
    return pd.DataFrame(rows)


def _row(label, scores):
    return {"forecast": label,
            "log-likelihood / test": f"{scores['log_likelihood_per_test']:.3f}",
            "Brier": f"{scores['brier']:.3f}",
            "reliability": f"{scores['reliability']:.3f}",
            "resolution": f"{scores['resolution']:.3f}",
            "accuracy": f"{scores['accuracy']:.3f}",
            "balanced accuracy": f"{scores['balanced_accuracy']:.3f}"}


def _verdict(part):
    """Whether the members beat the single set and the providers' models on the held-out
    tests (log-likelihood and Brier) and reach the accuracy goal."""
    members = part["members"]
    others = {"the single set": part.get("single_set")}
    others.update({f"the providers' {k}": v for k, v in (part.get("providers") or {}).items()})
    beaten = [n for n, s in others.items() if s is not None
              and members["log_likelihood_per_test"] > s["log_likelihood_per_test"]
              and members["brier"] < s["brier"]]
    compared = [n for n, s in others.items() if s is not None]
    reached = members["accuracy"] >= HELD_OUT_ACCURACY_GOAL
    return (f"On the held-out tests the members' log-likelihood and Brier score are both "
            f"better than those of {len(beaten)} of the {len(compared)} other forecasts"
            + (f" (not: {', '.join(n for n in compared if n not in beaten)})"
               if len(beaten) < len(compared) else "")
            + f"; the accuracy of P > 0.5 is {members['accuracy']:.3f}, "
            + ("at or above" if reached else "below")
            + f" the {HELD_OUT_ACCURACY_GOAL:.2f} the model aims at.\n")
