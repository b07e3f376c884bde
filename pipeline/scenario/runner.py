"""Run a scenario directory with YADE imported as a module (no launcher, no port).

The scene runs in a child process of Debian's python3 (YADE's compiled module
needs it), single-threaded, in its own process group, with a wall-clock limit;
the child is killed when its parent dies (Linux ``PR_SET_PDEATHSIG``), so a
killed campaign leaves no YADE behind.
"""
import ctypes
import functools
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

from pipeline import YADE_SCRIPTS_DIR
from pipeline.files import ToolError
from pipeline.outcome import Trajectory

DEBIAN_PYTHON = "/usr/bin/python3"
YADE_PY_PATH = "/usr/lib/x86_64-linux-gnu/yade-double/py"
WRAPPER = YADE_SCRIPTS_DIR / "run_scene.py"
STARTUP_ALLOWANCE_S = 120.0        # wall-clock seconds granted on top of the simulation
MIN_SIM_S_PER_WALL_S = 0.05        # slower than this and the run is declared hung
_PR_SET_PDEATHSIG = 1
_RUNNING = set()                   # YADE processes of this process, for kill_running()
_RUNNING_LOCK = threading.Lock()


class YadeError(ToolError):
    """YADE failed or exceeded its wall-clock limit; the message points at yade.log."""


@functools.lru_cache(maxsize=1)
def yade_version():
    """YADE's version string (from its config module), or None when not installed."""
    config = Path(YADE_PY_PATH) / "yade" / "config.py"
    if not config.is_file():
        return None
    for line in config.read_text(errors="replace").splitlines():
        if line.startswith("version="):
            return line.split("=", 1)[1].strip().strip("'\"")
    return None


def check_yade():
    """Raise a one-line ToolError when YADE or Debian's python3 is missing."""
    if not (Path(DEBIAN_PYTHON).is_file() and (Path(YADE_PY_PATH) / "yade").is_dir()):
        raise ToolError("YADE is not installed (Debian package 'yade'): run 'make setup'")


def wall_limit_s(t_max):
    """Wall-clock limit (s) of a run simulating ``t_max`` seconds."""
    return STARTUP_ALLOWANCE_S + t_max / MIN_SIM_S_PER_WALL_S


def _die_with_parent():
    libc = ctypes.CDLL("libc.so.6", use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # the parent decides about Ctrl-C


def run_yade(run_dir, timeout_s=None):
    """Run ``run_dir/scene.py``; return its :class:`~pipeline.outcome.Trajectory`.

    The log goes to ``run_dir/yade.log``.  Failure or timeout raises YadeError.
    """
    check_yade()
    run_dir = Path(run_dir)
    out = run_dir / "trajectory.npz"
    out.unlink(missing_ok=True)
    if timeout_s is None:
        import json
        timeout_s = wall_limit_s(json.loads((run_dir / "params.json").read_text())["t_max"])
    env = dict(os.environ, OMP_NUM_THREADS="1", YADE_PY_PATH=YADE_PY_PATH)
    env.pop("PYTHONPATH", None)
    env.pop("VIRTUAL_ENV", None)
    start = time.perf_counter()
    with open(run_dir / "yade.log", "w") as log:
        proc = subprocess.Popen([DEBIAN_PYTHON, str(WRAPPER), "scene.py"], cwd=run_dir,
                                stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                env=env, start_new_session=True, preexec_fn=_die_with_parent)
        with _RUNNING_LOCK:
            _RUNNING.add(proc)
        try:
            code = proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            _kill(proc)
            raise YadeError(f"YADE exceeded its wall-clock limit of {timeout_s:.0f} s; "
                            f"see {run_dir / 'yade.log'}") from None
        except BaseException:
            _kill(proc)
            raise
        finally:
            with _RUNNING_LOCK:
                _RUNNING.discard(proc)
    wall = time.perf_counter() - start
    if code < 0:
        raise YadeError(f"YADE was stopped by signal {-code}; see {run_dir / 'yade.log'}")
    if code != 0 or not out.exists():
        tail = (run_dir / "yade.log").read_text(errors="replace").strip().splitlines()[-1:]
        raise YadeError(f"YADE failed (exit {code}): {' '.join(tail)[:200]}; "
                        f"see {run_dir / 'yade.log'}")
    return Trajectory.load(out, wall_s=wall)


def kill_running():
    """Kill every YADE process this process started (Ctrl-C of a campaign)."""
    with _RUNNING_LOCK:
        procs = list(_RUNNING)
    for proc in procs:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def _kill(proc):
    """Kill the child's whole process group and reap it."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()
