"""Campaign stage: a registry of campaign definitions and one way to run them.

A :class:`Campaign` names its run specs (``specs(records)``), the worker that
performs one run and the outputs written from the finished runs.  Every
campaign, verification included, goes through :func:`run_campaign`: the
executor (:mod:`pipeline.campaign.executor`) runs what is not finished yet,
then the campaign writes its tables and figures.

A run spec is a :class:`~pipeline.campaign.spec.RunSpec` (its ``run_id`` the content hash
of its inputs and of the code that turns them into an outcome); a finished run leaves a
:class:`~pipeline.outcome.summary.RunSummary`.
"""
import importlib
import logging
import os
import pkgutil
import shutil
from importlib.metadata import entry_points
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from pipeline import RESULTS_DIR
from pipeline.files import (LONG_RUN_S, DirectoryLock, InputError, ToolError, check_jobs,
                            check_long, write_json)
from pipeline.campaign.executor import EXECUTORS, RUN_CORE_S, execute
from pipeline.campaign.run_dirs import count_finished
from pipeline.scenario.contact_file import contact_provenance
import json

log = logging.getLogger(__name__)

CAMPAIGNS = {}


@dataclass(frozen=True)
class Campaign:
    """name: command-line name; help: one line; specs(records, campaign_dir) -> run specs;
    worker(spec, run_dir) writes run_dir/summary.json; outputs(specs, campaign_dir,
    failures, animations, figures) writes tables (and figures unless ``figures`` is
    False, after Ctrl-C) and returns a dict for campaign.json; run_core_s: core seconds
    of one run, the long-run gate's estimate before any run."""
    name: str
    help: str
    specs: Callable
    worker: Callable
    outputs: Callable
    label: str = "runs"
    options: type = None           # its own options: a CampaignOptions dataclass
    driver: Callable = None        # driver(run, records, campaign_dir, options, gate):
    #                                runs it (several times: ensembles sized by their error)
    run_core_s: float = RUN_CORE_S
    estimate: Callable = None      # estimate(records, options) -> (runs, core-s a run) or
    #                                None: the gate's count from the options alone, asked
    #                                before any spec is built (a grid of hours takes minutes)


def register(campaign):
    """Add a campaign to the registry (one definition per module of definitions)."""
    CAMPAIGNS[campaign.name] = campaign
    return campaign


ENTRY_POINTS = "toppling_columns.campaigns"


def discover():
    """Import every module of this package (found with pkgutil, as readers and commands
    are) and the campaign modules of the stages above it, named as entry points
    ``toppling_columns.campaigns`` in pyproject.toml: each registers its definitions when
    imported."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    for entry in entry_points(group=ENTRY_POINTS):
        importlib.import_module(entry.value)


def get(name):
    discover()
    try:
        return CAMPAIGNS[name]
    except KeyError:
        raise InputError(f"unknown campaign {name!r} (known: {', '.join(CAMPAIGNS)})") from None


def names():
    discover()
    return list(CAMPAIGNS)


def run_campaign(name, jobs=None, records=None, campaign_dir=None, animations=1, options=None,
                 executor=None, scheduler=None, allow_long=None):
    """Run (or resume) a campaign and write its outputs; return the outputs dict.

    allow_long: False refuses (InputError, before any run) a campaign whose unfinished runs
    are estimated at over an hour on ``jobs`` cores (:func:`pipeline.files.check_long`;
    True runs it with a warning; None, for callers that asked the gate themselves, and on
    a Dask cluster of unknown size (no ``jobs``): no gate).

    executor: "threads" (default) or "dask" (a local Dask cluster, or the existing one
    at ``scheduler``, e.g. "tcp://10.0.0.5:8786"); see :mod:`pipeline.campaign.executor`.
    Ctrl-C stops within seconds: no new run starts, running YADE processes end,
    the tables of the finished runs are written, then KeyboardInterrupt propagates.
    """
    campaign = get(name)
    if executor is not None and executor not in EXECUTORS:
        raise InputError(f"--executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if scheduler and executor == "threads":
        raise InputError("--scheduler runs on a Dask cluster: drop --executor threads")
    if jobs is not None or not scheduler:   # on a cluster: as many as it has worker threads
        jobs = check_jobs(jobs)
    campaign_dir = Path(campaign_dir or RESULTS_DIR / name)
    if campaign_dir.exists() and not campaign_dir.is_dir():
        raise InputError(f"--out {campaign_dir} is a file, not a directory")
    existed = campaign_dir.exists()
    try:
        allowed = allow_long is not None and jobs is not None and _gate_from_options(
            campaign, records, options, campaign_dir, jobs, allow_long)
        driver_only = () if campaign.options is None else campaign.options.DRIVER_ONLY
        specs = campaign.specs(records, campaign_dir, **{
            k: v for k, v in (options or {}).items() if k not in driver_only})
        if allow_long is not None and jobs is not None and not allowed:
            runs_dir = campaign_dir / "runs"
            todo = [s for s in specs if not (runs_dir / s.run_id / "summary.json").exists()]
            core_s = [campaign.run_core_s if s.core_s is None else s.core_s   # a run's own
                      for s in todo]
            check_long(f"campaign {name}", len(todo), sum(core_s) / max(len(todo), 1), jobs,
                       allow_long, "fewer records, members or parameter values")
        provenance = {}
        if (options or {}).get("contact_file") is not None:     # which file, its values
            provenance["contact_file"] = contact_provenance(options["contact_file"])
        return _run_specs(campaign, name, specs, campaign_dir, jobs, animations, executor,
                          scheduler, provenance)
    except (InputError, ToolError, OSError):
        if not existed and not (campaign_dir / "campaign.json").exists() and \
                not any(campaign_dir.glob("runs/*/summary.json")):
            shutil.rmtree(campaign_dir, ignore_errors=True)   # a refusal leaves nothing
        raise


def _gate_from_options(campaign, records, options, campaign_dir, jobs, allow_long):
    """The long-run gate on the campaign's own count from its options (``estimate``),
    before its specs are built: the runs less those already finished in ``campaign_dir``
    (a resumed campaign: a lower bound, so the gate on the specs has the last word when
    this one passes).  True when it was over the hour and allowed (warned)."""
    estimate = None if campaign.estimate is None else \
        campaign.estimate(records, options or {})
    if estimate is None:
        return False
    runs, core_s = estimate
    done = count_finished(campaign_dir)
    return check_long(f"campaign {campaign.name}", max(runs - done, 0), core_s, jobs,
                      allow_long, "fewer records, members or parameter values") > LONG_RUN_S


def reuse_finished(specs, campaign_dir, worker):
    """Copy into ``campaign_dir/runs`` the unfinished specs' runs that a campaign beside it
    (a directory of the same parent with a campaign.json of a campaign with the same
    worker) has finished (campaigns run this for directories inside results/, where the
    project's campaigns live; one elsewhere, e.g. ``--out /data/x``, runs everything): the run id hashes the motion, the parameters and the model code,
    so a run computed once is not computed again.  A spec that keeps its trajectory takes
    only a run that kept one.  Returns how many runs were copied."""
    here = Path(campaign_dir).resolve()
    sources = []
    for meta in sorted(here.parent.glob("*/campaign.json")):
        if meta.parent == here:
            continue
        try:
            name = json.loads(meta.read_text())["campaign"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        discover()
        if name in CAMPAIGNS and CAMPAIGNS[name].worker is worker:
            sources.append(meta.parent / "runs")
    copied = 0
    for spec in specs:
        target = here / "runs" / spec.run_id
        if not sources or (target / "summary.json").exists():
            continue
        keep = spec.keep_trajectory
        for runs in sources:
            source = runs / spec.run_id
            if not (source / "summary.json").exists() or (
                    keep and not (source / "trajectory.npz").exists()):
                continue
            staging = target.with_name(target.name + ".copying")
            try:
                shutil.rmtree(staging, ignore_errors=True)
                if keep:
                    shutil.copytree(source, staging, ignore=shutil.ignore_patterns(".lock"))
                else:
                    staging.mkdir(parents=True)
                    shutil.copy2(source / "summary.json", staging / "summary.json")
                shutil.rmtree(target, ignore_errors=True)      # an unfinished attempt
                os.replace(staging, target)
                copied += 1
                break
            except OSError:                   # the other campaign is changing it: run it
                shutil.rmtree(staging, ignore_errors=True)
    return copied


def _run_specs(campaign, name, specs, campaign_dir, jobs, animations, executor, scheduler,
               provenance=None):
    """Execute the specs and write the campaign's outputs (see :func:`run_campaign`);
    ``provenance``: more entries of campaign.json (the contact file run with)."""
    with DirectoryLock(campaign_dir, wait=False):
        inside = RESULTS_DIR.resolve() in Path(campaign_dir).resolve().parents
        reused = reuse_finished(specs, campaign_dir, campaign.worker) if inside else 0
        if reused:
            log.info(f"{Path(campaign_dir).name}: {reused} run(s) copied from campaigns beside it "
                     "(same run id: same motion, parameters and model code)")
        failures, interrupted = execute(specs, campaign_dir, jobs, campaign.worker,
                                        campaign.label, executor=executor,
                                        scheduler=scheduler)
        result = campaign.outputs(specs, campaign_dir, failures, animations,
                                  figures=not interrupted)
        write_json(campaign_dir / "campaign.json", {
            "campaign": name, "runs": len(specs), "interrupted": interrupted,
            "failed": [{"run_id": s.run_id, "record": s.record, "error": str(e)}
                       for s, e in failures], **result, **(provenance or {})})
    if interrupted:
        raise KeyboardInterrupt
    if failures:
        raise ToolError(f"{len(failures)} run(s) failed; see error.txt in their run "
                        "directories; rerun the campaign to retry them")
    return result
