"""What runs on a Dask worker: one run in a temporary directory, its files returned; the
model code checked by hash against the client's."""
import functools
import json
import socket
import tempfile
import traceback
from dataclasses import replace
from pathlib import Path

from pipeline.files import ToolError, code_hash
from pipeline.scenario.runner import reuse_processes, stop_scenes
from pipeline.simulate import RUN_CODE

TASK_PREFIX = "toppling"        # Dask keys and worker temporary directories
# The model code (what turns a motion and parameters into an outcome, as in the run ids):
# a worker whose imported copy differs from the client's files refuses the task.
WORKER_CODE = RUN_CODE


@functools.lru_cache(maxsize=1)
def worker_code_version():
    """Hash of the model code (``WORKER_CODE``) when this worker process ran its first
    task (close to when it imported that code; a later edit of the files does not change
    what the process runs, so neither does it change this)."""
    return code_hash(*WORKER_CODE)


def run_task(worker, spec, motion, client_run_dir, code, token):
    """Dask task: run ``worker(spec, run_dir)`` in a temporary directory of this worker
    and return {"files": {relative path: bytes}, "error", "message", "host"}.

    ``motion``: bytes of the spec's processed-motion npz (None without a motion file).
    Paths of the temporary directory in summary.json and in messages are replaced by
    the client's (``client_run_dir``, the spec's ``motion_file``), so a run directory
    reads the same whichever executor wrote it.  Files: every file the worker wrote
    (only summary.json for ``keep_trajectory: False``); after a failure the small ones.
    """
    host = socket.gethostname()
    if code != worker_code_version():
        raise ToolError(f"the Dask worker on {host} runs other code than the client (hash "
                        f"{worker_code_version()} vs {code}): install the same version of "
                        "the project on the workers")
    with tempfile.TemporaryDirectory(prefix=f"{TASK_PREFIX}-{token}-",
                                     dir=_scratch_directory()) as tmp:
        tmp = Path(tmp)
        swaps = []
        if motion is not None:
            path = tmp / "input" / Path(spec.motion_file).name
            path.parent.mkdir()
            path.write_bytes(motion)
            swaps.append((str(path), spec.motion_file))
            spec = replace(spec, motion_file=str(path))     # the same run, its motion moved
        run_dir = tmp / "run"
        run_dir.mkdir()
        swaps.append((str(run_dir), client_run_dir))
        error = message = None
        try:
            with reuse_processes(end=False):          # the worker's YADE process serves on
                worker(spec, run_dir)
        except Exception as exc:                      # noqa: BLE001 (sent back to the client)
            error = _swap("".join(traceback.format_exception(exc)), swaps)
            message = _swap(str(exc), swaps)
        files = {}
        for path in sorted(run_dir.rglob("*")):
            if not path.is_file() or path.name == ".lock":
                continue
            name = path.relative_to(run_dir).as_posix()
            if error is not None and path.suffix == ".npz":
                continue                              # a failed run sends its logs only
            if error is None and not spec.keep_trajectory \
                    and name != "summary.json":
                continue
            files[name] = path.read_bytes()
        if "summary.json" in files:
            summary = _swap(json.loads(files["summary.json"]), swaps)
            files["summary.json"] = (json.dumps(summary, indent=2, allow_nan=False)
                                     + "\n").encode()
        return {"files": files, "error": error, "message": message, "host": host}


def _scratch_directory():
    """The Dask worker's local directory (its scratch space, which Dask purges when a
    killed worker's successor starts), else the system's temporary directory."""
    try:
        from distributed import get_worker  # lazy: distributed, only on a Dask cluster
        return get_worker().local_directory
    except (ImportError, ValueError, AttributeError):
        return None


def _swap(value, swaps):
    """``value`` (str, or JSON-like list/dict) with every (old, new) substring replaced."""
    if isinstance(value, str):
        for old, new in swaps:
            value = value.replace(old, new)
        return value
    if isinstance(value, list):
        return [_swap(v, swaps) for v in value]
    if isinstance(value, dict):
        return {k: _swap(v, swaps) for k, v in value.items()}
    return value


def kill_task_processes(token):
    """Kill this worker's YADE processes of campaign ``token`` and refuse the scenes its
    tasks have yet to start (run with Client.run after Ctrl-C:
    :func:`pipeline.scenario.runner.stop_scenes` on the campaign's temporary
    directories).  Returns their pids."""
    return stop_scenes(f"/{TASK_PREFIX}-{token}-")
