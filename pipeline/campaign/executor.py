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
"""
import contextlib
import functools
import hashlib
import json
import os
import shutil
import signal
import socket
import tempfile
import threading
import traceback
import uuid
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from pathlib import Path

from tqdm import tqdm

from pipeline.files import (
    DirectoryLock,
    InputError,
    ToolError,
    atomic_path,
    code_hash,
    write_text,
)
from pipeline.motion import Motion
from pipeline.scenario.runner import end_served_processes, kill_running, reuse_processes
from pipeline.simulate import RUN_CODE

EXECUTORS = ("threads", "dask")
DEFAULT_EXECUTOR = "threads"    # why: docs/campaigns.md, "On a cluster: Dask" (start-up, ports)
CONNECT_TIMEOUT_S = 10          # reaching an existing Dask scheduler (s)
CLOSE_TIMEOUT_S = 1.0           # closing the local cluster after Ctrl-C
TASK_PREFIX = "toppling"        # Dask keys and worker temporary directories
# The model code (what turns a motion and parameters into an outcome, as in the run ids):
# a worker whose imported copy differs from the client's files refuses the task.
WORKER_CODE = RUN_CODE


class RunError(ToolError):
    """A run failed on a Dask worker; the message is the worker's, with this
    machine's run directory in place of the worker's temporary one."""


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
    todo = [s for s in specs if not (runs_dir / s["run_id"] / "summary.json").exists()]
    durations = {}
    todo.sort(key=lambda spec: motion_seconds(spec, durations), reverse=True)
    done = len(specs) - len(todo)
    where = (f"{jobs} parallel YADE process(es)" if executor == "threads" else
             f"{jobs} local Dask worker process(es)" if not scheduler else
             f"the Dask cluster at {scheduler}" + (f", {jobs} at a time" if jobs else ""))
    print(f"{Path(campaign_dir).name}: {len(specs)} {label}, {done} already done, "
          f"{len(todo)} to run with {where}", flush=True)
    if not todo:
        return [], False
    bar = tqdm(total=len(specs), initial=done, unit="run", dynamic_ncols=True)
    try:
        if executor == "threads":
            with reuse_processes():        # one YADE process per thread, not per run
                return _execute_threads(todo, runs_dir, jobs, worker, bar)
        return _execute_dask(todo, runs_dir, jobs, worker, bar, scheduler)
    finally:
        bar.close()


def motion_seconds(spec, durations):
    """Seconds of motion a run shakes (its window, else its motion file's length; 0 if
    unknown): campaigns start the longest first, so that no core idles at the end while
    one long run finishes.  ``durations`` caches file lengths by path."""
    window = spec.get("params", {}).get("window")
    if window:
        return float(window[1]) - float(window[0])
    path = spec.get("motion_file")
    if not path:
        return 0.0
    if path not in durations:
        try:
            durations[path] = Motion.load(path).duration
        except (OSError, InputError):
            durations[path] = 0.0          # the run itself reports the bad file
    return durations[path]


def _finished(spec, exc, runs_dir, failures, bar):
    """Book one finished run: a failure gets error.txt and a line above the bar."""
    if exc is not None:
        failures.append((spec, exc))
        if not isinstance(exc, RunError):          # a RunError's error.txt is written
            _write_error(runs_dir / spec["run_id"], exc)
        tqdm.write(f"run {spec['run_id']} ({spec.get('record')}) failed: {exc}")
    bar.update()


# ---------------------------------------------------------------- threads
def _execute_threads(todo, runs_dir, jobs, worker, bar):
    failures = []
    pool = ThreadPoolExecutor(max_workers=jobs)
    futures = {pool.submit(_guarded, worker, spec, runs_dir / spec["run_id"]): spec
               for spec in todo}
    pending = set(futures)
    try:
        while pending:
            finished, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in finished:
                _finished(futures[future], future.exception(), runs_dir, failures, bar)
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
        if not spec.get("keep_trajectory", True):
            _keep_only_summary(run_dir)


def _keep_only_summary(run_dir):
    for path in Path(run_dir).iterdir():
        if path.name in ("summary.json", ".lock"):
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()


def _write_error(run_dir, exc, text=None):
    run_dir.mkdir(parents=True, exist_ok=True)
    write_text(run_dir / "error.txt", text or "".join(traceback.format_exception(exc)))


# ---------------------------------------------------------------- dask
def _execute_dask(todo, runs_dir, jobs, worker, bar, scheduler):
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ToolError("the dask executor needs dask.distributed: "
                        ".venv/bin/python -m pip install 'dask[distributed]'") from None
    failures, cluster, client, interrupted = [], None, None, False
    token = uuid.uuid4().hex[:8]
    running, motions = {}, {}                         # key -> (future, spec); file -> future
    queue = list(reversed(todo))
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
            except (OSError, ValueError, TypeError) as exc:
                first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                raise ToolError(f"cannot reach the Dask scheduler at {scheduler}: {first}") \
                    from None
        else:
            cluster = local_cluster(jobs)
            client = Client(cluster)
        code = code_hash(*WORKER_CODE)                # the client's files, now
        completed = as_completed(with_results=True, raise_errors=False)

        def submit(spec):
            motion = None
            if spec.get("motion_file"):
                try:
                    motion = _motion_future(client, motions, spec["motion_file"], token)
                except OSError as exc:
                    _finished(spec, exc, runs_dir, failures, bar)
                    return
            future = client.submit(run_task, worker, spec, motion,
                                   str(runs_dir / spec["run_id"]), code, token,
                                   key=f"{TASK_PREFIX}-run-{spec['run_id']}-{token}",
                                   pure=False)
            running[future.key] = (future, spec)
            completed.add(future)

        limit = jobs if (scheduler and jobs) else len(queue)
        while queue or running:
            while queue and len(running) < limit:
                submit(queue.pop())
            if not running:
                break
            future, result = next(completed)
            _, spec = running.pop(future.key)
            _store_result(spec, future, result, runs_dir, failures, bar)
            future.release()
    except KeyboardInterrupt:
        interrupted = True
    finally:
        close_dask(client, cluster, token, interrupted,
                   [f for f, _ in running.values()] + list(motions.values()))
    return failures, interrupted


def local_cluster(jobs):
    """A LocalCluster of ``jobs`` single-threaded worker processes on 127.0.0.1.

    Every server of it listens on 127.0.0.1 only, on ports the kernel picks: the
    scheduler (its comm and its HTTP server for /health and /metrics: the bokeh
    dashboard is off) and per worker its nanny, its comm and its HTTP server:
    2 + 3 x jobs ports, closed with the cluster.
    """
    import logging

    from distributed import LocalCluster
    return LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                        host="127.0.0.1", scheduler_port=0, dashboard_address=None,
                        scheduler_kwargs={"dashboard": False,
                                          "dashboard_address": "127.0.0.1:0"},
                        silence_logs=logging.CRITICAL)     # failures come back as results


def _motion_future(client, motions, motion_file, token):
    """The processed motion's bytes as a Dask task (one per file): the scheduler keeps
    the bytes, so a copy lost with its worker is recomputed."""
    if motion_file not in motions:
        data = Path(motion_file).read_bytes()
        digest = hashlib.sha256(data).hexdigest()[:16]
        motions[motion_file] = client.submit(_motion_bytes, data, pure=False,
                                             key=f"{TASK_PREFIX}-motion-{digest}-{token}")
    return motions[motion_file]


def _motion_bytes(data):
    return data


def _store_result(spec, future, result, runs_dir, failures, bar):
    """Write a task's files into its run directory (summary.json last), or book its
    failure."""
    run_dir = runs_dir / spec["run_id"]
    if future.status != "finished":               # the task raised (KilledWorker, ...)
        if isinstance(result, tuple) and len(result) == 3:      # (type, exception, traceback)
            exc = result[1].with_traceback(result[2])
        elif isinstance(result, BaseException):
            exc = result
        else:
            exc = RunError(f"the Dask task ended as {future.status}")
        _finished(spec, exc, runs_dir, failures, bar)
        return
    try:
        write_run_files(run_dir, result["files"], clear=result["error"] is None)
        if result["error"] is not None:
            _write_error(run_dir, None, result["error"])
    except (OSError, ToolError) as exc:
        _finished(spec, exc, runs_dir, failures, bar)
        return
    exc = None if result["error"] is None else RunError(
        f"{result['message']} (on {result['host']})")
    _finished(spec, exc, runs_dir, failures, bar)


def write_run_files(run_dir, files, clear=True):
    """Write ``files`` ({relative path: bytes}) into ``run_dir`` atomically, holding its
    lock, ``summary.json`` last; ``clear``: remove what an earlier attempt left first."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    root = run_dir.resolve()
    with DirectoryLock(run_dir, wait=False):
        if clear:
            for path in run_dir.iterdir():
                if path.name != ".lock":
                    shutil.rmtree(path) if path.is_dir() and not path.is_symlink() \
                        else path.unlink()
        else:
            (run_dir / "summary.json").unlink(missing_ok=True)
        for name in sorted(files, key=lambda n: n == "summary.json"):
            path = (run_dir / name).resolve()
            if root not in path.parents:
                raise ToolError(f"a worker returned a file outside its run directory: {name}")
            with atomic_path(path) as tmp:
                tmp.write_bytes(files[name])


def close_dask(client, cluster, token=None, interrupted=False, futures=()):
    """Cancel what is left; after Ctrl-C kill the campaign's YADE processes on the
    workers of a cluster we don't own, and end the idle YADE processes its workers kept
    for the next task (they would end by themselves after SERVE_IDLE_S).  Kill a local
    cluster's worker processes (their YADE processes die with them; a graceful close
    takes seconds) and close it and the client.  Best effort: nothing here may keep
    Ctrl-C from returning."""
    if client is not None and (interrupted or cluster is None):
        def stop():
            if interrupted:
                with contextlib.suppress(Exception):
                    client.cancel(futures)
            if cluster is None:
                with contextlib.suppress(Exception):
                    if interrupted:
                        client.run(kill_task_processes, token, on_error="ignore")
                    client.run(end_served_processes, on_error="ignore")
        stopping = threading.Thread(target=stop, daemon=True)     # an unreachable worker
        stopping.start()                                          # must not hold Ctrl-C up
        stopping.join(CLOSE_TIMEOUT_S if interrupted else CONNECT_TIMEOUT_S)
    if cluster is not None:             # results in, or Ctrl-C: nothing to wait for
        _kill_local_workers(cluster)
    for closing in (client, cluster):
        if closing is not None:
            with contextlib.suppress(Exception):
                closing.close(timeout=CLOSE_TIMEOUT_S if interrupted else 10)


def _kill_local_workers(cluster):
    """SIGKILL the local cluster's worker processes (their YADE children die with them,
    PR_SET_PDEATHSIG), their nannies told first not to start new ones."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        process = getattr(getattr(nanny, "process", None), "process", None)
        pid = getattr(process, "pid", None)
        with contextlib.suppress(Exception):
            nanny.close_gracefully(reason="campaign over")
        if pid:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


# ---------------------------------------------------------------- on the worker
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
        spec = dict(spec)
        swaps = []
        if motion is not None:
            path = tmp / "input" / Path(spec["motion_file"]).name
            path.parent.mkdir()
            path.write_bytes(motion)
            swaps.append((str(path), spec["motion_file"]))
            spec["motion_file"] = str(path)
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
            if error is None and not spec.get("keep_trajectory", True) \
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
        from distributed import get_worker
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
    """Kill this worker's YADE processes of campaign ``token`` (run with Client.run after
    Ctrl-C): children of this process whose working directory lies in a temporary
    directory of that campaign.  Returns their pids."""
    mark = f"/{TASK_PREFIX}-{token}-"
    me, killed = os.getpid(), []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
            parent = int(stat.rsplit(")", 1)[1].split()[1])
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except (OSError, ValueError, IndexError):
            continue
        if parent == me and mark in cwd:
            pid = int(pid)
            try:
                if os.getpgid(pid) == pid:                # YADE leads its own group
                    os.killpg(pid, signal.SIGKILL)
                else:
                    os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            except ProcessLookupError:
                pass
    return killed

