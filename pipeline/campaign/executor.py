"""One executor for every campaign: run ids, resume, parallel runs, progress, Ctrl-C.

Each run lives in ``<campaign>/runs/<run_id>/``; a run whose ``summary.json``
exists is finished and never run again, so a killed campaign resumes where it
stopped.  Runs are single-thread YADE processes, ``jobs`` at a time.  Ctrl-C
starts no new run, kills the running YADE processes and returns what finished;
the caller writes its tables and exits 130.
"""
import traceback
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from pathlib import Path

from tqdm import tqdm

from pipeline.files import DirectoryLock, write_text
from pipeline.scenario.runner import kill_running


def execute(specs, campaign_dir, jobs, worker, label="runs"):
    """Run every spec without ``summary.json``; return (failures, interrupted).

    ``worker(spec, run_dir)`` writes ``run_dir/summary.json`` atomically as its last act.
    failures: list of (spec, exception).
    """
    runs_dir = Path(campaign_dir) / "runs"
    todo = [s for s in specs if not (runs_dir / s["run_id"] / "summary.json").exists()]
    done = len(specs) - len(todo)
    print(f"{Path(campaign_dir).name}: {len(specs)} {label}, {done} already done, "
          f"{len(todo)} to run with {jobs} parallel YADE process(es)", flush=True)
    failures = []
    if not todo:
        return failures, False
    pool = ThreadPoolExecutor(max_workers=jobs)
    bar = tqdm(total=len(specs), initial=done, unit="run", dynamic_ncols=True)
    futures = {pool.submit(_guarded, worker, spec, runs_dir / spec["run_id"]): spec
               for spec in todo}
    pending = set(futures)
    try:
        while pending:
            finished, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in finished:
                spec = futures[future]
                exc = future.exception()
                if exc is not None:
                    failures.append((spec, exc))
                    _write_error(runs_dir / spec["run_id"], exc)
                    tqdm.write(f"run {spec['run_id']} ({spec.get('record')}) failed: {exc}")
                bar.update()
    except KeyboardInterrupt:
        for future in pending:
            future.cancel()
        kill_running()
        pool.shutdown(wait=True, cancel_futures=True)
        bar.close()
        return failures, True
    pool.shutdown(wait=True)
    bar.close()
    return failures, False


def _guarded(worker, spec, run_dir):
    """Run one spec holding its run directory's lock."""
    run_dir.mkdir(parents=True, exist_ok=True)
    with DirectoryLock(run_dir, wait=False):
        (run_dir / "error.txt").unlink(missing_ok=True)
        worker(spec, run_dir)


def _write_error(run_dir, exc):
    run_dir.mkdir(parents=True, exist_ok=True)
    write_text(run_dir / "error.txt", "".join(traceback.format_exception(exc)))
