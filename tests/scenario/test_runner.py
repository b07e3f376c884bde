"""The runner's reused YADE processes (campaign threads): the same trajectory to the last
bit as a fresh process, failures and timeouts that leave the next scene unharmed, and no
process left behind."""
import contextlib
import os
import re
import threading
import time

import numpy as np
import pytest

from pipeline.motion.pulses import one_sine_pulse
from pipeline.scenario import Column, YadeError, run_yade, scene_params, write_scenario
from pipeline.scenario import runner

pytestmark = pytest.mark.yade


def scene(path, amplitude=6.0):
    """A monolith under a short one-sine pulse: a scene directory."""
    motion = one_sine_pulse(30.0, amplitude, 0.8, 2.0)
    params = scene_params(columns=Column("monolithic").specs(),
                          motion_duration=motion.duration)
    write_scenario(path, params, motion)
    return path


def same(a, b):
    return all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("t", "pos", "quat"))


def gone(pid, within_s=5.0):
    """True when process ``pid`` has exited (and been reaped) within ``within_s``."""
    end = time.monotonic() + within_s
    while time.monotonic() < end:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        try:
            with open(f"/proc/{pid}/stat") as f:    # a zombie waits for its parent's wait()
                if f.read().split()[2] == "Z":
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


def test_served_scenes_match_a_fresh_process_and_end_with_the_block(tmp_path):
    fresh = run_yade(scene(tmp_path / "fresh"))
    with runner.reuse_processes():
        served = [run_yade(scene(tmp_path / f"s{k}")) for k in range(3)]
        pid = runner._SERVED.proc.pid
    assert all(same(fresh, s) for s in served)
    assert gone(pid) and not runner._RUNNING


def test_a_served_scene_may_live_in_a_directory_of_any_name(tmp_path):
    odd = tmp_path / "it's \"odd\" ; $(x) \u00f6 \udcff"     # quotes, shell, UTF-8, raw 0xff
    with runner.reuse_processes():
        served = run_yade(scene(odd))
    assert same(served, run_yade(scene(tmp_path / "plain")))


def test_a_failing_scene_leaves_the_next_one_unharmed(tmp_path):
    bad = scene(tmp_path / "bad")
    (bad / "scene.py").write_text("raise RuntimeError('a broken scene')\n")
    with runner.reuse_processes():
        with pytest.raises(YadeError, match="a broken scene"):
            run_yade(bad)
        pid = runner._SERVED.proc.pid
        ok = run_yade(scene(tmp_path / "ok"))
        assert runner._SERVED.proc.pid == pid          # the same process ran both
    assert same(ok, run_yade(scene(tmp_path / "fresh")))


def test_a_hung_scene_is_killed_and_the_next_gets_a_new_process(tmp_path):
    hung = scene(tmp_path / "hung")
    (hung / "scene.py").write_text("import time\ntime.sleep(60)\n")
    with runner.reuse_processes():
        run_yade(scene(tmp_path / "first"))
        pid = runner._SERVED.proc.pid
        started = time.monotonic()
        with pytest.raises(YadeError, match="wall-clock limit of 2 s"):
            run_yade(hung, timeout_s=2.0)
        assert time.monotonic() - started < 10 and gone(pid)
        run_yade(scene(tmp_path / "next"))
        assert runner._SERVED.proc.pid != pid


def test_a_threads_process_dies_with_its_thread(tmp_path):
    pids = []

    def work():
        run_yade(scene(tmp_path / "in_thread"))
        pids.append(runner._SERVED.proc.pid)

    with runner.reuse_processes():
        thread = threading.Thread(target=work)
        thread.start()
        thread.join()
        assert pids and gone(pids[0])                  # PR_SET_PDEATHSIG of its thread


def test_a_kept_process_serves_the_next_block_and_ends_when_told_or_idle(tmp_path, monkeypatch):
    """Dask tasks keep their thread's process (end=False); end_served_processes ends it,
    and a process left alone ends itself after SERVE_IDLE_S without a scene."""
    with runner.reuse_processes(end=False):
        run_yade(scene(tmp_path / "a"))
    first = runner._SERVED.proc.pid
    with runner.reuse_processes(end=False):
        run_yade(scene(tmp_path / "b"))
    assert runner._SERVED.proc.pid == first and not gone(first, within_s=0.2)
    log = (tmp_path / "b" / "yade.log").read_text()
    assert f"process {first}, scene 2" in log                   # its second scene
    assert os.readlink(f"/proc/{first}/cwd") == "/"             # holds no run directory
    assert runner.end_served_processes() == 1 and gone(first)
    assert not runner._RUNNING

    monkeypatch.setattr(runner, "SERVE_IDLE_S", 2.0)
    with runner.reuse_processes(end=False):
        run_yade(scene(tmp_path / "c"))
    idle = runner._SERVED.proc.pid
    assert gone(idle, within_s=8.0)                             # no one told it: idle limit
    with runner.reuse_processes(end=False):                     # the next scene: a new one
        run_yade(scene(tmp_path / "d"))
    assert runner._SERVED.proc.pid != idle
    runner.end_served_processes()


def test_yade_processes_leave_no_temporary_directory(tmp_path, monkeypatch):
    """YADE makes /tmp/yade-XXXXXX per process and keeps it when killed: the runner
    removes it when the process ends, fresh or served (ended by a kill)."""
    import glob
    import tempfile
    scratch = tmp_path / "notes"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    made = []
    real = runner._remove_tmp

    def spy(note_dir):
        note = os.path.join(note_dir, "yade_tmp_dir")
        made.append(open(note).read().strip() if os.path.exists(note) else None)
        real(note_dir)

    monkeypatch.setattr(runner, "_remove_tmp", spy)
    run_yade(scene(tmp_path / "fresh"))
    with runner.reuse_processes():
        run_yade(scene(tmp_path / "served"))
    noted = [m for m in made if m]
    assert len(noted) >= 2 and all(m.startswith("/tmp/yade-") for m in noted), made
    assert not any(glob.glob(m) for m in noted)
    assert list(scratch.iterdir()) == []


@pytest.mark.parametrize("served", [False, True])
def test_stopped_scenes_are_killed_and_those_not_started_are_refused(tmp_path, monkeypatch,
                                                                     served):
    """Ctrl-C of a Dask campaign on a worker: the scenes under the campaign's mark die at
    once (SIGKILL; SIGTERM as soon as YADE has started in a process that was starting it:
    it removes its temporary directory), a scene not yet started is refused, and other
    scenes run on."""
    monkeypatch.setattr(runner, "_STOPPED", set())
    running = scene(tmp_path / "mark-1" / "running")
    (running / "scene.py").write_text("import time\ntime.sleep(60)\n")
    errors = []

    def work():
        try:
            run_yade(running, timeout_s=60.0)
        except YadeError as exc:
            errors.append(str(exc))

    with runner.reuse_processes() if served else contextlib.nullcontext():
        thread = threading.Thread(target=work)
        thread.start()
        deadline = time.monotonic() + 30
        while not any(getattr(p, "run_dir", "") == str(running) for p in list(runner._RUNNING)):
            assert time.monotonic() < deadline, "the scene did not start"
            time.sleep(0.02)
        started = time.monotonic()
        pids = runner.stop_scenes("/mark-1/")
        thread.join(timeout=30)
        assert not thread.is_alive() and time.monotonic() - started < 10
        assert len(pids) == 1 and gone(pids[0])
        assert errors and re.search("stopped by signal (9|15);", errors[0]), errors
        with pytest.raises(YadeError, match="not run, its campaign was stopped"):
            run_yade(scene(tmp_path / "mark-1" / "later"))
        assert not (tmp_path / "mark-1" / "later" / "yade.log").exists()
        assert same(run_yade(scene(tmp_path / "mark-2" / "other")),
                    run_yade(scene(tmp_path / "fresh")))
