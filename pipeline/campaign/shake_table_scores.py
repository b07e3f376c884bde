"""Scores of the shake-table members mode (:mod:`pipeline.campaign.shake_table_members`):
each test's P from its members, per split (calibration: before ``--validate-from``;
validation: the held-out tests from it on; all), beside the single parameter set and the
baselines, every one scored as a probability forecast the same way
(:func:`pipeline.stats.forecast.forecast_scores`: a 0/1 forecast is P = 0 or 1).
Files: ``members.csv``, ``shake_table_members.json``, ``shake_table_reliability.png``;
with the ranges chosen over folds, ``folds.csv`` and ``shake_table_folds_reliability.png``
(per fold, the reliability of the ranges chosen without it); where the members and the
laboratory disagree, ``disagreements.csv`` and ``shake_table_disagreements.png``
(:mod:`pipeline.campaign.shake_table_disagreements`)."""
import io
import logging
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign import shake_table_experiments
from pipeline.campaign.shake_table_disagreements import write_disagreements
from pipeline.campaign.shake_table_folds import fold_table
from pipeline.files import InputError, write_csv, write_json
from pipeline.records import RECORDS_DIR
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.stats.forecast import BIN_EDGES, forecast_scores
from pipeline.userfiles import DATA_FILE_BYTES, read_user_text

log = logging.getLogger(__name__)

PROVIDERS = RECORDS_DIR / "shake_table" / "sp1_numerical.csv"
SPLITS = ("calibration", "validation", "all")
CLIP_RULE = ("log-likelihood: P from n member runs held within 1/(2(n + 1)) of 0 and 1 "
             "(the Jeffreys-prior posterior mean when all n agree), a 0/1 forecast within "
             "0.01; Brier score on the raw P; bins of width 0.1 (the last closed at 1); "
             "predicted overturned when P > 0.5")


def load_providers(path):
    """Other models' 0/1 predictions: {model: {test: 0/1}}; one-line InputError for a
    table without ``test`` or a value not 0/1."""
    path = Path(path)
    try:
        frame = pd.read_csv(io.StringIO(read_user_text(path, "--providers", DATA_FILE_BYTES)),
                            dtype={"test": str})
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"--providers {path.name}: not a readable table "
                         f"({str(exc).splitlines()[0][:120]})") from None
    if "test" not in frame.columns or len(frame.columns) < 2:
        raise InputError(f"--providers {path.name}: needs a column test and one column of "
                         "0/1 predictions per model")
    out = {}
    for model in frame.columns.drop("test"):
        values = pd.to_numeric(frame[model], errors="coerce")
        if not values.isin([0, 1]).all():
            raise InputError(f"--providers {path.name}: column {model} must be 0 or 1")
        out[str(model)] = dict(zip(frame["test"], values.astype(int)))
    return out


def providers_of(options):
    """(path or None, predictions): ``--providers``, or for the shipped tests and outcome
    the providers' models of SP1."""
    path = options.get("providers")
    if path is None and Path(options["experiments"]).resolve() == \
            shake_table_experiments.EXPERIMENTS.resolve() and options["outcome"] == shake_table_experiments.OUTCOME:
        path = PROVIDERS
    return path, ({} if path is None else load_providers(path))


def split_scores(rows, threshold_g, providers):
    """Scores of one split's tests (``rows``: members.csv rows with a P); None for a split
    without tests (e.g. only held-out tests named with --tests)."""
    if rows.empty:
        return None
    y = rows["observed"].to_numpy(bool)
    out = {"tests": int(len(rows)), "member_runs": int(rows["runs"].sum()),
           "members": forecast_scores(y, rows["P"].to_numpy(float), rows["runs"].to_numpy())}
    single = rows[rows["single_set_predicted"].notna()]
    out["single_set"] = forecast_scores(single["observed"].to_numpy(bool),
                                        single["single_set_predicted"].to_numpy(float))
    out["never_overturns"] = forecast_scores(y, np.zeros(len(rows)))
    out["pga_threshold"] = forecast_scores(y, (rows["pga_g"].to_numpy(float)
                                               >= threshold_g).astype(float))
    out["providers"] = {}
    for model, predicted in providers.items():
        have = rows[rows["test"].isin(predicted)]
        out["providers"][model] = forecast_scores(
            have["observed"].to_numpy(bool),
            np.array([predicted[t] for t in have["test"]], float))
    return out


def write_scores(per_test, campaign_dir, options, full, settled, choice=None):
    """Write members.csv, shake_table_members.json and the reliability diagram; return
    the JSON's dict.  ``choice``: how the ranges were chosen on the calibration tests
    (:func:`pipeline.campaign.shake_table_folds.choose_ranges`), if they were; with
    folds, also folds.csv and shake_table_folds_reliability.png."""
    campaign_dir = Path(campaign_dir)
    specimen = ColumnGeometry.load(options["specimen"])
    axis = options.get("axis_deg", shake_table_experiments.AXIS_DEG)
    critical = specimen.critical_angle_along_deg(axis)
    threshold_g = math.tan(math.radians(critical))
    path, providers = providers_of(options)
    write_csv(campaign_dir / "members.csv", per_test)
    disagreements = write_disagreements(
        campaign_dir, f"{specimen.name}: where the members' majority (P > 0.5) and the "
        "laboratory disagree")
    scored = per_test[per_test["P"].notna()]
    splits = {split: split_scores(scored if split == "all" else
                                  scored[scored["split"] == split], threshold_g, providers)
              for split in SPLITS}
    splits = {split: scores for split, scores in splits.items() if scores is not None}
    member_specs = [s for s in full if s.tags.member >= 0]
    sets = sorted({s.tags.member: s.tags.point for s in member_specs}.items())
    result = {
        "specimen": specimen.name, "experiments": str(options["experiments"]),
        "outcome": options["outcome"], "validate_from": options["validate_from"],
        "members": options["members"], "seed": options.get("seed"),
        "ranges": options.get("ranges"), "parameter_sets": [p for _, p in sets],
        "single_set": next(s.tags.point for s in full if s.tags.member < 0),
        "providers": None if path is None else str(path),
        "pga_threshold_g": threshold_g, "critical_angle_deg": critical, "axis_deg": axis,
        "runs": int(per_test["runs"].sum()) + int(per_test["single_set_predicted"].notna()
                                                   .sum()),
        "runs_at_most": len(full), "adaptive_settled": settled,
        "rules": CLIP_RULE, "bin_edges": [float(e) for e in BIN_EDGES],
        "ranges_choice": choice, "splits": splits,
        "disagreements": disagreements.to_json(),
        "lines": choice_lines(choice) + lines_of(splits) + list(disagreements.lines)}
    write_json(campaign_dir / "shake_table_members.json", result)
    from pipeline.figures.reliability import plot_reliability  # lazy: matplotlib, not imported by a run or after Ctrl-C
    plot_reliability({s: v["members"]["reliability_diagram"] for s, v in splits.items()},
                     campaign_dir / "shake_table_reliability.png",
                     f"{specimen.name}: {options['members']} members per test at most")
    if choice and choice.get("folds"):
        write_csv(campaign_dir / "folds.csv", fold_table(choice))
        plot_reliability({f"fold {f['fold']}: {' to '.join(f['days'] or [])}, "
                          f"{f['chosen_without'] or 'default'}": f["reliability"]
                          for f in choice["folds"]},
                         campaign_dir / "shake_table_folds_reliability.png",
                         f"{specimen.name}: each fold scores the ranges chosen without it")
    for line in result["lines"]:
        log.info(line)
    return result


def _line(name, s):
    if not s["n"]:
        return f"  {name}: no test"
    acc = s["balanced_accuracy"]
    return (f"  {name}: log-likelihood {s['log_likelihood_per_test']:.3f}/test, Brier "
            f"{s['brier']:.3f} (REL {s['reliability']:.3f}, RES {s['resolution']:.3f}, UNC "
            f"{s['uncertainty']:.3f}), accuracy {s['accuracy']:.3f}, balanced "
            f"{'n/a' if acc is None else f'{acc:.3f}'}")


def choice_lines(choice):
    """What the log says of the candidate ranges on the calibration tests and of the
    folds' out-of-sample check."""
    if not choice:
        return []
    out = ["candidate ranges on the calibration tests (chosen by the worst fold's "
           "log-likelihood):"]
    for c in choice["candidates"]:
        mark = "*" if c["ranges"] == (choice["chosen"] or None) else " "
        folds = ", ".join(f"{v:.3f}" for v in c.get("per_fold_log_likelihood", []))
        out.append(f" {mark}{c['ranges'] or 'default'}: log-likelihood "
                   f"{c['log_likelihood_per_test']:.3f}/test (per fold {folds}), Brier "
                   f"{c['brier']:.3f}, accuracy {c['accuracy']:.3f} ({c['tests']} tests, "
                   f"{c['member_runs']} member runs)")
    for f in choice.get("folds", []):
        held = f["held_out"]
        missed = [r["label"] for r in f["reliability"] if not r["covers"]]
        out.append(f"  fold {f['fold']} ({' to '.join(f['days'] or [])}, {held['tests']} "
                   f"tests), chosen without it {f['chosen_without'] or 'default'}: "
                   f"log-likelihood {held['log_likelihood_per_test']:.3f}/test, Brier "
                   f"{held['brier']:.3f}, accuracy {held['accuracy']:.3f}; bins outside "
                   f"their interval: {', '.join(missed) or 'none'}")
    cv = choice.get("cross_validated_log_likelihood_per_test")
    if cv is not None:
        out.append(f"  cross-validated log-likelihood of the choice: {cv:.3f}/test")
    return out


def lines_of(splits):
    """What the log says: per split the members, the single set and the baselines."""
    out = []
    for split, s in splits.items():
        out.append(f"{split} ({s['tests']} tests, {s['member_runs']} member runs):")
        out.append(_line("members", s["members"]))
        for name in ("single_set", "never_overturns", "pga_threshold"):
            out.append(_line(name.replace("_", " "), s[name]))
        for model, scores in s["providers"].items():
            out.append(_line(f"provider {model}", scores))
    return out
