"""The ``shake-table`` campaign: a specimen against laboratory experiments.

Each test with a motion (the experiment table and the parameter grid:
:mod:`pipeline.campaign.shake_table_experiments`; a test without a motion counts in the
observed rates only) is one YADE run of the specimen (``--column-file``: a column
description or a mesh specimen) standing alone on the table.

Calibration keeps the validation tests out: the tests dated before ``--validate-from``
choose among the parameter sets of ``--grid`` (the best accuracy; ties: the first), and
only the chosen set runs on the validation tests.  Scores (accuracy, precision, recall,
F1, confusion) are reported per split beside the trivial baselines ("never overturns";
"overturns when PGA >= g tan(critical angle)").  Outputs in the campaign directory:
``experiments.csv`` (per test and parameter set), ``shake_table.json`` (scores), the
figure ``shake_table_rates.png`` (observed and predicted rate per PGA x PGV/PGA bin) and,
for tests with ``table_motion_800hz.csv`` beside their table, ``shake_table_motion.png``
(what the 200 Hz motions lose against the 800 Hz records).

With ``--members N`` the campaign runs in its members mode instead
(:mod:`pipeline.campaign.shake_table_members`, which enters itself in :data:`MODES`):
every test with the fragility's members, scored as probabilities.
"""
from dataclasses import dataclass
import logging
import math
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign import Campaign, register
from pipeline.campaign.run_dirs import finished_runs
from pipeline.campaign.options import (CampaignOptions, column_file_param, contact_file_param,
                                       contact_of)
from pipeline.scenario.contact_file import contact_values
from pipeline.scenario.parameters import param
from pipeline.files import InputError, write_csv, write_json
from pipeline.stats.classification import scores
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.campaign.shake_table_experiments import (AXIS_DEG, DEFAULT_GRID, EXPERIMENTS,
                                                       GRID_CONTACT, GRID_MOTION,
                                                       GRID_SPECIMEN, OUTCOME, PGA_EDGES_G,
                                                       PGV_PGA_EDGES_S, SPECIMEN,
                                                       VALIDATE_FROM, grid_run_params,
                                                       load_experiments, parse_grid)
from pipeline.campaign.shake_table_folds import DEFAULT_FOLDS, date_folds
from pipeline.campaign.shake_table_motion import (TABLE_MOTION, load_table_motion,
                                                  shared_tests, write_table_motion_figure)
from pipeline.campaign.tags import ShakeTableTags

log = logging.getLogger(__name__)

RUN_CPU_S = 1.6                  # CPU-s per run: 2,303 runs of SP1 took 62 CPU-min (2026-11-24)
# other modes of the campaign, by name: a module with check(options), specs, outputs and
# drive (the members mode enters itself: it draws its members with the pulse grid's
# sampler, which imports this module)
MODES = {}

def _label(point):
    return ", ".join(f"{k}={v:g}" for k, v in point.items()) or "defaults"

def specs(records, campaign_dir, experiments=EXPERIMENTS, specimen=SPECIMEN, outcome=OUTCOME,
          validate_from=VALIDATE_FROM, grid=DEFAULT_GRID, stage="calibration", chosen=None,
          tests=None, axis_deg=AXIS_DEG, contact_file=None, members=None, seed=None,
          ranges=None, only_runs=None, full=None):
    """Run specs of one stage: every grid point on the calibration tests, or the chosen
    point on the validation tests; a contact file's values are the base the points
    override.  Stage "members": the members mode's (``members``, ``seed``, ``ranges``,
    ``only_runs`` of ``full``)."""
    if stage == "members":
        return MODES["members"].specs(records, campaign_dir, experiments, specimen, outcome,
                                      validate_from, grid, tests, contact_file, members,
                                      seed, ranges, only_runs, full)
    if records:
        raise InputError("the shake-table campaign takes its motions from --experiments, "
                         "not --records")
    frame = load_experiments(experiments, outcome)
    frame = frame[[p is not None for p in frame["motion_path"]]]
    if tests:
        frame = frame[frame["test"].isin(tests)]
    split = date.fromisoformat(validate_from)
    frame = frame[(frame["day"] < split) if stage == "calibration" else (frame["day"] >= split)]
    description = ColumnGeometry.load(specimen).to_dict()
    base = None if contact_file is None else contact_values(contact_file)
    points = parse_grid(grid) if stage == "calibration" else [chosen or {}]
    runs, meta = [], []
    for point in points:
        params = grid_run_params(description, point, base)
        for row in frame.itertuples():
            runs.append((str(row.motion_path), params))
            meta.append(ShakeTableTags(row.test, bool(row.observed), stage, _label(point),
                                       point))
    return column_specs(runs, campaign_dir, meta)

def outputs(specs_, campaign_dir, failures, animations, figures=True):
    """Per-run table of this stage and its scores per grid point."""
    if specs_ and specs_[0].tags.stage == "members":
        return MODES["members"].outputs(specs_, campaign_dir, failures, animations, figures)
    campaign_dir = Path(campaign_dir)
    rows = []
    for spec, summary in finished_runs(campaign_dir, specs_):
        column = summary.columns[0]
        rows.append({"test": spec.tags.test, "stage": spec.tags.stage,
                     "grid_point": spec.tags.grid_point, "observed": spec.tags.observed,
                     "predicted": column.toppled, "max_tilt_deg": column.max_tilt_deg,
                     "run_id": spec.run_id})
    table = pd.DataFrame(rows)
    per_point = {}
    if len(table):
        stage = specs_[0].tags.stage
        write_csv(campaign_dir / f"{stage}.csv", table)
        for label, group in table.groupby("grid_point", sort=False):
            per_point[label] = scores(group["observed"], group["predicted"])
    points = {spec.tags.grid_point: spec.tags.point for spec in specs_}
    return {"scores": per_point, "points": points, "runs_done": len(rows)}

def best_point(result):
    """The grid point of the best calibration accuracy (ties: the first)."""
    ranked = [(s["accuracy"] if s["accuracy"] is not None else -1, -k, label)
              for k, (label, s) in enumerate(result["scores"].items())]
    if not ranked:
        raise InputError("no calibration run finished")
    _, _, label = max(ranked)
    return label, result["points"][label]

def drive(run, records, campaign_dir, options, gate=None):
    """Calibrate on the tests before ``validate_from``, validate the chosen parameters on
    the others (none: the calibration's scores alone), write experiments.csv,
    shake_table.json and the rates figure.  ``gate(what, runs, run_core_s, advice)``: the
    long-run gate (:func:`pipeline.files.check_long`), asked before any run.  With
    ``members``: the members mode's driver instead."""
    if options.get("members") is not None:
        return MODES["members"].drive(run, records, campaign_dir, options, gate)
    campaign_dir = Path(campaign_dir)
    frame = load_experiments(options["experiments"], options["outcome"])
    motion_rows = _table_motion(Path(options["experiments"]), frame)   # checked before any run
    if options.get("tests"):
        frame = frame[frame["test"].isin(options["tests"])]
    simulated = frame[[p is not None for p in frame["motion_path"]]]
    early = int((simulated["day"] < date.fromisoformat(options["validate_from"])).sum())
    late = len(simulated) - early
    if not early:
        raise InputError(f"no test with a motion before --validate-from "
                         f"{options['validate_from']} ({len(simulated)} with a motion in "
                         "all): nothing to calibrate on")
    points = len(parse_grid(options["grid"]))
    runs = points * early + late
    log.info(f"shake-table: {points} parameter set(s) x {early} calibration tests, then the "
             f"chosen set on {late} validation tests: at most {runs} YADE runs, about "
             f"{runs * RUN_CPU_S / 60:.0f} CPU-min (finished runs are kept and not run again)")
    if gate is not None:
        gate("shake-table", runs, RUN_CPU_S, "a smaller --grid or --tests")
    calibration = run({**options, "stage": "calibration"})
    label, point = best_point(calibration)
    log.info(f"calibration: best {label} (accuracy {calibration['scores'][label]['accuracy']:.3f} "
             f"on {calibration['scores'][label]['n']} tests)")
    if late:
        validation = run({**options, "stage": "validation", "chosen": point})
    else:
        log.info(f"no test from {options['validate_from']} on: the calibration's scores alone, "
                 "no validation")
        validation = calibration
    specimen = ColumnGeometry.load(options["specimen"])
    table = _experiment_table(frame, campaign_dir, label, options["validate_from"])
    write_csv(campaign_dir / "experiments.csv", table.drop(columns=["day", "motion_path"]))
    result = summarise(table, specimen, calibration, label, point, options)
    write_json(campaign_dir / "shake_table.json", result)
    from pipeline.figures.shake_table import plot_rates  # lazy: matplotlib, not imported by a run or after Ctrl-C
    plot_rates(table, campaign_dir / "shake_table_rates.png", result, PGA_EDGES_G,
               PGV_PGA_EDGES_S)
    if motion_rows is not None:
        write_table_motion_figure(motion_rows, frame, campaign_dir / "shake_table_motion.png")
    for line in result["lines"]:
        log.info(line)
    return {**validation, "summary": result}


def _table_motion(experiments, frame):
    """The table of what the 200 Hz motions lose (:mod:`pipeline.campaign.shake_table_motion`)
    when it lies beside the experiment table (the shipped tests have one; its tests must be
    of ``frame``, the experiments), else None."""
    path = experiments.parent / TABLE_MOTION.name
    if not path.is_file():
        log.info(f"no {TABLE_MOTION.name} beside {experiments.name}: no shake_table_motion.png")
        return None
    rows = load_table_motion(path)
    shared_tests(rows, frame)
    return rows


def _experiment_table(frame, campaign_dir, label, validate_from):
    """The experiment table with split and the chosen parameters' prediction (None where
    not simulated)."""
    predicted = {}
    for stage in ("calibration", "validation"):
        path = Path(campaign_dir) / f"{stage}.csv"
        if path.exists():
            runs = pd.read_csv(path)
            runs = runs[runs["grid_point"] == label]
            predicted.update(dict(zip(runs["test"].astype(str), runs["predicted"])))
    out = frame.copy()
    out["split"] = np.where(out["day"] < date.fromisoformat(validate_from), "calibration",
                            "validation")
    out["predicted"] = [predicted.get(t) for t in out["test"]]
    return out

def summarise(table, specimen, calibration, label, point, options):
    """Scores per split for the model and the baselines, the calibration table, lines."""
    axis = options.get("axis_deg", AXIS_DEG)
    critical = specimen.critical_angle_along_deg(axis)
    threshold_g = math.tan(math.radians(critical))
    splits = {}
    for split in ("calibration", "validation", "all"):
        rows = table if split == "all" else table[table["split"] == split]
        run = rows.loc[[p is not None for p in rows["predicted"]]]
        obs = run["observed"].to_numpy(bool)
        splits[split] = {
            "model": scores(obs, run["predicted"].astype(bool)),
            "never_overturns": scores(obs, np.zeros(len(run), bool)),
            "pga_threshold": scores(obs, run["pga_g"].to_numpy() >= threshold_g),
            "tests_with_motion": len(run), "tests": len(rows)}
    lines = [f"specimen {specimen.name}: critical angle {critical:.1f} deg along the "
             f"table's axis ({axis:g} deg) "
             f"(PGA threshold baseline {threshold_g:.3f} g); parameters {label}"]
    for split, s in splits.items():
        m = s["model"]
        if not m["n"]:
            continue
        lines.append(f"{split:>11} ({m['n']} tests): accuracy {m['accuracy']:.3f} "
                     f"[{m['accuracy_95'][0]:.2f}, {m['accuracy_95'][1]:.2f}], precision "
                     f"{_f(m['precision'])}, recall {_f(m['recall'])}, F1 {_f(m['f1'])}; "
                     f"baselines: never {s['never_overturns']['accuracy']:.3f}, PGA >= "
                     f"{threshold_g:.2f} g {s['pga_threshold']['accuracy']:.3f}")
    return {"specimen": specimen.to_dict(), "critical_angle_deg": critical, "axis_deg": axis,
            "pga_threshold_g": threshold_g, "validate_from": options["validate_from"],
            "grid": options["grid"], "contact_file": options.get("contact_file"),
            "chosen": {"label": label, "parameters": point},
            "calibration_scores": calibration["scores"], "splits": splits, "lines": lines}

def _f(value):
    return "n/a" if value is None else f"{value:.3f}"

@dataclass(frozen=True)
class ShakeTableOptions(CampaignOptions):
    experiments: Path = param(EXPERIMENTS, "", "experiment table (the default: the SP1 "
                              "granite tests shipped)",
                              flag="--experiments", metavar="CSV")
    outcome: str = param(OUTCOME, "", "column of the observed outcome, 1 = overturned",
                         flag="--outcome", metavar="COLUMN")
    column_file: str = column_file_param(
        "the specimen: a mesh specimen or column description (the default: the scanned "
        "rock SP1)", default=SPECIMEN)
    validate_from: str = param(VALIDATE_FROM, "", "tests from this date on are held out for "
                               "validation; the earlier ones calibrate",
                               flag="--validate-from", metavar="YYYY-MM-DD")
    grid: str = param(DEFAULT_GRID, "", "parameter sets the calibration chooses from "
                      "(Cartesian product; names: "
                      f"{', '.join([*GRID_CONTACT, *GRID_SPECIMEN, *GRID_MOTION])})",
                      flag="--grid", metavar="NAME=V,V;NAME=V")
    axis_deg: float = param(AXIS_DEG, "deg", "azimuth of the table's shaking line, for the "
                            "PGA-threshold baseline's critical angle (90: East-West)",
                            0.0, 360.0, flag="--axis-deg", metavar="DEG")
    tests: str = param(None, "", "only these tests (a quick look)",
                       flag="--tests", metavar="TEST,TEST", optional="all")
    contact_file: str = contact_file_param(
        "its values are the base every --grid point starts from: a point's own values "
        "override them")
    members: int = param(None, "", "members mode: run every test with this many members "
                         "drawn as campaign fragility --column-file draws them (--ranges, "
                         "--seed), each test's P with its Monte Carlo error, scored as "
                         "probabilities; a test's members stop early once its first ones "
                         "agree", 1, 1000, flag="--members",
                         optional="the calibration grid (no members mode)")
    seed: int = param(None, "", "members mode: Latin-hypercube seed of the members",
                      flag="--seed", optional="the fragility's")
    ranges: str = param(None, "", "members mode: ranges the members are drawn from (LO = "
                        "HI fixes one)", flag="--ranges", metavar="NAME=LO:HI;...",
                        optional="the fragility's")
    candidates: str = param(None, "", "members mode: candidate ranges separated by '|' "
                            "('default': the fragility's), each run on the calibration tests "
                            "and scored by log-likelihood over --folds blocks of test days; "
                            "the best is frozen, then run and scored on every test",
                            flag="--candidates",
                            metavar="RANGES|RANGES", optional="no choice of ranges")
    folds: int = param(DEFAULT_FOLDS, "", "members mode with --candidates: the calibration "
                       "tests' days cut into this many blocks of consecutive days; chosen: "
                       "the candidate whose worst block scores best, checked on each block "
                       "by the choice made without it (1: the score over all calibration "
                       "tests, no check)", 1, 10, flag="--folds")
    providers: Path = param(None, "", "members mode: other models' 0/1 predictions scored "
                            "beside the members (CSV: test and one column per model)",
                            flag="--providers", metavar="CSV",
                            optional="for the shipped tests, the providers' models of SP1 "
                            "(records/shake_table/sp1_numerical.csv)")
    TAKES_JOBS = True
    DRIVER_ONLY = ("candidates", "folds", "providers", "jobs")

    def check(self):
        contact_of(self)
        if self.members is None:
            given = [f for f, v in (("--seed", self.seed), ("--ranges", self.ranges),
                                    ("--candidates", self.candidates),
                                    ("--providers", self.providers)) if v is not None]
            if given:
                raise InputError(f"{given[0]} belongs to the members mode: add --members N")
        else:
            MODES["members"].check(self)
        try:
            date.fromisoformat(self.validate_from)
        except (TypeError, ValueError):
            raise InputError(f"--validate-from {self.validate_from!r}: expected "
                             "yyyy-mm-dd") from None
        if self.axis_deg >= 360.0:
            raise InputError(f"--axis-deg must be in [0, 360), got {self.axis_deg:g}")
        parse_grid(self.grid)
        frame = load_experiments(self.experiments, self.outcome)
        tests = self.test_names()
        if self.tests is not None and not tests:
            raise InputError(f"--tests {self.tests!r} names no test: give TEST,TEST, or leave "
                             "it out for all tests")
        repeated = sorted({t for t in tests if tests.count(t) > 1})
        if repeated:
            raise InputError(f"--tests names {repeated[0]} twice: a test is run and counted "
                             "once")
        unknown = [t for t in tests if t not in set(frame["test"])]
        if unknown:
            raise InputError(f"--tests: unknown test(s) {', '.join(unknown)} (not in "
                             f"{Path(self.experiments).name})")
        if self.members is not None and self.candidates is not None:
            run = MODES["members"].tests_of(self.experiments, self.outcome, tests or None,
                                            self.validate_from)
            if not (run["split"] == "calibration").any():
                raise InputError(f"--candidates: no test before --validate-from "
                                 f"{self.validate_from} to choose the ranges on")
            date_folds(run.loc[run["split"] == "calibration", "day"], self.folds)

    def test_names(self):
        """The tests of ``--tests`` (an empty list: all)."""
        return [t.strip() for t in (self.tests or "").split(",") if t.strip()]

    def kwargs(self):
        return {"experiments": self.experiments, "outcome": self.outcome,
                "specimen": self.column_file,
                "validate_from": self.validate_from, "grid": self.grid,
                "tests": self.test_names() or None, "axis_deg": self.axis_deg,
                "contact_file": self.contact_file, "members": self.members,
                "seed": self.seed, "ranges": self.ranges, "candidates": self.candidates,
                "folds": self.folds, "providers": self.providers}


def _worker(spec, run_dir):
    run_column_spec(spec, run_dir)

register(Campaign(
    "shake-table", "a specimen (default the scanned granite rock SP1) against shake-table "
    "experiments: calibrate on the early tests, validate on the held-out later ones",
    specs, _worker, outputs, label="experiments", options=ShakeTableOptions, driver=drive,
    run_core_s=RUN_CPU_S))
