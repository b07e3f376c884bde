"""Reliability: every bad input one line, no silent wrong result, no orphan, no open port."""
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import psutil
import pytest
from obspy import Stream, Trace

from pipeline import cli
from pipeline.files import check_jobs
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse
from pipeline.scenario.runner import TMP_PREFIX

PROJECT = Path(__file__).resolve().parents[2]


def wavelet(azimuth_deg, peak_disp=0.4, freq=0.5, width=1.5, rate=100.0, duration=12.0):
    """(n, 3) acceleration of d(t) = D exp(-((t-t0)/w)^2) sin(2 pi f (t-t0)) along an azimuth:
    a strong two-sided displacement pulse (no permanent offset), PGA ~ (2 pi f)^2 D."""
    t = np.arange(0, duration, 1 / rate) - duration / 2
    g = np.exp(-(t / width) ** 2)
    gp, gpp = -2 * t / width ** 2 * g, (4 * t ** 2 / width ** 4 - 2 / width ** 2) * g
    w = 2 * np.pi * freq
    s, sp, spp = np.sin(w * t), w * np.cos(w * t), -w ** 2 * np.sin(w * t)
    acc = peak_disp * (gpp * s + 2 * gp * sp + g * spp)
    u = np.array([np.sin(np.radians(azimuth_deg)), np.cos(np.radians(azimuth_deg)), 0.0])
    return acc[:, None] * u


def write_mseed(path, azimuth_deg, amplitude=0.4, rate=100.0, nan=False, rates=None):
    """A strong displacement pulse (``amplitude`` m) along ``azimuth_deg`` as MiniSEED."""
    acc = wavelet(azimuth_deg, amplitude, rate=rate)
    traces = []
    for i, code in enumerate("ENZ"):
        data = acc[:, i].copy()
        if nan:
            data[50] = np.nan
        r = rates[i] if rates else rate
        traces.append(Trace(data, header={"station": "T", "channel": f"HN{code}",
                                          "sampling_rate": r}))
    path.parent.mkdir(parents=True, exist_ok=True)
    Stream(traces).write(str(path), format="MSEED")
    return path


def write_motion_npz(path, azimuth_deg=0.0, amplitude=5.0, duration=5.0, **meta):
    m = one_sine_pulse(azimuth_deg, amplitude, duration=duration)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": path.stem, **meta}).save(path)
    return path


def at2(path, header_line4):
    path.write_text("PEER NGA STRONG MOTION DATABASE RECORD\nQuake, 1/1/2000, Sta, 90\n"
                    "ACCELERATION TIME SERIES IN UNITS OF G\n" + header_line4 + "\n"
                    + "\n".join(" 0.1 0.2 -0.1 0.0 0.05" for _ in range(170)) + "\n")
    return path


def bad_npz(path, **arrays):
    np.savez(path, **arrays)
    return path


# ---------------------------------------------------------------- bad inputs, one line each
def _two_rate_channel(d):
    t1 = Trace(np.zeros(500), header={"station": "T", "channel": "HNE", "sampling_rate": 100.0})
    t2 = Trace(np.zeros(500), header={"station": "T", "channel": "HNE", "sampling_rate": 50.0,
                                      "starttime": t1.stats.endtime + 1})
    Stream([t1, t2]).write(str(d / "rates.mseed"), format="MSEED")
    return d / "rates.mseed"


def _sac_bad_coordinates(d):
    from obspy.io.sac import SACTrace
    for ch, az, inc in (("HN1", 0.0, 90.0), ("HN2", 90.0, 90.0), ("HNZ", 0.0, 0.0)):
        SACTrace(data=np.random.default_rng(0).standard_normal(1000).astype(np.float32),
                 delta=0.01, kstnm="S", kcmpnm=ch, cmpaz=az, cmpinc=inc, stla=123.0, stlo=20.0,
                 evla=41.0, evlo=20.0).write(str(d / f"s.{ch}.sac"))
    return d / "s.*.sac"


def _dmg_impossible_time(d):
    from pipeline import RECORDS_DIR
    import gzip
    text = gzip.decompress((RECORDS_DIR / "ridgecrest2019/CI.CLC.V1.gz").read_bytes()).decode(
        "latin-1")
    lines = text.splitlines()
    import re
    lines[3] = re.sub(r"start time:\s*\d+/\d+/\d+", "Start time: 13/45/19", lines[3], flags=re.I)
    (d / "bad.v1").write_text("\n".join(lines) + "\n", encoding="latin-1")
    return d / "bad.v1"


FILE_CASES = {
    "missing file": (lambda d: d / "nothing.mseed", "no such file"),
    "wrong format": (lambda d: (d / "junk.mseed").write_bytes(b"hello" * 100) and d / "junk.mseed",
                     "junk.mseed"),
    "NaN samples": (lambda d: write_mseed(d / "nan.mseed", 0.0, nan=True), "NaN"),
    "one channel at two sampling rates": (_two_rate_channel, "rates.mseed"),
    "components at different rates": (lambda d: write_mseed(d / "r.mseed", 0.0,
                                                              rates=(100.0, 50.0, 100.0)),
                                       "sampling rates"),
    "AT2 DT = .": (lambda d: at2(d / "a.AT2", "NPTS=  850, DT= .    SEC"), "DT"),
    "AT2 DT = 0": (lambda d: at2(d / "b.AT2", "NPTS=  850, DT=   0.0000 SEC"), "DT"),
    "AT2 DT negative": (lambda d: at2(d / "c.AT2", "NPTS=  850, DT=  -0.0100 SEC"), "DT"),
    "V1 header with an impossible start time": (_dmg_impossible_time, "start time"),
    "SAC coordinates out of range": (_sac_bad_coordinates, "out of range"),
    "npz with bad meta": (lambda d: bad_npz(d / "m.npz", dt=0.01, acc=np.zeros((10, 3)),
                                            vel=np.zeros((10, 3)), disp=np.zeros((10, 3)),
                                            meta=np.array("{not json")), "meta"),
    "npz with 1-D arrays": (lambda d: bad_npz(d / "o.npz", dt=0.01, acc=np.zeros(10),
                                              vel=np.zeros(10), disp=np.zeros(10),
                                              meta=np.array("{}")), "(n, 3)"),
    "npz with dt 0": (lambda d: bad_npz(d / "z.npz", dt=0.0, acc=np.zeros((10, 3)),
                                        vel=np.zeros((10, 3)), disp=np.zeros((10, 3)),
                                        meta=np.array("{}")), "dt"),
}

PARAMETER_CASES = {
    "h/d zero": (["--hd", "0"], "--hd"), "h/d absurd": (["--hd", "1e6"], "--hd"),
    "height NaN": (["--height", "nan"], "--height"), "drums 1000": (["--drums", "1000"], "--drums"),
    "mu_s negative": (["--mu-s", "-0.1"], "--mu-s"),
    "mu_k above mu_s": (["--mu-s", "0.5", "--mu-k", "0.6"], "mu_k"),
    "kn zero": (["--kn", "0"], "--kn"), "damping 5": (["--damping", "5"], "--damping"),
    "dt factor -1": (["--dt-factor", "-1"], "--dt-factor"),
    "dt factor 0": (["--dt-factor", "0"], "--dt-factor"),
    "dt factor NaN": (["--dt-factor", "nan"], "--dt-factor"),
    "rim points 2": (["--rim-points", "2"], "--rim-points"),
    "window not finite": (["--window", "0", "inf"], "--window"),
    "window reversed": (["--window", "5", "2"], "--window"),
    "scale negative": (["--scale", "-1"], "--scale"), "scale NaN": (["--scale", "nan"], "--scale"),
    "rotate NaN": (["--rotate", "nan"], "--rotate"),
    "back azimuth 400": (["--back-azimuth", "400"], "--back-azimuth"),
    "back azimuth NaN": (["--back-azimuth", "nan"], "--back-azimuth"),
    "time step too coarse for the damping": (["--dt-factor", "0.4", "--damping", "1"],
                                             "--dt-factor"),
}


def _one_line_error(capsys, code, expected_code=2):
    err = capsys.readouterr().err
    assert code == expected_code, err
    assert err.count("\n") == 1 and err.startswith("error: "), err
    return err


@pytest.mark.parametrize("case", sorted(FILE_CASES))
def test_bad_record_file_one_line_and_nothing_written(tmp_path, case, capsys):
    make, words = FILE_CASES[case]
    path = make(tmp_path)
    out = tmp_path / "out"
    err = _one_line_error(capsys, cli.main(["records", str(path), "--out", str(out)]))
    assert words.lower() in err.lower()
    assert not out.exists()
    err = _one_line_error(capsys, cli.main(["run", "--record", str(path), "--out",
                                            str(tmp_path / "run")]))
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("command", [["records", "GM20"], ["synthetics", "--quick"]])
@pytest.mark.parametrize("jobs", ["0", "-2"])
def test_jobs_below_one_one_line_and_nothing_written(tmp_path, capsys, command, jobs):
    """--jobs below 1 is refused, not taken as 1 (synthetics took max(1, jobs))."""
    out = tmp_path / "out"
    extra = ["--out", str(out)] if command[0] == "records" else []
    err = _one_line_error(capsys, cli.main([*command, "--jobs", jobs, *extra]))
    assert f"--jobs must be at least 1, got {jobs}" in err
    assert not out.exists()


def test_check_jobs_takes_every_core_by_default():
    assert check_jobs(None) == (os.cpu_count() or 1) and check_jobs(3) == 3


@pytest.mark.parametrize("case", sorted(PARAMETER_CASES))
def test_impossible_parameter_one_line_naming_the_option(tmp_path, case, capsys):
    args, option = PARAMETER_CASES[case]
    record = write_motion_npz(tmp_path / "pulse.npz")
    out = tmp_path / "run"
    err = _one_line_error(capsys, cli.main(["run", "--record", str(record), *args,
                                            "--out", str(out)]))
    assert option in err
    assert not out.exists()


def test_out_that_is_a_file_is_refused(tmp_path, capsys):
    record = write_motion_npz(tmp_path / "pulse.npz")
    blocker = tmp_path / "file"
    blocker.write_text("x")
    _one_line_error(capsys, cli.main(["run", "--record", str(record), "--out", str(blocker)]))
    _one_line_error(capsys, cli.main(["campaign", "records", "--records", str(record),
                                      "--out", str(blocker)]))
    _one_line_error(capsys, cli.main(["records", str(record), "--out", str(blocker)]))
    assert blocker.read_text() == "x"


def test_long_record_needs_a_window(tmp_path, capsys):
    m = one_sine_pulse(0.0, 0.1, duration=400.0, dt=0.05)
    record = Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": "long"}).save(
        tmp_path / "long.npz")
    err = _one_line_error(capsys, cli.main(["run", "--record", str(record), "--out",
                                            str(tmp_path / "o")]))
    assert "--window" in err


def test_default_out_stays_inside_results(tmp_path, monkeypatch):
    from pipeline.records import resolve
    odd = tmp_path / "...mseed"
    write_mseed(odd, 0.0)
    assert resolve(odd).id not in ("", ".", "..")
    assert "/" not in resolve(odd).id


def test_failed_rerun_leaves_no_old_summary(tmp_path, monkeypatch):
    from pipeline import simulate as sim
    from pipeline.scenario import YadeError
    record = write_motion_npz(tmp_path / "pulse.npz")
    out = tmp_path / "run"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"old": True}))

    def failing(*args, **kwargs):
        raise YadeError("boom")

    monkeypatch.setattr(sim, "run_yade", failing)
    with pytest.raises(YadeError):
        sim.simulate(Motion.load(record), out)
    assert not (out / "summary.json").exists()


def test_result_files_follow_the_umask(tmp_path):
    from pipeline.files import write_json
    old = os.umask(0o022)
    try:
        write_json(tmp_path / "a.json", {"x": 1})
    finally:
        os.umask(old)
    assert (tmp_path / "a.json").stat().st_mode & 0o777 == 0o644


# ---------------------------------------------------------------- runs with YADE
def yade_processes(under):
    """pids of scene processes whose working directory lies under ``under``."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except OSError:
            continue
        if b"run_scene.py" in cmd and cwd.startswith(str(under)):
            found.append(int(pid))
    return found


def cli_process(*args, cwd=PROJECT):
    return subprocess.Popen([sys.executable, "-m", "pipeline", *args], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.yade
def test_same_stem_records_give_two_outcomes(tmp_path, capsys):
    north = write_mseed(tmp_path / "a" / "rec.mseed", 0.0)
    east = write_mseed(tmp_path / "b" / "rec.mseed", 90.0)
    out = tmp_path / "camp"
    assert cli.main(["campaign", "records", "--records", f"{north},{east}", "--out", str(out),
                     "--jobs", "2", "--animations", "0"]) == 0
    import pandas as pd
    runs = pd.read_csv(out / "runs.csv")
    mono = runs[runs["column"] == "monolithic"].set_index("record_id")
    assert len(mono) == 2 and mono.index.nunique() == 2
    axes = sorted(min(a % 180, 180 - a % 180) for a in mono["downfall_azimuth_deg"])
    assert axes[0] < 15 and abs(axes[1] - 90) < 15      # one falls N-S, the other E-W


@pytest.mark.yade
def test_two_runs_into_one_directory(tmp_path):
    record = write_motion_npz(tmp_path / "rocking.npz", amplitude=1.7, duration=40.0)
    out = tmp_path / "run"
    first = cli_process("run", "--record", str(record), "--column", "monolithic", "--out",
                        str(out), "--quiet-motion", "simulate")     # rocks on to 40 s
    deadline = time.monotonic() + 30
    while not yade_processes(out) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert yade_processes(out), "the first run did not start YADE"
    paused = yade_processes(out)           # the first run is still running when the second
    for pid in paused:                     # starts, however slow the machine
        os.kill(pid, signal.SIGSTOP)
    try:
        second = cli_process("run", "--record", str(record), "--out", str(out))
        _, err = second.communicate(timeout=60)
    finally:
        for pid in paused:
            os.kill(pid, signal.SIGCONT)
    assert second.returncode == 2 and err.count("\n") == 1 and "in use" in err
    first.communicate(timeout=120)
    assert first.returncode == 0
    summary = json.loads((out / "summary.json").read_text())
    assert [c["column"] for c in summary["columns"]] == ["monolithic"]


def _campaign_records(tmp_path, n=4):
    return ",".join(str(write_motion_npz(tmp_path / f"p{k}.npz", 45.0 * k)) for k in range(n))


def start_campaign_and_wait_for_yade(tmp_path):
    """(records, campaign dir, CLI process) of a 4-run campaign once YADE runs."""
    records, out = _campaign_records(tmp_path), tmp_path / "camp"
    proc = cli_process("campaign", "records", "--records", records, "--out", str(out),
                       "--jobs", "2", "--animations", "0")
    deadline = time.monotonic() + 60
    while not yade_processes(out) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert yade_processes(out), "no YADE run started"
    return records, out, proc


def resume_completes(records, out):
    assert cli.main(["campaign", "records", "--records", records, "--out", str(out),
                     "--jobs", "2", "--animations", "0"]) == 0
    assert len(list(out.glob("runs/*/summary.json"))) == 4


@pytest.mark.yade
def test_ctrl_c_stops_a_campaign_and_resume_completes(tmp_path):
    """Ctrl-C ends a running campaign (a bound that catches a hang, not a speed: make
    bench, section 10, measures the time)."""
    records, out, proc = start_campaign_and_wait_for_yade(tmp_path)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 30.0
    assert err.strip().splitlines()[-1] == "interrupted: finished results are kept"
    assert proc.returncode == 130
    assert (out / "runs.csv").exists()
    assert not yade_processes(out)
    assert json.loads((out / "campaign.json").read_text())["interrupted"] is True
    resume_completes(records, out)


@pytest.mark.parametrize("delay_s", [0.2, 0.6])
@pytest.mark.parametrize("stop, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_ctrl_c_during_start_up_exits_130_with_one_line(tmp_path, delay_s, stop, status):
    """Ctrl-C (SIGTERM: a plain kill) while the command is still importing its modules:
    the same one line and exit status 130 (143) as later, no traceback, nothing written."""
    out = tmp_path / "camp"
    proc = cli_process("campaign", "records", "--records", "GM20", "--out", str(out))
    deadline = time.monotonic() + 30       # the command catches both signals from its first
    while not _catches(proc.pid, signal.SIGTERM) and time.monotonic() < deadline:  # line (Python
        time.sleep(0.005)                  # catches SIGINT before: a stop then is Python's own)
    time.sleep(delay_s)
    proc.send_signal(stop)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    assert err.strip().splitlines() == ["interrupted: finished results are kept"]
    assert "Traceback" not in err


def _catches(pid, signum):
    """Whether process ``pid`` has a handler for signal ``signum`` (/proc: SigCgt)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    caught = int(status.split("SigCgt:")[1].split()[0], 16)
    return bool(caught >> (signum - 1) & 1)


@pytest.mark.yade
def test_kill_9_leaves_no_yade_behind_and_resume_completes(tmp_path):
    records, out, proc = start_campaign_and_wait_for_yade(tmp_path)
    proc.kill()
    proc.communicate(timeout=30)
    deadline = time.monotonic() + 5
    while yade_processes(out) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not yade_processes(out)
    resume_completes(records, out)


# YADE makes /tmp/yade-XXXXXX per process, at that fixed path (not TMPDIR): a command run
# by private_tmp_cli sees a /tmp of its own (``tmp_path/tmp``, in a mount namespace), so
# that a test sees only its own YADE directories, not those of tests running beside it.
# What lives under /tmp and the command needs is bound back at its own path: tmp_path,
# the checkout and the virtual environment (a clone under /tmp, as CI systems make).
# Arguments: private_tmp, N, N directories to keep, then the command.
PRIVATE_TMP = r"""
private=$1; count=$2; shift 2
fd=3; i=0
for dir; do
  [ "$i" -lt "$count" ] || break
  eval "exec $fd<\"\$dir\"" || exit 99
  fd=$((fd + 1)); i=$((i + 1))
done
mount --bind "$private" /tmp || exit 99
fd=3; i=0
while [ "$i" -lt "$count" ]; do
  mkdir -p "$1" && mount --no-canonicalize --bind "/proc/self/fd/$fd" "$1" || exit 99
  eval "exec $fd<&-"
  fd=$((fd + 1)); i=$((i + 1)); shift
done
exec "$@"
"""


def kept_under_tmp(tmp_path):
    """The directories a private-/tmp command must still see: tmp_path, and the checkout,
    the virtual environment and the interpreter's installation where they lie under /tmp
    (outermost only, so a bind never hides another)."""
    tmp = Path("/tmp").resolve()
    wanted = [Path(p).resolve() for p in (tmp_path, PROJECT, sys.prefix, sys.base_prefix)]
    under = [p for p in wanted if p == tmp_path.resolve() or tmp in p.parents]
    outer = [p for p in under if not any(q in p.parents for q in under)]
    return list(dict.fromkeys(str(p) for p in outer))


def private_tmp_cli(tmp_path, *args):
    """The CLI (as cli_process) with /tmp = ``tmp_path/tmp``; skips the test when this
    machine gives no user and mount namespace (``unshare -Urm``)."""
    if subprocess.run(["unshare", "-Urm", "true"], capture_output=True).returncode != 0:
        pytest.skip("no unprivileged mount namespace (unshare -Urm) for a private /tmp")
    (tmp_path / "tmp").mkdir(exist_ok=True)
    kept = kept_under_tmp(tmp_path)
    return subprocess.Popen(["unshare", "-Urm", "sh", "-c", PRIVATE_TMP, "sh",
                             str(tmp_path / "tmp"), str(len(kept)), *kept, sys.executable,
                             "-m", "pipeline", *args], cwd=PROJECT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def yade_temporary_dirs(tmp_path):
    """What YADE processes and their notes left in the private /tmp of private_tmp_cli."""
    return sorted(p.name for p in (tmp_path / "tmp").iterdir()
                  if p.name.startswith(("yade-", TMP_PREFIX)))


def start_private_campaign(tmp_path, started, executor="threads"):
    """(records, campaign dir, CLI process, its descendant processes) of a 4-run campaign
    in a private /tmp, once a YADE process runs (``started`` False) or YADE has started in
    it and noted its temporary directory (True)."""
    records, out = _campaign_records(tmp_path), tmp_path / "camp"
    proc = private_tmp_cli(tmp_path, "campaign", "records", "--records", records, "--out",
                           str(out), "--jobs", "2", "--animations", "0", "--executor",
                           executor)
    deadline = time.monotonic() + 180    # a hang bound: a loaded machine starts YADE slowly
    while time.monotonic() < deadline:
        children = _descendants(proc.pid)
        yade = [p for p in children if "run_scene.py" in _cmdline(p)]
        noted = list((tmp_path / "tmp").glob(f"{TMP_PREFIX}*/yade_tmp_dir"))
        if yade and (noted or not started):
            return records, out, proc, children
        time.sleep(0.02)
    proc.kill()
    raise AssertionError(f"YADE did not start: {proc.communicate()[1]}")


def _descendants(pid):
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _cmdline(process):
    try:
        return " ".join(process.cmdline())
    except psutil.Error:
        return ""


@pytest.mark.yade
@pytest.mark.parametrize("started, executor", [(False, "threads"), (True, "threads"),
                                               (True, "dask")])
def test_sigterm_stops_a_campaign_with_one_line_and_leaves_nothing(tmp_path, started,
                                                                   executor):
    """A plain kill (SIGTERM) of a campaign, while YADE starts or once it runs a scene
    (on a local Dask cluster too): one line, exit status 143, no process and no
    temporary directory left."""
    records, out, proc, yade = start_private_campaign(tmp_path, started, executor)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    lines = [line for line in err.splitlines() if line.strip() and "run/s" not in line]
    assert lines == ["interrupted: finished results are kept"], err   # (and the progress bar)
    _, alive = psutil.wait_procs(yade, timeout=30)
    assert not alive
    assert yade_temporary_dirs(tmp_path) == []
    assert json.loads((out / "campaign.json").read_text())["interrupted"] is True


@pytest.mark.yade
@pytest.mark.parametrize("started", [False, True])
def test_kill_9_leaves_nothing_in_tmp_after_the_next_run(tmp_path, started):
    """kill -9 of a campaign while YADE starts (its YADE processes remove their temporary
    directories themselves) or runs a scene (they die with it: the next campaign removes
    them): after the next campaign nothing of the killed one is left in /tmp."""
    records, out, proc, yade = start_private_campaign(tmp_path, started)
    proc.kill()
    proc.communicate(timeout=30)
    _, alive = psutil.wait_procs(yade, timeout=30)
    assert not alive
    if started:
        assert yade_temporary_dirs(tmp_path), "the test kills no YADE that noted its directory"
    resume = private_tmp_cli(tmp_path, "campaign", "records", "--records", records, "--out",
                             str(out), "--jobs", "2", "--animations", "0")
    _, err = resume.communicate(timeout=300)
    assert resume.returncode == 0, err
    assert len(list(out.glob("runs/*/summary.json"))) == 4
    assert yade_temporary_dirs(tmp_path) == []


def test_the_next_campaign_removes_only_what_processes_gone_left(tmp_path):
    """Note directories of a process that is gone (or has ended, not yet reaped) are
    removed with the YADE directory they name; those of a live process (this one), of an
    unknown owner (no pid in the name) and directories that are no note stay."""
    from pipeline.scenario.runner import remove_orphaned_tmp
    gone = subprocess.Popen(["true"])
    gone.wait()                                    # reaped: its pid names no process
    ended = subprocess.Popen(["true"])             # a zombie until reaped
    deadline = time.monotonic() + 30
    while psutil.Process(ended.pid).status() != psutil.STATUS_ZOMBIE:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    made = {}
    for owner in (gone.pid, ended.pid, os.getpid(), "x"):
        yade = tmp_path / f"yade-{owner}"
        note = tmp_path / f"{TMP_PREFIX}{owner}-abc"
        yade.mkdir()
        note.mkdir()
        (note / "yade_tmp_dir").write_text(str(yade))
        made[owner] = (yade, note)
    (tmp_path / "yade-unnoted").mkdir()
    assert remove_orphaned_tmp(tmp_path) == 2
    ended.wait()
    assert not any(p.exists() for owner in (gone.pid, ended.pid) for p in made[owner])
    assert all(p.exists() for owner in (os.getpid(), "x") for p in made[owner])
    assert (tmp_path / "yade-unnoted").exists()


def listening_sockets(root):
    """(address, port) of the listening TCP sockets that process ``root`` and its
    descendants hold (psutil): this test's own, not those of tests running beside it
    (pytest-xdist)."""
    found = set()
    try:
        procs = [psutil.Process(root)]
        procs += procs[0].children(recursive=True)
    except psutil.NoSuchProcess:
        return found
    for proc in procs:
        try:
            found.update(tuple(c.laddr) for c in proc.net_connections(kind="tcp")
                         if c.status == psutil.CONN_LISTEN)
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
    return found


def test_the_socket_watch_sees_a_child_listening():
    """The watch below can fail: a child process that listens on a port is seen."""
    me = os.getpid()
    before = listening_sockets(me)
    child = subprocess.Popen([sys.executable, "-c", "import socket, sys, time; "
                              "s = socket.socket(); s.bind(('127.0.0.1', 0)); s.listen(); "
                              "print('up', flush=True); time.sleep(30)"],
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "up"
        assert listening_sockets(me) - before
    finally:
        child.kill()
        child.wait()


@pytest.mark.yade
def test_a_run_opens_no_listening_socket(tmp_path, capsys):
    me = os.getpid()
    before = listening_sockets(me)
    record = write_motion_npz(tmp_path / "pulse.npz")
    seen, done = set(), threading.Event()

    def watch():
        while not done.is_set():
            seen.update(listening_sockets(me) - before)
            time.sleep(0.05)

    watcher = threading.Thread(target=watch)
    watcher.start()
    try:
        assert cli.main(["run", "--record", str(record), "--out", str(tmp_path / "r")]) == 0
    finally:
        done.set()
        watcher.join()
    assert not seen


@pytest.mark.yade
def test_sub_threshold_motion_is_not_simulated_and_says_so(tmp_path, capsys):
    record = write_motion_npz(tmp_path / "weak.npz", amplitude=0.2)
    assert cli.main(["run", "--record", str(record), "--out", str(tmp_path / "r")]) == 0
    assert "not simulated" in capsys.readouterr().out
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert summary["simulated"] is False
    assert not any(c["toppled"] for c in summary["columns"])


@pytest.mark.parametrize("full", [("runs.csv",), ("summary.json",), ("summary.json", "error.txt")])
def test_a_full_disk_gives_one_line_nothing_partial_and_resume_finishes(tmp_path, monkeypatch,
                                                                        capsys, full):
    """ENOSPC while writing the campaign's table, the runs' summaries, or those and their
    error.txt: exit 1 with one line, no partial file, finished runs kept; once there is room,
    the same command finishes the campaign."""
    import errno
    records = ",".join(str(write_motion_npz(tmp_path / f"weak{k}.npz", 30.0 * k, amplitude=0.2))
                       for k in range(2))                   # sub-threshold: no YADE needed
    args = ["campaign", "records", "--records", records, "--out", str(tmp_path / "camp"),
            "--animations", "0"]
    replace = os.replace

    def disk_full(src, dst, *rest, **kwargs):
        if Path(dst).name in full:
            raise OSError(errno.ENOSPC, "No space left on device", str(dst))
        return replace(src, dst, *rest, **kwargs)

    monkeypatch.setattr(os, "replace", disk_full)
    assert cli.main(args) == 1
    err = [line for line in capsys.readouterr().err.splitlines()
           if line.strip() and "run/s]" not in line and "failed:" not in line]   # bar, runs
    assert len(err) == 1 and err[0].startswith("error: ")
    assert ("disk full" in err[0]) != (full == ("summary.json",))   # else: runs failed
    out = tmp_path / "camp"
    assert not list(out.rglob("*.tmp")) and not list(out.rglob(".*.tmp"))
    assert (out / "runs.csv").exists() == (full == ("summary.json",))
    assert len(list(out.glob("runs/*/summary.json"))) == (2 if full == ("runs.csv",) else 0)
    monkeypatch.setattr(os, "replace", replace)
    assert cli.main(args) == 0
    if full == ("runs.csv",):
        assert "2 already done, 0 to run" in capsys.readouterr().out   # kept, not redone
    assert len(list(out.glob("runs/*/summary.json"))) == 2 and (out / "runs.csv").exists()
