"""The Dask executor: tasks carry their inputs, a campaign on an existing cluster gives the
local run's ids and outcomes, a killed worker loses no finished result, Ctrl-C stops it."""
import json
import signal
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import pandas as pd
import psutil
import pytest

from pipeline import cli
from pipeline.campaign.dask_worker import run_task, worker_code_version
from pipeline.campaign.dask_worker import TASK_PREFIX
from pipeline.campaign.spec import RunSpec
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse
from pipeline.scenario import RunParams

PROJECT = Path(__file__).resolve().parents[2]
DASK = Path(sys.executable).parent / "dask"


def pulse_npz(path, azimuth_deg, amplitude=5.0, duration=5.0):
    """A processed one-sine pulse motion (strong enough to topple the twin model)."""
    m = one_sine_pulse(azimuth_deg, amplitude, duration=duration)
    return Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": path.stem}).save(path)


# ---------------------------------------------------------------- the task, without YADE
@dataclass(frozen=True)
class Failing:
    """A test campaign's tags: whether the fake run fails."""
    fail: bool


def fake_worker(spec, run_dir):
    """Stands in for run_column_spec: reads the motion, writes what a run writes."""
    motion = Motion.load(spec.motion_file)
    (run_dir / "trajectory.npz").write_bytes(b"trajectory")
    (run_dir / "yade.log").write_text(f"ran in {run_dir}\n")
    if spec.tags is not None and spec.tags.fail:
        raise RuntimeError(f"boom; see {run_dir / 'yade.log'}")
    (run_dir / "summary.json").write_text(json.dumps(
        {"record": motion.record_id, "parameters": {"motion_file": spec.motion_file},
         "log": str(run_dir / "yade.log")}))


def test_task_carries_its_motion_and_returns_files_with_client_paths(tmp_path):
    data = pulse_npz(tmp_path / "a.npz", 0.0).read_bytes()
    spec = RunSpec("a", "a", "/client/only/a.npz", RunParams(), "r1")     # not here
    code, client_dir = worker_code_version(), "/client/camp/runs/r1"
    result = run_task(fake_worker, spec, data, client_dir, code, "t0")
    assert result["error"] is None
    assert sorted(result["files"]) == ["summary.json", "trajectory.npz", "yade.log"]
    summary = json.loads(result["files"]["summary.json"])
    assert summary["record"] == "a"
    assert summary["parameters"]["motion_file"] == "/client/only/a.npz"
    assert summary["log"] == client_dir + "/yade.log"
    lean = run_task(fake_worker, replace(spec, keep_trajectory=False), data, client_dir, code, "t0")
    assert sorted(lean["files"]) == ["summary.json"]
    failed = run_task(fake_worker, replace(spec, tags=Failing(True)), data, client_dir, code, "t0")
    assert failed["message"] == f"boom; see {client_dir}/yade.log"
    assert sorted(failed["files"]) == ["yade.log"]          # logs, no summary, no npz
    assert not list(Path(tempfile.gettempdir()).glob(f"{TASK_PREFIX}-t0-*"))
    with pytest.raises(Exception, match="other code"):
        run_task(fake_worker, spec, data, client_dir, "0" * 16, "t0")


# ---------------------------------------------------------------- a real cluster on 127.0.0.1
def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """`dask scheduler` and `dask worker --nthreads 1` processes on 127.0.0.1."""

    def __init__(self, directory):
        self.directory, self.port = directory, free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.processes = []

    def start(self, *args):
        with open(self.directory / f"dask{len(self.processes)}.log", "w") as log:
            proc = subprocess.Popen([str(DASK), *args], cwd=PROJECT, stdout=log,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                    start_new_session=True)
        self.processes.append(proc)
        return proc

    # Should the test process die before its finaliser: the scheduler ends after 2 idle
    # minutes, its workers 30 s after losing it.
    def scheduler(self):
        return self.start("scheduler", "--host", "127.0.0.1", "--port", str(self.port),
                          "--no-dashboard", "--dashboard-address", "127.0.0.1:0",
                          "--idle-timeout", "120s")

    def worker(self):
        return self.start("worker", self.address, "--nthreads", "1", "--no-nanny",
                          "--host", "127.0.0.1", "--no-dashboard",
                          "--dashboard-address", "127.0.0.1:0", "--death-timeout", "30s",
                          "--local-directory", str(self.directory))

    def wait_for_workers(self, n, timeout_s=60):
        from distributed import Client
        with Client(self.address, timeout=timeout_s) as client:
            client.wait_for_workers(n, timeout=timeout_s)

    def stop(self):
        """Kill every process started (a worker's YADE children die with it)."""
        for proc in reversed(self.processes):
            if proc.poll() is None:
                proc.kill()
            proc.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    cluster = Cluster(tmp_path_factory.mktemp("dask"))
    try:
        cluster.scheduler()
        cluster.worker()
        cluster.worker()
        cluster.wait_for_workers(2)
        yield cluster
    finally:
        cluster.stop()


def scene_processes(cluster):
    """{pid: (worker pid, working directory)} of the scene processes (run_scene.py) that
    the cluster's live worker processes started, running or idle (psutil): not those of
    tests running beside (pytest-xdist)."""
    found = {}
    for worker in cluster.processes:
        if worker.poll() is not None:
            continue
        try:
            children = psutil.Process(worker.pid).children()
        except psutil.NoSuchProcess:
            continue
        for child in children:
            try:
                if any("run_scene.py" in part for part in child.cmdline()):
                    found[child.pid] = (worker.pid, child.cwd())
            except (psutil.NoSuchProcess, psutil.AccessDenied):
                continue
    return found


def task_yade_processes(cluster):
    """{pid: worker pid} of the cluster's scene processes running in a Dask task's
    temporary directory."""
    return {pid: worker for pid, (worker, cwd) in scene_processes(cluster).items()
            if f"/{TASK_PREFIX}-" in cwd}


def worker_yade_processes(cluster):
    """pids of the cluster's scene processes, running or idle."""
    return list(scene_processes(cluster))


def wait_for(condition, seconds):
    """Poll ``condition`` every 0.05 s until it holds or ``seconds`` (s) pass (a bound)."""
    deadline = time.monotonic() + seconds
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.05)


def campaign_args(records, out, *extra):
    return ["campaign", "records", "--records", ",".join(map(str, records)), "--out", str(out),
            "--animations", "0", *extra]


def cli_process(*args):
    return subprocess.Popen([sys.executable, "-m", "pipeline", *args], cwd=PROJECT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def run_ids(out):
    return sorted(p.parent.name for p in out.glob("runs/*/summary.json"))


@pytest.mark.yade
def test_a_campaign_on_a_cluster_gives_the_local_run_ids_and_outcomes(tmp_path, cluster,
                                                                        capsys):
    records = [pulse_npz(tmp_path / "a.npz", 0.0), pulse_npz(tmp_path / "b.npz", 90.0)]
    local, remote = tmp_path / "local", tmp_path / "remote"
    assert cli.main(campaign_args(records, local, "--jobs", "2")) == 0
    assert cli.main(campaign_args(records, remote, "--scheduler", cluster.address)) == 0
    assert run_ids(remote) == run_ids(local) and len(run_ids(local)) == 2
    a, b = pd.read_csv(local / "runs.csv"), pd.read_csv(remote / "runs.csv")
    pd.testing.assert_frame_equal(a, b)              # same outcomes, paths and parameters
    assert b["toppled"].all()
    pd.testing.assert_frame_equal(pd.read_parquet(remote / "runs.parquet"), b,
                                  check_dtype=False)
    for run_id in run_ids(local):                    # the same files in each run directory
        files = sorted(p.name for p in (local / "runs" / run_id).iterdir())
        assert sorted(p.name for p in (remote / "runs" / run_id).iterdir()) == files
        assert "trajectory.npz" in files
    # resume by run id: nothing left to run
    assert cli.main(campaign_args(records, remote, "--scheduler", cluster.address)) == 0
    assert "2 already done, 0 to run" in capsys.readouterr().out


@pytest.mark.yade
def test_a_worker_runs_its_tasks_in_one_yade_process_and_keeps_none_after(tmp_path, cluster):
    records = [pulse_npz(tmp_path / f"p{k}.npz", 20.0 * k, duration=2.0) for k in range(6)]
    out = tmp_path / "camp"
    assert cli.main(campaign_args(records, out, "--scheduler", cluster.address)) == 0
    served = [int(line.split("process ")[1].split(",")[0])
              for log in out.glob("runs/*/yade.log")
              for line in log.read_text().splitlines()[:1]
              if line.startswith("run_scene.py --serve: process ")]
    assert len(served) == 6
    assert len(set(served)) <= 2                     # two workers: one YADE process each
    wait_for(lambda: not worker_yade_processes(cluster), 5)
    assert not worker_yade_processes(cluster), "idle YADE processes outlived the campaign"


@pytest.mark.yade
def test_ctrl_c_on_a_cluster_stops_and_kills_its_runs(tmp_path, cluster):
    """Ctrl-C ends the campaign on a cluster (the bound catches a hang; make bench,
    section 10, measures the time) and its runs on the workers."""
    records = [pulse_npz(tmp_path / f"p{k}.npz", 45.0 * k, duration=20.0) for k in range(2)]
    out = tmp_path / "camp"
    proc = cli_process(*campaign_args(records, out, "--scheduler", cluster.address))
    wait_for(lambda: task_yade_processes(cluster), 60)
    assert task_yade_processes(cluster), "no YADE run started on the workers"
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
    assert time.monotonic() - sent < 30.0
    assert proc.returncode == 130
    assert json.loads((out / "campaign.json").read_text())["interrupted"] is True
    wait_for(lambda: not task_yade_processes(cluster), 5)
    assert not task_yade_processes(cluster), "the workers kept running the interrupted campaign"


@pytest.mark.yade
def test_a_killed_worker_loses_no_finished_result(tmp_path, cluster):
    victim = cluster.worker()                         # a third worker, killed mid-campaign
    cluster.wait_for_workers(3)
    records = [pulse_npz(tmp_path / f"p{k}.npz", 30.0 * k) for k in range(6)]
    out = tmp_path / "camp"
    proc = cli_process(*campaign_args(records, out, "--scheduler", cluster.address))

    def ready():        # a result is in, and the third worker runs YADE
        return (any(out.glob("runs/*/summary.json"))
                and victim.pid in task_yade_processes(cluster).values())

    wait_for(ready, 90)
    assert ready(), "no result, or the third worker runs nothing"
    finished = {p.parent.name: p.read_bytes() for p in out.glob("runs/*/summary.json")}
    victim.send_signal(signal.SIGKILL)
    victim.wait()
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert len(run_ids(out)) == 6
    for run_id, summary in finished.items():         # finished results kept as they were
        assert (out / "runs" / run_id / "summary.json").read_bytes() == summary
    assert len(pd.read_csv(out / "runs.csv")) == 12  # 6 runs x 2 columns
    assert not task_yade_processes(cluster)
