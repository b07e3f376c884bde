"""The members mode of ``campaign shake-table`` (``--members N``): every test run with the
fragility's members, each test's P with its Monte Carlo error, scored as probabilities.

The members are those of ``campaign fragility --column-file``: the same Latin hypercube
(:func:`pipeline.campaign.pulse_grid.sample_sets`) over the same ranges
(:func:`pipeline.campaign.pulse_grid.parse_ranges`: its defaults for a mesh specimen,
``--ranges`` over them; kn log-uniform; mu_k in the fragility's ratio to mu_s) and seed
(the fragility's default); a contact file fixes what it sets, as there.  The table's
motion is the test's own, along its axis as shipped (``rotate_deg`` 0), turned by a
member's yaw (the rock's orientation on the table, a drawn unknown).

Each test's members stop early by the pulse grid's adaptive rule
(:func:`pipeline.campaign.pulse_adaptive.adaptive_sampling`, every test a row of one cell
with no guide): first :data:`~pipeline.campaign.pulse_adaptive.ADAPTIVE_FIRST_RUNS`
members; a test whose Wilson 95 % interval then excludes 0.5 is decided and stops (the
first members all agree), one whose interval holds 0.5 doubles its members, up to N.

Beside the members, each test is run once with one parameter set (``--grid`` of one
point; by default the calibration's choice, :data:`SINGLE_SET`) and scored the same way,
with the baselines "never overturns", "PGA >= g tan(critical angle)" and other models'
0/1 predictions (``--providers``; for the shipped tests the providers' own numerical
models of SP1, fitted on these tests: in-sample).  Outputs (the campaign directory):
``members.csv`` (per test: runs, overturned, P, its Wilson interval, the single set's
prediction), ``shake_table_members.json`` (scores per split,
:func:`pipeline.stats.forecast.forecast_scores`), ``shake_table_reliability.png`` and
where the members and the laboratory disagree (``disagreements.csv``,
``shake_table_disagreements.png``).
"""
import logging
import sys
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign import ensemble_members, pulse_adaptive, pulse_grid, shake_table, \
    shake_table_experiments
from pipeline.campaign.column_file import column_kn
from pipeline.campaign.run_dirs import finished_runs, finished_summary
from pipeline.campaign.runs import column_specs
from pipeline.campaign.shake_table_folds import choose_ranges, date_folds
from pipeline.campaign.shake_table_scores import load_providers, write_scores
from pipeline.files import InputError, duration_text, write_csv
from pipeline.scenario.contact_file import contact_values
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.stats.ensemble import wilson_interval
from pipeline.campaign.tags import ShakeMemberTags

log = logging.getLogger(__name__)

# the single parameter set scored beside the members: the calibration's choice on the
# June-July tests (make shake-table; the parameters make contact-convergence varies kn at)
SINGLE_SET = "footprint_tolerance_m=0.001;damping=0.1;mu_s=0.7;rotate_deg=0"
MAX_CANDIDATES = 8
# a run at a stiffer contact takes longer: the time step goes as sqrt(m / kn)
KN_OF_RUN_CPU_S = 1.2e8


def check(options):
    """One-line refusals of the members mode's options, before any work."""
    ensemble_members.check_seed(options.seed)
    specimen = ColumnGeometry.load(options.column_file).to_dict()
    contact = None if options.contact_file is None else contact_values(options.contact_file)
    member_sets(specimen, options.members, options.seed, options.ranges, contact)
    if options.candidates is not None:
        if options.ranges is not None:
            raise InputError("--candidates and --ranges: give one (--candidates chooses the "
                             "ranges on the calibration tests)")
        for text in options.candidates.split("|"):
            text = "" if text.strip() == "default" else text
            try:
                member_sets(specimen, options.members, options.seed, text, contact)
            except InputError as exc:
                raise InputError(str(exc).replace("--ranges", "--candidates")) from None
        candidate_ranges(options.candidates, "mesh" in specimen)
    single_set(options.grid)
    if options.providers is not None:
        load_providers(options.providers)


def single_set(grid):
    """The one parameter set run beside the members: ``grid``'s one point
    (:data:`SINGLE_SET` for the campaign's default grid)."""
    text = SINGLE_SET if grid == shake_table_experiments.DEFAULT_GRID else grid
    points = shake_table_experiments.parse_grid(text)
    if len(points) != 1:
        raise InputError(f"--members: --grid names {len(points)} parameter sets; give one "
                         "(the single set scored beside the members) or leave it out")
    return points[0]


def member_sets(specimen, members, seed, ranges, contact=None):
    """(parameter sets, ranges drawn): the fragility's draws for this specimen."""
    mesh = "mesh" in specimen
    drawn = pulse_grid.drawn_ranges(ranges, mesh, contact)
    if members > 1 and all(lo == hi for lo, hi in drawn.values()):
        raise InputError(f"--members {members} with nothing drawn (give --ranges: a column "
                         "description draws nothing by default) would repeat one run")
    seed = ensemble_members.DEFAULT_SEED if seed is None else seed
    return pulse_grid.sample_sets(members, seed, drawn), drawn


def run_params(specimen, point, base):
    """Run parameters of one member (or the single set) on the table; a member's
    ``yaw_deg`` (the rock turned clockwise) turns the table motion by -yaw_deg."""
    point = dict(point)
    yaw = point.pop("yaw_deg", 0.0)
    if yaw != 0.0:
        point["rotate_deg"] = round((point.get("rotate_deg", 0.0) - yaw) % 360.0, 6) % 360.0
    params = shake_table_experiments.grid_run_params(specimen, point, base)
    if "kn" not in point and "kn" not in (base or {}) and "mesh" not in specimen:
        params["kn"] = column_kn(specimen)          # a description's matched kn, as there
    return params


def core_s(params):
    """Core seconds of one run: the campaign's, longer at a stiffer contact."""
    return shake_table.RUN_CPU_S * max(1.0, (params["kn"] / KN_OF_RUN_CPU_S) ** 0.5)


def _point_kn(specimen, point, base):
    """The contact stiffness (N/m) of one member's run, as :func:`run_params` sets it,
    without building its geometry."""
    kn = shake_table_experiments.grid_contact(point, base)["kn"]
    if "kn" not in point and "kn" not in (base or {}) and "mesh" not in specimen:
        kn = column_kn(specimen)
    return kn


def planned_runs(specimen, options, candidates, n_calibration, n_tests):
    """(at most how many YADE runs, their core seconds) of the members mode, counted from
    the options alone, no run spec built: each candidate's members on the calibration
    tests, then the chosen's on the others (the costliest candidate's), the single set on
    every test; without candidates, the members and the single set on every test."""
    base = None if options.get("contact_file") is None else \
        contact_values(options["contact_file"])

    def member_core_s(ranges):
        sets, _ = member_sets(specimen, options["members"], options.get("seed"), ranges, base)
        return [core_s({"kn": _point_kn(specimen, p, base)}) for p in sets]
    single = core_s({"kn": _point_kn(specimen, single_set(options["grid"]), base)})
    per = [member_core_s(c) for c in candidates] or [member_core_s(options.get("ranges"))]
    n_first = n_calibration if candidates else n_tests
    runs = sum(map(len, per)) * n_first + max(map(len, per)) * (n_tests - n_first) + n_tests
    core = (sum(map(sum, per)) * n_first + max(map(sum, per)) * (n_tests - n_first)
            + single * n_tests)
    return runs, core


def tests_of(experiments, outcome, tests, validate_from):
    """The tests with a motion (of ``tests``), with their split."""
    frame = shake_table_experiments.load_experiments(experiments, outcome)
    frame = frame[[p is not None for p in frame["motion_path"]]]
    if tests:
        frame = frame[frame["test"].isin(tests)]
    if frame.empty:
        raise InputError("--members: no test with a motion to run")
    frame = frame.copy()
    frame["split"] = np.where(frame["day"] < date.fromisoformat(validate_from),
                              "calibration", "validation")
    return frame


def specs(records, campaign_dir, experiments, specimen, outcome, validate_from, grid, tests,
          contact_file, members=None, seed=None, ranges=None, only_runs=None, full=None):
    """Every test x (N members and the single set); ``only_runs`` keeps those run ids (of
    ``full``, the specs made already)."""
    if full is None:
        if records:
            raise InputError("the shake-table campaign takes its motions from --experiments, "
                             "not --records")
        frame = tests_of(experiments, outcome, tests, validate_from)
        description = ColumnGeometry.load(specimen).to_dict()
        base = None if contact_file is None else contact_values(contact_file)
        sets, _ = member_sets(description, members, seed, ranges, base)
        points = [(m, p) for m, p in enumerate(sets)] + [(-1, single_set(grid))]
        runs, tags, costs = [], [], []
        for m, point in points:
            params = run_params(description, point, base)
            for row in frame.itertuples():
                runs.append((str(row.motion_path), params))
                tags.append(ShakeMemberTags(row.test, bool(row.observed), "members", m, point))
                costs.append(round(core_s(params), 3))
        full = column_specs(runs, campaign_dir, tags, core_s=costs)
    if only_runs is None:
        return full
    keep = set(only_runs)
    return [s for s in full if s.run_id in keep]


def outputs(specs_, campaign_dir, failures, animations, figures=True):
    """The finished runs of this stage (``members_runs.csv``); the scores are written by
    :func:`drive` once every stage has run."""
    rows = []
    for spec, summary in finished_runs(Path(campaign_dir), specs_):
        rows.append({"test": spec.tags.test, "member": spec.tags.member,
                     "observed": spec.tags.observed,
                     "predicted": summary.columns[0].toppled,
                     "max_tilt_deg": summary.columns[0].max_tilt_deg,
                     "run_id": spec.run_id})
    if rows:
        write_csv(Path(campaign_dir) / "members_runs.csv", pd.DataFrame(rows))
    return {"runs_done": len(rows)}


def drive(run, records, campaign_dir, options, gate=None):
    """Say the cost and ask the gate, run the members test by test in the pulse grid's
    adaptive stages, then write members.csv, the scores and the reliability diagram.
    With ``candidates``: each candidate's members on the calibration tests first, the
    best chosen over ``folds`` blocks of test days
    (:func:`pipeline.campaign.shake_table_folds.choose_ranges`), then the chosen on every
    test."""
    specimen = ColumnGeometry.load(options["specimen"]).to_dict()
    candidates = candidate_ranges(options.get("candidates"), "mesh" in specimen)
    frame = tests_of(options["experiments"], options["outcome"], options.get("tests"),
                     options["validate_from"])
    calibration = list(frame.loc[frame["split"] == "calibration", "test"])
    days = frame.loc[frame["split"] == "calibration", ["test", "day"]]
    fold_of = (dict(zip(days["test"], date_folds(days["day"], options["folds"])))
               if candidates else None)
    passes = ([{**options, "ranges": c, "tests": calibration} for c in candidates]
              + [options] if candidates else [options])
    n, jobs = options["members"], max(options.get("jobs") or 1, 1)
    most, core = planned_runs(specimen, options, candidates, len(calibration), len(frame))
    what = (f"{len(candidates)} candidate ranges on {len(calibration)} calibration tests, "
            f"then the chosen on {len(frame)} tests" if candidates else f"{len(frame)} tests")
    log.info(f"shake-table (members): {what} x ({n} members + the single set): at most "
             f"{most} YADE runs, about {duration_text(core / jobs)} on {jobs} core(s) (a "
             f"test's members stop once its first {min(n, pulse_adaptive.ADAPTIVE_FIRST_RUNS)} "
             "agree; finished runs are kept and not run again)")
    if gate is not None:
        gate("campaign shake-table --members", most, core / most, "fewer --tests or --members")
    log.info(f"shake-table (members): preparing the runs of {len(frame)} tests "
             f"({len(passes)} set(s) of ranges; tens of seconds each)")
    fulls = [run_specs(records, campaign_dir, o) for o in passes]
    choice = None
    if candidates:
        tried = []
        for text, opts, full in zip(candidates, passes, fulls):
            log.info(f"shake-table (members): candidate ranges {text or 'default'} on the "
                     f"{len(calibration)} calibration tests")
            per_test, _ = _members(run, campaign_dir, opts, full,
                                   frame[frame["test"].isin(calibration)])
            tried.append((text, per_test))
        choice = choose_ranges(tried, fold_of)
        log.info(f"shake-table (members): chosen on the calibration tests: ranges "
                 f"{choice['chosen'] or 'default'}")
        if choice["chosen"]:
            log.warning(f"shake-table (members): the chosen ranges {choice['chosen']} are "
                        "not the declared defaults; campaign fragility draws them once "
                        "pipeline/campaign/member_ranges.py declares them")
        options = {**options, "ranges": choice["chosen"]}
        fulls[-1] = run_specs(records, campaign_dir, options)
    per_test, settled = _members(run, campaign_dir, options, fulls[-1], frame)
    return write_scores(per_test, campaign_dir, options, fulls[-1], settled, choice)


def _members(run, campaign_dir, options, full, frame):
    """Run ``full``'s members test by test in adaptive stages; (members.csv rows of
    ``frame``'s tests, whether every test settled)."""
    n = options["members"]
    by_test = {}
    for spec in full:
        by_test.setdefault(spec.tags.test, []).append(spec)
    order = {t: sorted([s for s in rows if s.tags.member >= 0],
                       key=lambda s: s.tags.member) for t, rows in by_test.items()}
    single = [s.run_id for rows in by_test.values() for s in rows if s.tags.member < 0]
    cells = {t: (i, 0) for i, t in enumerate(order)}
    guide = {cell: pulse_adaptive.ADAPTIVE_LEVEL for cell in cells.values()}    # no guide

    def run_stage(stage, targets):
        chosen = [s.run_id for t, rows in order.items() for s in rows[:targets[cells[t]]]]
        log.info(f"shake-table (members), stage {stage}: {len(chosen)} of "
                 f"{len(full) - len(single)} member runs")
        run({**options, "stage": "members", "only_runs": chosen + single, "full": full})
        return {cells[t]: [summary.columns[0].toppled for _, summary in
                           finished_runs(Path(campaign_dir), rows[:targets[cells[t]]])]
                for t, rows in order.items()}

    targets, settled = pulse_adaptive.adaptive_sampling(guide, n, run_stage)
    if not settled:
        log.warning(f"shake-table (members): stopped after {pulse_adaptive.MAX_STAGES} stages "
                    "with tests still undecided (their Wilson intervals say so)")
    return _per_test(frame, order, by_test, campaign_dir, targets, cells), settled


def candidate_ranges(text, mesh=True):
    """``--candidates``: the candidate ranges' texts ('' for the defaults), or [] for
    none; one-line InputError for fewer than two, more than MAX_CANDIDATES or a repeat."""
    if text is None:
        return []
    out = ["" if c.strip() in ("", "default") else c.strip() for c in text.split("|")]
    if not 2 <= len(out) <= MAX_CANDIDATES:
        raise InputError(f"--candidates: give 2 to {MAX_CANDIDATES} ranges separated by '|' "
                         f"('default' for the fragility's), got {len(out)}")
    drawn = [tuple(sorted(pulse_grid.parse_ranges(c, mesh).items())) for c in out]
    repeated = [c or "default" for k, c in enumerate(out) if drawn[k] in drawn[:k]]
    if repeated:
        raise InputError(f"--candidates: {repeated[0]!r} draws the same ranges as an earlier "
                         "candidate")
    return out


def run_specs(records, campaign_dir, options):
    """The full specs of the members mode (every member of every test, and the single
    set)."""
    keys = ("experiments", "specimen", "outcome", "validate_from", "grid", "tests",
            "contact_file")
    return specs(records, campaign_dir, *(options.get(k) for k in keys),
                 members=options["members"], seed=options.get("seed"),
                 ranges=options.get("ranges"))


def _per_test(frame, order, by_test, campaign_dir, targets, cells):
    """Per test: its member runs (those of its last stage), overturned, P and Wilson 95 %
    interval, and the single set's prediction."""
    rows = []
    for row in frame.itertuples():
        done = [summary.columns[0].toppled for _, summary in
                finished_runs(Path(campaign_dir), order[row.test][:targets[cells[row.test]]])]
        single = [finished_summary(Path(campaign_dir), s.run_id)
                  for s in by_test[row.test] if s.tags.member < 0][0]
        k, m = int(sum(done)), len(done)
        lo, hi = wilson_interval(k, m)
        rows.append({"test": row.test, "date": row.date, "split": row.split,
                     "pga_g": row.pga_g, "pgv_pga_s": row.pgv_pga_s,
                     "observed": bool(row.observed), "runs": m, "overturned": k,
                     "P": k / m if m else None, "ci95_low": lo, "ci95_high": hi,
                     "single_set_predicted": None if single is None
                     else bool(single.columns[0].toppled)})
    return pd.DataFrame(rows)


shake_table.MODES["members"] = sys.modules[__name__]
