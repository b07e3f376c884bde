"""Shared file helpers: the input-error type, atomic writes, content and code hashes,
and the software versions recorded as provenance.

Every result file is written to a temporary file in the same directory and
renamed into place, so an interrupted run never leaves a partial result.
"""
import ctypes
import hashlib
import io
import json
import logging
import math
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Collection, Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path

import numpy as np
from pipeline import PROJECT_ROOT

log = logging.getLogger(__name__)


class ToolError(Exception):
    """An error the command line reports as one line (exit status 1)."""


class InputError(ToolError):
    """Bad user input (missing file, wrong format, NaN, impossible parameter).

    The message is one line naming the problem; the CLI prints it and exits 2.
    """


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; rename it to ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())          # like any tool: honour the user's umask
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path, text):
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def json_text(obj) -> str:
    """``obj`` as the JSON text result files hold (indented; ValueError for a NaN or an
    infinity, which JSON cannot hold: serialised before any file of a set is written)."""
    return json.dumps(obj, indent=2, allow_nan=False, default=_json_default) + "\n"


def result_json_text(obj, name: str) -> str:
    """:func:`json_text` of a command's result ``name`` (e.g. constrain.json), made before
    any file of it is written: a NaN or an infinity in it is a ToolError naming its key
    (one line, nothing written), not a traceback after some files."""
    try:
        return json_text(obj)
    except ValueError:
        where = _non_finite(obj)
        if where is None:
            raise
        raise ToolError(f"{name}: {where} is not a finite number; nothing written (please "
                        "report this with the command that gave it)") from None


def _non_finite(obj, path="") -> str | None:
    """The key path of the first NaN or infinity in ``obj``, or None."""
    if isinstance(obj, dict):
        items = ((f"{path}.{k}" if path else str(k), v) for k, v in obj.items())
    elif isinstance(obj, (list, tuple, np.ndarray)):
        items = ((f"{path}[{k}]", v) for k, v in enumerate(obj))
    else:
        is_number = isinstance(obj, (float, np.floating))
        return (path or "the value") if is_number and not math.isfinite(obj) else None
    return next((found for key, value in items
                 if (found := _non_finite(value, key)) is not None), None)


def write_json(path, obj):
    write_text(path, json_text(obj))


def write_npz(path, **arrays):
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    with atomic_path(path) as tmp:
        tmp.write_bytes(buf.getvalue())


def write_csv(path, frame):
    """Write a pandas DataFrame atomically (no index)."""
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, index=False)


def save_figure(fig, path, **kwargs):
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip("."), **kwargs)


@contextmanager
def file_set(directory: Path, names: Collection[str],
             summaries: Sequence[str]) -> Iterator[Path]:
    """Yield an empty staging directory inside ``directory`` in which a command writes
    its set of result files (each named in ``names``, every file name the command
    writes); when the block ends without an exception the set replaces the command's
    files in ``directory``: those of ``names`` the set does not hold are removed (no
    earlier result is left beside the new one), the others replaced, and the
    ``summaries`` (the files that say what the set is) removed first and renamed in
    last, with Ctrl-C and SIGTERM held until that is done: a reader who finds a summary
    finds the whole set it names.  Files of other names are left alone.  An exception
    in the block leaves ``directory`` as it was (removed when the block made it and it
    is empty)."""
    directory = Path(directory)
    made = not directory.exists()
    directory.mkdir(parents=True, exist_ok=True)
    _remove_stale_stages(directory)
    stage = Path(tempfile.mkdtemp(prefix=f".staging.{os.getpid()}.", suffix=".tmp",
                                  dir=directory))
    try:
        yield stage
        written = {p.name for p in stage.iterdir()}
        if not written <= set(names):
            raise ValueError(f"files outside the set {sorted(names)}: "
                             f"{sorted(written - set(names))}")
        last = [n for n in summaries if n in names]
        with _signals_held():
            for name in [*last, *(n for n in names if n not in last)]:
                if name not in written:
                    (directory / name).unlink(missing_ok=True)
            for name in [*(n for n in names if n not in last), *last]:
                if name in written:
                    os.replace(stage / name, directory / name)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        if made:
            with suppress(OSError):
                directory.rmdir()
        raise
    shutil.rmtree(stage, ignore_errors=True)


def _remove_stale_stages(directory: Path) -> None:
    """Remove the staging directories in ``directory`` whose process is gone (a command
    killed with SIGKILL cannot remove its own)."""
    for stage in directory.glob(".staging.*.tmp"):
        pid = stage.name.split(".")[2]
        if pid.isdigit() and not _process_alive(int(pid)):
            shutil.rmtree(stage, ignore_errors=True)


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM for the block (in the main thread; elsewhere nothing to
    hold): a signal that comes meanwhile is raised again after it, to the handler that
    was in place."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    before = {s: signal.signal(s, lambda signum, frame: pending.append(signum)) for s in held}
    try:
        yield
    finally:
        for signum, handler in before.items():
            signal.signal(signum, handler)
        for signum in pending[:1]:
            signal.raise_signal(signum)


def read_run_json(path, what):
    """(path, data) of a run's JSON file: ``path`` itself or ``summary.json`` in the run
    directory ``path``; a one-line InputError naming the file and ``what`` it should be."""
    path = Path(path)
    if path.is_dir():
        path = path / "summary.json"
    try:
        return path, json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"{what} not found: {path}") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a {what} ({exc})") from None


def content_hash(*parts):
    """Hex digest (16 chars) of JSON-serialisable parts and file contents (Path)."""
    h = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path):
            h.update(part.read_bytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=_json_default).encode())
    return h.hexdigest()[:16]


def code_hash(*packages):
    """Hex digest (16 chars) of every ``*.py`` file under the named sub-packages or
    modules of :mod:`pipeline` (e.g. ``"scenario", "simulate"``), else of project
    directories (``"yade_scripts"``): it changes whenever the code of a stage changes."""
    h = hashlib.sha256()
    for name in packages:
        package = PROJECT_ROOT / "pipeline" / name
        base = package if package.is_dir() or package.with_suffix(".py").is_file() \
            else PROJECT_ROOT / name
        paths = sorted(base.rglob("*.py")) if base.is_dir() else [base.with_suffix(".py")]
        if not paths or not all(p.is_file() for p in paths):
            raise FileNotFoundError(f"no code found for {name!r}")
        for path in paths:
            h.update(str(path.relative_to(PROJECT_ROOT)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


class DirectoryLock:
    """Exclusive lock of a directory (``DIR/.lock``, ``flock``) for the duration of a
    ``with`` block.  A second user waits (``wait=True``) or gets a one-line
    InputError.  The kernel releases the lock when its holder dies: no stale locks.
    The open descriptor (``fd``) can be passed to a child process to share the lock.
    """

    def __init__(self, directory, wait=False):
        self.directory, self.wait, self.fd = Path(directory), wait, None

    def __enter__(self):
        import fcntl  # lazy: POSIX only
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except (FileExistsError, NotADirectoryError):
            raise InputError(f"{self.directory} exists and is not a directory") from None
        except PermissionError:
            raise InputError(f"{self.directory}: not writable") from None
        path = self.directory / ".lock"
        try:
            self.fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except PermissionError:
            raise InputError(f"{self.directory}: not writable") from None
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | (0 if self.wait else fcntl.LOCK_NB))
        except BlockingIOError:
            os.close(self.fd)
            raise InputError(f"{self.directory} is in use by another run or campaign; "
                             "wait for it to finish") from None
        return self

    def __exit__(self, *exc):
        os.close(self.fd)
        self.fd = None
        return False


def check_out_file(path, flag="--out"):
    """InputError (one line) unless a file can be written at ``path``: not a directory,
    its nearest existing folder a writable directory (checked before any work)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{flag} {path} is a directory, not a file")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"{flag} {path}: {folder} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{flag} {path}: {folder} is not writable")


def display_path(path):
    """``path`` as people read it: relative to the project when inside it."""
    try:
        return str(Path(path).resolve().relative_to(PROJECT_ROOT))
    except ValueError:
        return str(path)


def check_jobs(jobs):
    """The number of parallel processes a ``--jobs`` option asks for: None is every core;
    InputError below 1."""
    if jobs is not None and jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {jobs}")
    return jobs or os.cpu_count() or 1


LONG_RUN_S = 3600.0     # a command estimated to take longer here needs --allow-long


def check_long(what, runs, run_core_s, jobs, allow_long, advice="", unit="runs"):
    """The gate of every long command (campaigns, invert, synthetics), before any run:
    ``runs`` runs (``unit``: what one is) of ``run_core_s`` core seconds each (the
    command's own cost model) on ``jobs`` cores.  InputError when that is over LONG_RUN_S
    and ``allow_long`` is False; a warning line when it is over and allowed.  Returns the
    estimate (wall s)."""
    estimate = runs * run_core_s / max(jobs, 1)
    if estimate <= LONG_RUN_S:
        return estimate
    said = (f"{what} ({runs} {unit}, {run_core_s:.3g} core-s each) would take about "
            f"{duration_text(estimate)} on {jobs} core(s)")
    if not allow_long:
        raise InputError(f"{said}, over {LONG_RUN_S / 3600:g} h: add --allow-long to start "
                         "it" + (f", or {advice}" if advice else ""))
    log.warning(f"{said} (--allow-long)")
    return estimate


def duration_text(seconds):
    """'40 min', '2.5 h', '3.0 d': a wall time as people say it."""
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} d"


def die_with_parent(parent_pid=None, death_signal=signal.SIGKILL):
    """In a child process (``preexec_fn``, a Pool's ``initializer``): be killed when the
    parent dies, even by kill -9 (Linux PR_SET_PDEATHSIG, sending ``death_signal``), and
    leave Ctrl-C and SIGTERM handling to the parent (a Pool's workers take SIGTERM as
    plain processes do).  ``parent_pid``: the parent's pid, taken in the parent before
    the fork: a child whose parent died before the death signal was armed (a kill in
    between) exits at once."""
    ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, death_signal)   # 1: PR_SET_PDEATHSIG
    if parent_pid is not None and os.getppid() != parent_pid:
        os._exit(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def csv_true(value):
    """True for a boolean read back from a CSV cell or a JSON value: True, numpy's True
    or the text "true" in any case; False for anything else (False, "", NaN, None)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    return isinstance(value, str) and value.strip().lower() == "true"


def csv_number(value):
    """A number read back from a CSV cell or a JSON value as a float; NaN for a missing or
    unreadable one (None, "", text)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def finite_number(value, name, minimum=-math.inf):
    """``value`` as a finite float >= ``minimum`` (None stays None: not known); else an
    InputError naming ``name``."""
    if value is None:
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(value) and value >= minimum):
        bound = "" if minimum == -math.inf else f" >= {minimum:g}"
        raise InputError(f"{name} must be a finite number{bound}, got {value!r}")
    return value


def csv_true_column(series):
    """:func:`csv_true` of every cell of a pandas Series (a bool Series)."""
    return series.map(csv_true).astype(bool)


def json_safe(obj):
    """JSON-safe copy: NaN / inf -> None, numpy scalars -> Python."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj
