"""The Dask client of the campaign executor: a local cluster or an existing one, tasks that
carry the spec and the motion's bytes, results written atomically into ``runs/``."""
import contextlib
import hashlib
import logging
import os
import shutil
import signal
import threading
import uuid
from pathlib import Path

from pipeline import raise_if_stop_asked
from pipeline.campaign.dask_worker import TASK_PREFIX, WORKER_CODE, kill_task_processes, run_task
from pipeline.campaign.run_dirs import RunError, book_finished, write_error
from pipeline.files import DirectoryLock, ToolError, atomic_path, code_hash
from pipeline.scenario.runner import end_served_processes, remove_orphaned_tmp

CONNECT_TIMEOUT_S = 10          # reaching an existing Dask scheduler (s)
CLOSE_TIMEOUT_S = 1.0           # closing the local cluster after Ctrl-C


def execute_dask(todo, runs_dir, jobs, worker, bar, scheduler):
    try:
        from distributed import Client, as_completed  # lazy: distributed, only on a Dask cluster
    except ImportError:
        raise ToolError("the dask executor needs dask.distributed: "
                        ".venv/bin/python -m pip install 'dask[distributed]'") from None
    logging.getLogger("distributed").setLevel(logging.WARNING)   # its info is not for users
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
            if spec.motion_file:
                try:
                    motion = _motion_future(client, motions, spec.motion_file, token)
                except OSError as exc:
                    book_finished(spec, exc, runs_dir, failures, bar)
                    return
            future = client.submit(run_task, worker, spec, motion,
                                   str(runs_dir / spec.run_id), code, token,
                                   key=f"{TASK_PREFIX}-run-{spec.run_id}-{token}",
                                   pure=False)
            running[future.key] = (future, spec)
            completed.add(future)

        limit = jobs if (scheduler and jobs) else len(queue)
        while queue or running:
            raise_if_stop_asked()                     # a Ctrl-C a library swallowed
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
    from distributed import LocalCluster  # lazy: distributed, only on a Dask cluster
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
    run_dir = runs_dir / spec.run_id
    if future.status != "finished":               # the task raised (KilledWorker, ...)
        if isinstance(result, tuple) and len(result) == 3:      # (type, exception, traceback)
            exc = result[1].with_traceback(result[2])
        elif isinstance(result, BaseException):
            exc = result
        else:
            exc = RunError(f"the Dask task ended as {future.status}")
        book_finished(spec, exc, runs_dir, failures, bar)
        return
    try:
        write_run_files(run_dir, result["files"], clear=result["error"] is None)
        if result["error"] is not None:
            write_error(run_dir, None, result["error"])
    except (OSError, ToolError) as exc:
        book_finished(spec, exc, runs_dir, failures, bar)
        return
    exc = None if result["error"] is None else RunError(
        f"{result['message']} (on {result['host']})")
    book_finished(spec, exc, runs_dir, failures, bar)


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
    workers; end the idle YADE processes the workers kept for the next task (they would
    end by themselves after SERVE_IDLE_S; a local cluster's would die with their worker,
    leaving their temporary directories to the next campaign).  Kill a local cluster's
    worker processes (what still runs dies with them; a graceful close takes seconds;
    the temporary directories of those YADE processes are removed after) and close it
    and the client.  Best effort, bounded: Ctrl-C returns within about
    CONNECT_TIMEOUT_S on a cluster we don't own (its runs killed first: a busy worker may
    answer only after seconds) and CLOSE_TIMEOUT_S on a local one."""
    if interrupted:     # comms closing under a stopped campaign are expected: one line
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
    if client is not None:
        def stop():
            if interrupted:
                with contextlib.suppress(Exception):
                    client.cancel(futures)
            with contextlib.suppress(Exception):
                if interrupted:
                    client.run(kill_task_processes, token, on_error="ignore")
                client.run(end_served_processes, on_error="ignore")
        stopping = threading.Thread(target=stop, daemon=True)     # an unreachable worker
        stopping.start()                                          # must not hold Ctrl-C up
        # a cluster we don't own keeps running what is not killed: wait as long as for
        # reaching it (a busy worker answers in seconds); a local one dies below
        stopping.join(CONNECT_TIMEOUT_S if cluster is None else CLOSE_TIMEOUT_S)
    if cluster is not None:             # results in, or Ctrl-C: nothing to wait for
        _kill_local_workers(cluster)
    for closing in (client, cluster):
        if closing is not None:
            with contextlib.suppress(Exception):
                closing.close(timeout=CLOSE_TIMEOUT_S if interrupted else 10)
    if cluster is not None:       # what YADE processes that died with a worker left
        remove_orphaned_tmp()


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
