"""One executor for every campaign: run ids, resume, parallel runs, progress, Ctrl-C.

Each run lives in ``<campaign>/runs/<run_id>/``; a run whose ``summary.json``
exists is finished and never run again, so a killed campaign resumes where it
stopped.  Runs are single-thread YADE processes, ``jobs`` at a time, through one
of two executors:

- ``threads`` (the default on one machine): a thread pool in this process; each
  thread starts one YADE child process that writes straight into the run
  directory.  No start-up cost, no network port.
- ``dask``: ``dask.distributed``, either a :class:`~distributed.LocalCluster` of
  ``jobs`` single-threaded worker processes on 127.0.0.1 or, with ``scheduler``,
  an existing Dask cluster.  A task carries everything it needs (the spec and the
  processed motion's bytes, shipped once per motion as a task of its own so that
  a lost worker's copy is recomputed), runs the scene in a temporary directory on
  its worker and returns the run's files; this process writes them atomically
  into ``runs/<run_id>/``, ``summary.json`` last.  Workers need the project
  installed (the same code: checked by hash) and YADE, not the client's files.

A spec with ``keep_trajectory: False`` keeps only ``summary.json`` in its run
directory (large ensembles).  Ctrl-C starts no new run, kills the running YADE
processes (on a Dask cluster: the campaign's own, through the workers), closes a
local cluster and returns what finished; the caller writes its tables and
exits 130.

Once the first runs are done (as many as run at once), a campaign whose rest takes
``FORECAST_FROM_S`` or more says how long, measured on this machine: a warning from
``WARN_FROM_S`` on; it says it again, a few times in hours at most, when the pace moves
the rest by ``REVISE_FACTOR``.
"""
import logging
import os
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from pathlib import Path

from tqdm import tqdm

from pipeline import raise_if_stop_asked
from pipeline.campaign.dask_client import execute_dask
from pipeline.campaign.run_dirs import book_finished, keep_only_summary
from pipeline.files import DirectoryLock, InputError, duration_text
from pipeline.motion import Motion
from pipeline.scenario.runner import kill_running, reuse_processes

log = logging.getLogger(__name__)

EXECUTORS = ("threads", "dask")
DEFAULT_EXECUTOR = "threads"    # why: docs/campaigns.md, "On a cluster: Dask" (start-up, ports)
FORECAST_FROM_S = 600.0         # a campaign says how long its rest takes from 10 min on
WARN_FROM_S = 3600.0            # ... and warns from an hour on
REVISE_FACTOR = 1.5             # ... and again when the pace moves it this much
RUN_CORE_S = 9.0                # core s of one twin-model run, for the estimate before any
#                                 run (the gate, pipeline.files.check_long; make invert-demo:
#                                 672 + 2 x 72 runs of 20 s motions in 48.6 min on 2 cores
#                                 with the time-step factor 0.3, x 1.28 for the default 0.235
#                                 at damping 0.36)


def execute(specs, campaign_dir, jobs, worker, label="runs", executor=None, scheduler=None):
    """Run every spec without ``summary.json``; return (failures, interrupted).

    ``worker(spec, run_dir)`` writes ``run_dir/summary.json`` atomically as its last act.
    failures: list of (spec, exception).  executor: "threads" (default) or "dask";
    scheduler: address of a Dask scheduler (implies "dask"); jobs: parallel runs
    (None with a scheduler: as many as the cluster has worker threads).
    """
    executor = executor or ("dask" if scheduler else DEFAULT_EXECUTOR)
    if executor not in EXECUTORS:
        raise InputError(f"--executor must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if scheduler and executor != "dask":
        raise InputError("--scheduler needs the dask executor (not --executor threads)")
    if jobs is None and not scheduler:
        jobs = os.cpu_count() or 1
    runs_dir = Path(campaign_dir) / "runs"
    todo = [s for s in specs if not (runs_dir / s.run_id / "summary.json").exists()]
    durations = {}
    todo.sort(key=lambda spec: motion_seconds(spec, durations), reverse=True)
    done = len(specs) - len(todo)
    where = (f"{jobs} parallel YADE process(es)" if executor == "threads" else
             f"{jobs} local Dask worker process(es)" if not scheduler else
             f"the Dask cluster at {scheduler}" + (f", {jobs} at a time" if jobs else ""))
    log.info(f"{Path(campaign_dir).name}: {len(specs)} {label}, {done} already done, "
             f"{len(todo)} to run with {where}")
    if not todo:
        return [], False
    bar = ForecastBar(total=len(specs), initial=done, unit="run", dynamic_ncols=True,
                      name=Path(campaign_dir).name, first=min(jobs or 4, len(todo)),
                      weights=[motion_seconds(spec, durations) for spec in todo])
    try:
        if executor == "threads":
            with reuse_processes():        # one YADE process per thread, not per run
                return _execute_threads(todo, runs_dir, jobs, worker, bar)
        return execute_dask(todo, runs_dir, jobs, worker, bar, scheduler)
    finally:
        bar.close()


class ForecastBar(tqdm):
    """The campaign's progress bar.  Once the ``first`` runs of this command are done it
    says how long the rest takes at the pace so far (wall time on this machine) when that
    is ``FORECAST_FROM_S`` or more, as a warning from ``WARN_FROM_S`` on.  It says it
    again when the pace of every run done so far puts the rest ``REVISE_FACTOR`` times
    (and ``FORECAST_FROM_S``) longer or shorter than the last forecast, at most once per
    half the time the campaign has run and ``FORECAST_FROM_S`` apart (so a few times in
    hours).  ``weights``: the runs' seconds of motion in the order they start (longest
    first); the pace is per second of motion, so that the long first runs do not stretch
    the forecast (per run when the motions' lengths are unknown)."""

    clock = staticmethod(time.monotonic)

    def __init__(self, *args, name, first, weights=(), **kwargs):
        super().__init__(*args, **kwargs)
        self.name, self.first = name, first
        self.weights = list(weights) if all(w > 0 for w in weights) else []
        self.started = self.clock()
        self.forecast = None        # the last said or looked at: (clock, rest s)

    def update(self, n=1):
        shown = super().update(n)
        finished, left = self.n - self.initial, self.total - self.n
        if finished < self.first or left <= 0:
            return shown
        now = self.clock()
        if self.forecast is None:
            rest_s = self.rest_s(now, finished, left)
            self.forecast = (now, rest_s)
            if rest_s >= FORECAST_FROM_S:
                self.say(rest_s, left, f"the first {finished}")
            return shown
        said_at, said_rest_s = self.forecast
        if now - said_at < max(FORECAST_FROM_S, 0.5 * (now - self.started)):
            return shown
        expected_s = max(said_rest_s - (now - said_at), 0.0)
        rest_s = self.rest_s(now, finished, left)
        moved = rest_s > REVISE_FACTOR * expected_s or rest_s * REVISE_FACTOR < expected_s
        if moved and abs(rest_s - expected_s) >= FORECAST_FROM_S <= rest_s:
            self.forecast = (now, rest_s)
            self.say(rest_s, left, f"all {finished} so far", expected_s=expected_s)
        return shown

    def rest_s(self, now, finished, left):
        """Wall seconds the ``left`` runs take at the pace of the ``finished`` ones."""
        pace_s = (now - self.started) / finished                         # per run
        if len(self.weights) == finished + left:                         # per motion second
            return sum(self.weights[finished:]) * pace_s * finished / sum(self.weights[:finished])
        return left * pace_s

    def say(self, rest_s, left, pace_of, expected_s=None):
        """One line: the rest's duration (as a warning from WARN_FROM_S on); with
        ``expected_s``, what the last forecast left for it."""
        head = "warning: " if rest_s >= WARN_FROM_S else ""
        change = ("" if expected_s is None
                  else f", not the {duration_text(expected_s)} said before")
        self.write(f"{head}{self.name}: the other {left} runs take about "
                   f"{duration_text(rest_s)} at the pace of {pace_of}{change}; Ctrl-C stops "
                   "the campaign and the same command resumes it, keeping every finished run")


def motion_seconds(spec, durations):
    """Seconds of motion a run shakes (its window, else its motion file's length; 0 if
    unknown): campaigns start the longest first, so that no core idles at the end while
    one long run finishes.  ``durations`` caches file lengths by path."""
    params = getattr(spec, "params", None)       # a verification check has none
    window = None if params is None else params.drive.window
    if window:
        return float(window[1]) - float(window[0])
    path = spec.motion_file
    if not path:
        return 0.0
    if path not in durations:
        try:
            durations[path] = Motion.load(path).duration
        except (OSError, InputError):
            durations[path] = 0.0          # the run itself reports the bad file
    return durations[path]


# ---------------------------------------------------------------- threads
def _execute_threads(todo, runs_dir, jobs, worker, bar):
    failures = []
    pool = ThreadPoolExecutor(max_workers=jobs)
    futures = {pool.submit(_guarded, worker, spec, runs_dir / spec.run_id): spec
               for spec in todo}
    pending = set(futures)
    try:
        while pending:
            raise_if_stop_asked()                  # a Ctrl-C a library swallowed
            finished, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in finished:
                book_finished(futures[future], future.exception(), runs_dir, failures, bar)
    except BaseException as exc:                   # Ctrl-C, or no room for error.txt
        for future in pending:
            future.cancel()
        pool.shutdown(wait=False, cancel_futures=True)
        while not all(f.done() for f in pending):  # a thread still writing its scene
            kill_running()                         # starts YADE after the first kill
            wait(pending, timeout=0.05)
        pool.shutdown(wait=True)
        if isinstance(exc, KeyboardInterrupt):
            return failures, True
        raise
    pool.shutdown(wait=True)
    return failures, False


def _guarded(worker, spec, run_dir):
    """Run one spec holding its run directory's lock."""
    run_dir.mkdir(parents=True, exist_ok=True)
    with DirectoryLock(run_dir, wait=False):
        (run_dir / "error.txt").unlink(missing_ok=True)
        worker(spec, run_dir)
        if not spec.keep_trajectory:
            keep_only_summary(run_dir)
