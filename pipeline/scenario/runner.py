"""Run a scenario directory with YADE imported as a module (no launcher, no port).

The scene runs in a child process of Debian's python3 (YADE's compiled module
needs it), single-threaded, in its own process group, with a wall-clock limit;
the child is killed when its parent dies (Linux ``PR_SET_PDEATHSIG``), so a
killed campaign leaves no YADE behind.

YADE makes a temporary directory /tmp/yade-XXXXXX per process (a fixed path, not
TMPDIR) and removes it only at a normal exit.  Each YADE process notes it in a directory
of its own, ``$TMPDIR/toppling-yade-<pid of this process>-XXXXXXXX``, from which it is
removed when the process is killed; a process stopped while YADE still starts removes it
itself (``run_scene.py``); and a campaign killed with SIGKILL, whose YADE processes died
with it, leaves both to the next YADE process started, by any run or campaign of the
same user (:func:`remove_orphaned_tmp`).

Within :func:`reuse_processes` (the campaign executor's threads, a Dask worker's tasks)
each thread keeps one YADE process that runs its scenes one after the other
(``run_scene.py --serve``, ``O.reset()`` between scenes): YADE's start-up, about 1 s, is
paid once per thread instead of once per run.  That process dies with its thread
(``PR_SET_PDEATHSIG`` is per thread), when the block ends (or, for a Dask worker, with
:func:`end_served_processes` at the campaign's end), on a timeout, on Ctrl-C, and by
itself after ``SERVE_IDLE_S`` without a scene.
"""
import contextlib
import os
import re
import select
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from functools import partial
from pathlib import Path

from pipeline import YADE_SCRIPTS_DIR
from pipeline.files import ToolError, die_with_parent
from pipeline.outcome import Trajectory
from pipeline.provenance import YADE_PY_PATH
from pipeline.scenario.scene_file import SceneFile

DEBIAN_PYTHON = "/usr/bin/python3"
TMP_PREFIX = "toppling-yade-"     # a YADE process's note of its temporary directory
NOTE = "yade_tmp_dir"              # ... the file in it (run_scene.py writes it)
OWNER = re.compile(re.escape(TMP_PREFIX) + r"(\d+)-")   # ... named after the campaign's pid
STOP_GRACE_S = 30.0                # a YADE process stopped while starting ends within this
# glibc picks its libm routines (exp, sin, pow...) by CPU feature: with these tunables a
# YADE process takes the non-FMA/AVX2 ones, as an older or another vendor's CPU would, so
# that one machine can show which results depend on a CPU's last bits (make test runs the
# tests marked ``libm`` once more this way; make bench, section 9)
SECOND_LIBM_TUNABLES = "glibc.cpu.hwcaps=-AVX2_Usable,-FMA_Usable,-AVX2,-FMA"
WRAPPER = YADE_SCRIPTS_DIR / "run_scene.py"
STARTUP_ALLOWANCE_S = 120.0        # wall-clock seconds granted on top of the simulation
MIN_SIM_S_PER_WALL_S = 0.05        # slower than this and the run is declared hung
_RUNNING = set()                   # YADE processes of this process, for kill_running()
_RUNNING_LOCK = threading.Lock()
SCENES_PER_PROCESS = 200           # a served process is replaced after this many scenes
SERVE_IDLE_S = 120.0               # a served process ends itself after this long without a scene
_SERVED = threading.local()        # this thread's serving process (reuse_processes)
_REUSE = {"depth": 0}
_STOPPED = set()                   # marks of run directories whose scenes stop_scenes() ends


class YadeError(ToolError):
    """YADE failed or exceeded its wall-clock limit; the message points at yade.log."""


def check_yade():
    """Raise a one-line ToolError when YADE or Debian's python3 is missing."""
    if not (Path(DEBIAN_PYTHON).is_file() and (Path(YADE_PY_PATH) / "yade").is_dir()):
        raise ToolError("YADE is not installed (Debian package 'yade'): run 'make setup'")


def wall_limit_s(t_max):
    """Wall-clock limit (s) of a run simulating ``t_max`` seconds."""
    return STARTUP_ALLOWANCE_S + t_max / MIN_SIM_S_PER_WALL_S


def run_yade(run_dir, timeout_s=None):
    """Run ``run_dir/scene.py``; return its :class:`~pipeline.outcome.Trajectory`.

    The log goes to ``run_dir/yade.log``.  Failure or timeout raises YadeError.
    """
    check_yade()
    run_dir = Path(run_dir).resolve()
    out = run_dir / "trajectory.npz"
    out.unlink(missing_ok=True)
    if timeout_s is None:
        timeout_s = wall_limit_s(SceneFile.read(run_dir).t_max)
    with _RUNNING_LOCK:
        _refuse_stopped(run_dir)     # before any file or process (checked again at the start)
    start = time.perf_counter()
    if _REUSE["depth"] and "\n" not in str(run_dir):
        code = _run_served(run_dir, timeout_s)
    else:
        code = _run_once(run_dir, timeout_s)
    wall = time.perf_counter() - start
    if code < 0:
        raise YadeError(f"YADE was stopped by signal {-code}; see {run_dir / 'yade.log'}")
    if code != 0 or not out.exists():
        tail = (run_dir / "yade.log").read_text(errors="replace").strip().splitlines()[-1:]
        raise YadeError(f"YADE failed (exit {code}): {' '.join(tail)[:200]}; "
                        f"see {run_dir / 'yade.log'}")
    return Trajectory.load(out, wall_s=wall)


def _environment(note_dir):
    """The YADE process's environment; it notes the temporary directory YADE makes for it
    in ``note_dir`` (run_scene.py), which :func:`_remove_tmp` removes with that note."""
    env = dict(os.environ, OMP_NUM_THREADS="1", YADE_PY_PATH=YADE_PY_PATH,
               TOPPLING_YADE_NOTE_DIR=note_dir)
    env.pop("PYTHONPATH", None)
    env.pop("VIRTUAL_ENV", None)
    return env


def _note_dir():
    """A new directory for a YADE process's note of its temporary directory, named after
    this process (those of processes gone are removed first)."""
    remove_orphaned_tmp()
    return tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{os.getpid()}-")


def remove_orphaned_tmp(tmp_dir=None):
    """Remove this user's note directories in ``tmp_dir`` (default: the temporary
    directory) whose campaign process is gone, and the YADE directories noted in them:
    what a campaign killed with SIGKILL while YADE ran a scene leaves.  Their number."""
    removed = 0
    for note_dir in Path(tmp_dir or tempfile.gettempdir()).glob(TMP_PREFIX + "*"):
        owner = OWNER.match(note_dir.name)
        with contextlib.suppress(OSError):
            if owner and note_dir.stat().st_uid == os.getuid() and not _alive(int(owner[1])):
                _remove_tmp(note_dir)
                removed += 1
    return removed


def _alive(pid):
    """Whether process ``pid`` runs (any user's; not a zombie: it has ended)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return True
    return stat[stat.rindex(")") + 2:].split()[0] != "Z"


def _start(args, note_dir, stdout, **popen):
    """Start the YADE process ``args`` (run_scene.py) in a process group of its own; its
    death signal is SIGTERM until YADE has started (run_scene.py), then SIGKILL."""
    proc = subprocess.Popen(args, stdout=stdout, stderr=subprocess.STDOUT,
                            env=_environment(note_dir), start_new_session=True,
                            preexec_fn=partial(die_with_parent, os.getpid(), signal.SIGTERM),
                            **popen)
    proc.tmpdir = note_dir
    return proc


def _run_once(run_dir, timeout_s):
    """One scene in a fresh process; its exit code (negative: killed by a signal)."""
    with open(run_dir / "yade.log", "w") as log:
        tmpdir = _note_dir()
        with _RUNNING_LOCK:                      # refused or seen by stop_scenes()
            try:
                _refuse_stopped(run_dir)
                proc = _start([DEBIAN_PYTHON, str(WRAPPER), "scene.py"], tmpdir, log,
                              cwd=run_dir, stdin=subprocess.DEVNULL)
            except BaseException:
                _remove_tmp(tmpdir)
                raise
            proc.run_dir = str(run_dir)
            _RUNNING.add(proc)
        try:
            return proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            _kill(proc)
            raise _timed_out(run_dir, timeout_s) from None
        except BaseException:
            _kill(proc)
            raise
        finally:
            with _RUNNING_LOCK:
                _RUNNING.discard(proc)
            _remove_tmp(tmpdir)


@contextlib.contextmanager
def reuse_processes(end=True):
    """Within this block, every thread runs its scenes in one YADE process of its own.

    ``end``: end the idle served processes when the last such block ends; False (a Dask
    task) leaves them to the next task, to :func:`end_served_processes` and to their
    own idle limit."""
    with _RUNNING_LOCK:
        _REUSE["depth"] += 1
    try:
        yield
    finally:
        with _RUNNING_LOCK:
            _REUSE["depth"] -= 1
            last = _REUSE["depth"] == 0
        if last and end:
            end_served_processes()


def end_served_processes():
    """Kill this process's served YADE processes that run no scene now; their number."""
    with _RUNNING_LOCK:
        idle = [p for p in _RUNNING if hasattr(p, "control") and not p.busy]
        for proc in idle:
            proc.retired = True           # no thread takes it up again
    for proc in idle:
        _kill(proc)
    return len(idle)


def _server():
    """This thread's serving process, marked busy (started, or replaced when dead, old,
    retired or near its idle limit)."""
    proc = getattr(_SERVED, "proc", None)
    with _RUNNING_LOCK:
        usable = (proc is not None and not proc.retired and proc.poll() is None
                  and proc.scenes < SCENES_PER_PROCESS
                  and time.monotonic() - proc.last_used < SERVE_IDLE_S / 2)
        if usable:
            proc.busy = True
            return proc
    if proc is not None:
        _kill(proc)
    read_fd, write_fd = os.pipe()
    tmpdir = _note_dir()
    try:
        proc = _start([DEBIAN_PYTHON, str(WRAPPER), "--serve", str(write_fd),
                       str(SERVE_IDLE_S)], tmpdir, subprocess.DEVNULL,
                      stdin=subprocess.PIPE, pass_fds=(write_fd,))
    except BaseException:
        _remove_tmp(tmpdir)
        raise
    finally:
        os.close(write_fd)
    proc.control = os.fdopen(read_fd, "rb")
    proc.scenes, proc.busy, proc.retired, proc.last_used = 0, True, False, time.monotonic()
    _SERVED.proc = proc
    with _RUNNING_LOCK:
        _RUNNING.add(proc)
    return proc


def _run_served(run_dir, timeout_s):
    """One scene in this thread's serving process; its exit code."""
    proc = _server()
    proc.scenes += 1
    try:
        return _answer(proc, run_dir, timeout_s)
    finally:
        proc.last_used, proc.busy, proc.run_dir = time.monotonic(), False, ""


def _answer(proc, run_dir, timeout_s):
    """Send ``run_dir`` to the serving process ``proc``; the scene's exit code."""
    with _RUNNING_LOCK:                          # refused or seen by stop_scenes()
        _refuse_stopped(run_dir)
        proc.run_dir = str(run_dir)
    try:
        proc.stdin.write(os.fsencode(run_dir) + b"\n")     # any bytes a path may hold
        proc.stdin.flush()
        ready, _, _ = select.select([proc.control], [], [], timeout_s)
        answer = proc.control.readline() if ready else None
    except BrokenPipeError:
        answer = b""
    except BaseException:
        _kill(proc)
        raise
    if answer is None:
        _kill(proc)
        raise _timed_out(run_dir, timeout_s)
    if not answer:                     # the process died (a crash, or killed)
        _kill(proc)
        return proc.returncode if proc.returncode != 0 else 1
    return int(answer)


def _timed_out(run_dir, timeout_s):
    return YadeError(f"YADE exceeded its wall-clock limit of {timeout_s:.0f} s; "
                     f"see {run_dir / 'yade.log'}")


def kill_running():
    """Kill every YADE process this process started (Ctrl-C of a campaign)."""
    with _RUNNING_LOCK:
        procs = list(_RUNNING)
    for proc in procs:
        if proc.returncode is None:              # reaped: its pid is no longer its own
            _stop_group(proc)


def stop_scenes(mark):
    """Kill this process's YADE processes that run a scene whose run directory's path
    contains ``mark``, and refuse such scenes from now on (Ctrl-C of a Dask campaign on a
    worker: a task about to start its scene is refused rather than missed).  Returns their
    pids once their temporary directories are removed (by the threads that ran them, or
    by themselves when stopped while YADE started; at most STOP_GRACE_S)."""
    with _RUNNING_LOCK:
        _STOPPED.add(mark)
        procs = [p for p in _RUNNING
                 if p.returncode is None and mark in getattr(p, "run_dir", "")]
        for proc in procs:
            _stop_group(proc)
    deadline = time.monotonic() + STOP_GRACE_S
    while any(os.path.exists(p.tmpdir) for p in procs) and time.monotonic() < deadline:
        time.sleep(0.02)
    return [p.pid for p in procs]


def _refuse_stopped(run_dir):
    """Raise YadeError when ``run_dir`` is a scene stop_scenes() ended (hold _RUNNING_LOCK)."""
    if any(mark in str(run_dir) for mark in _STOPPED):
        raise YadeError(f"{run_dir}: not run, its campaign was stopped")


def _kill(proc):
    """Kill the child's whole process group and reap it (and close a served process's
    pipes).  A child already reaped is not signalled: its pid may belong to another
    process by now (unreaped, even when it has exited, its pid is still its own)."""
    if proc.returncode is None:
        _stop_group(proc)
        try:
            proc.wait(timeout=STOP_GRACE_S)
        except subprocess.TimeoutExpired:
            _stop_group(proc)                    # SIGKILL by now
            proc.wait()
    with _RUNNING_LOCK:
        _RUNNING.discard(proc)
    for pipe in (proc.stdin, getattr(proc, "control", None)):
        if pipe is not None:
            with contextlib.suppress(OSError):
                pipe.close()
    if getattr(proc, "tmpdir", None):
        _remove_tmp(proc.tmpdir)


def _stop_group(proc):
    """Stop the child's process group: SIGKILL once YADE has started in it (its temporary
    directory is noted: removed after), before that SIGTERM, which the child takes once
    YADE has started, removing that directory itself; SIGKILL after all when a SIGTERM
    did not end it within STOP_GRACE_S."""
    started = os.path.exists(os.path.join(proc.tmpdir, NOTE))
    first = vars(proc).setdefault("stop_sent", time.monotonic())
    late = time.monotonic() - first > STOP_GRACE_S
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL if started or late else signal.SIGTERM)


def _remove_tmp(note_dir):
    """Remove the temporary directory YADE made for a process that has ended (named in
    ``note_dir``, by run_scene.py) and ``note_dir`` itself."""
    with contextlib.suppress(OSError):
        made = (Path(note_dir) / NOTE).read_text().strip()
        if Path(made).name.startswith("yade-"):
            shutil.rmtree(made, ignore_errors=True)
    shutil.rmtree(note_dir, ignore_errors=True)
