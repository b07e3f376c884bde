# Run a generated YADE scene with YADE imported as a Python module.
#
#     /usr/bin/python3 run_scene.py DIR/scene.py
#     /usr/bin/python3 run_scene.py --serve FD IDLE_S   (campaigns: one process, many scenes)
#
# Unlike the `yade` launcher this opens no network port (the launcher serves a
# Python prompt on 0.0.0.0:9000 and an info server on 0.0.0.0:21000) and saves
# the launcher's start-up.  YADE's compiled module is built for Debian's python3
# and its numpy, so this runs under /usr/bin/python3, not the project's venv.
# `yade -n -x scene.py` still runs the same scene on its own.
#
# --serve: read scene directories from stdin, one per line; for each, reset YADE,
# run DIR/scene.py with stdout and stderr in DIR/yade.log, and answer its exit code
# as one line on file descriptor FD (a pipe from the parent).  YADE's start-up (about
# 1 s) is paid once per process instead of once per scene.  The process ends by itself
# after IDLE_S seconds without a scene (a Dask worker keeps it between tasks; should its
# campaign's client vanish, nothing stays behind for long) or when stdin closes.
import ctypes
import os
import runpy
import select
import shutil
import signal
import sys
import traceback

YADE_PY = os.environ.get("YADE_PY_PATH", "/usr/lib/x86_64-linux-gnu/yade-double/py")
sys.path.insert(1, YADE_PY)


def run(scene):
    """Run one scene file as __main__ (it reads and writes next to itself)."""
    scene = os.path.abspath(scene)
    sys.argv = [scene]
    runpy.run_path(scene, run_name="__main__")


def lines(fd, idle_s):
    """Lines read from ``fd`` (decoded, without newline) until it closes or stays silent
    for ``idle_s`` seconds."""
    buffer = b""
    while True:
        while b"\n" not in buffer:
            ready, _, _ = select.select([fd], [], [], idle_s)
            chunk = os.read(fd, 65536) if ready else b""
            if not chunk:
                return
            buffer += chunk
        line, buffer = buffer.split(b"\n", 1)
        yield os.fsdecode(line)


def serve(control_fd, idle_s):
    from yade import O
    control = os.fdopen(control_fd, "w", buffering=1)
    quiet = os.open(os.devnull, os.O_WRONLY)
    for scene_number, run_dir in enumerate(lines(sys.stdin.fileno(), idle_s), 1):
        sys.stdout.flush()
        sys.stderr.flush()
        log = os.open(os.path.join(run_dir, "yade.log"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC,
                      0o666)
        os.dup2(log, 1)
        os.dup2(log, 2)
        os.close(log)
        print(f"run_scene.py --serve: process {os.getpid()}, scene {scene_number}", flush=True)
        code = 0
        try:
            os.chdir(run_dir)
            O.reset()
            run(os.path.join(run_dir, "scene.py"))
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except BaseException:
            traceback.print_exc()
            code = 1
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(quiet, 1)
        os.dup2(quiet, 2)
        os.chdir("/")                 # hold no run directory (it may be a temporary one)
        control.write(f"{code}\n")


def start_yade():
    """Import YADE, which makes /tmp/yade-XXXXXX for this process (a fixed path: not
    TMPDIR) and removes it only at a normal exit, and leave no such directory behind:

    - it is noted in the directory named by TOPPLING_YADE_NOTE_DIR (file
      ``yade_tmp_dir``), from which the parent removes it after it killed this process
      with SIGKILL (or, should the parent be gone too, the next run);
    - SIGTERM, the parent's stop before the note exists and the death signal this
      process gets should its parent die meanwhile, waits for the import (blocked):
      then this process removes the directory itself and ends by that SIGTERM.
    """
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})   # YADE's threads inherit it
    parent = os.getppid()
    import yade  # noqa: F401  (boots YADE: plugins, O)
    from yade import O
    made = os.path.dirname(O.tmpFilename())
    note_dir = os.environ.get("TOPPLING_YADE_NOTE_DIR")
    if note_dir:
        try:
            with open(os.path.join(note_dir, "yade_tmp_dir.part"), "w") as note:
                note.write(made)
            os.replace(os.path.join(note_dir, "yade_tmp_dir.part"),
                       os.path.join(note_dir, "yade_tmp_dir"))
        except OSError:            # removed: the parent is gone, and its next run was here
            pass
    ctypes.CDLL("libc.so.6").prctl(1, signal.SIGKILL)    # 1: PR_SET_PDEATHSIG; noted now
    if signal.SIGTERM in signal.sigpending() or os.getppid() != parent:
        shutil.rmtree(made, ignore_errors=True)
        if note_dir:
            shutil.rmtree(note_dir, ignore_errors=True)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})   # ends here
        os._exit(1)                                                    # (parent gone)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})


if __name__ == "__main__":
    start_yade()
    if sys.argv[1] == "--serve":
        serve(int(sys.argv[2]), float(sys.argv[3]))
    else:
        run(sys.argv[1])
