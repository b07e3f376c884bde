"""A run's directory, as both executors keep it: a failure's error.txt, a finished run
booked on the progress bar, only summary.json kept for runs that keep no trajectory."""
import shutil
import traceback
from pathlib import Path

from tqdm import tqdm

from pipeline.files import ToolError, write_text
from pipeline.outcome.summary import RunSummary


class RunError(ToolError):
    """A run failed on a Dask worker; the message is the worker's, with this
    machine's run directory in place of the worker's temporary one."""


def book_finished(spec, exc, runs_dir, failures, bar):
    """Book one finished run: a failure gets error.txt and a line above the bar."""
    if exc is not None:
        failures.append((spec, exc))
        if not isinstance(exc, RunError):          # a RunError's error.txt is written
            write_error(runs_dir / spec.run_id, exc)
        tqdm.write(f"run {spec.run_id} ({spec.record}) failed: {exc}")
    bar.update()


def finished_summary(campaign_dir, run_id):
    """The :class:`~pipeline.outcome.summary.RunSummary` of run ``run_id`` of the campaign
    in ``campaign_dir``; None while the run has not finished."""
    path = Path(campaign_dir) / "runs" / run_id / "summary.json"
    return RunSummary.load(path) if path.exists() else None


def finished_runs(campaign_dir, specs):
    """(spec, :class:`~pipeline.outcome.summary.RunSummary`) of each of ``specs`` whose
    run has finished in the campaign in ``campaign_dir``, in their order."""
    for spec in specs:
        summary = finished_summary(campaign_dir, spec.run_id)
        if summary is not None:
            yield spec, summary


def count_finished(campaign_dir):
    """How many runs the campaign in ``campaign_dir`` holds finished (0 when none)."""
    runs_dir = Path(campaign_dir) / "runs"
    return sum(1 for _ in runs_dir.glob("*/summary.json")) if runs_dir.is_dir() else 0


def keep_only_summary(run_dir):
    """Delete everything in ``run_dir`` but summary.json (and the lock)."""
    for path in Path(run_dir).iterdir():
        if path.name in ("summary.json", ".lock"):
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()


def write_error(run_dir, exc, text=None):
    run_dir.mkdir(parents=True, exist_ok=True)
    write_text(run_dir / "error.txt", text or "".join(traceback.format_exception(exc)))
