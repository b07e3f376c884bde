"""The contract of the old surfaces on the new ones: ensemble, fragility, invert, verify
and campaign options are range-checked before any work, zero is a value, duplicates
are refused; each refusal is one `error:` line, exit 2, and writes nothing."""
import gzip

import pytest

from pipeline import cli
from pipeline.inversion import EXAMPLES_DIR


def one_line_error(capsys, code):
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("error: "), err
    return err


@pytest.mark.parametrize("args, words", [
    (["campaign", "ensemble", "--records", "GM20", "--vary", "scale=1000,2000"], "--vary scale"),
    (["campaign", "ensemble", "--records", "GM20", "--vary", "damping=0.2,5"], "damping"),
    (["campaign", "ensemble", "--records", "GM20", "--vary", "mu_s=0.5,0.6",
      "--vary", "mu_s=0.6,0.7"], "twice"),
    (["campaign", "ensemble", "--records", "GM20", "--vary", "tilt_deg=0,90"], "tilt_deg"),
    (["campaign", "ensemble", "--records", "GM20", "--seed", "-1"], "--seed"),
    (["campaign", "fragility", "--records", "GM20", "--seed", "-1"], "--seed"),
    (["campaign", "records", "--records", "GM20,NF04,GM20"], "GM20 more than once"),
    (["verify", "housner", "--impacts", "-3"], "--impacts"),
    (["verify", "sine-pulse", "--amplitude-ratio", "6", "--omega-ratio", "1e9"],
     "--omega-ratio"),
    (["invert", str(EXAMPLES_DIR / "two_sites.json"), "--kernel-deg", "0"], "--kernel-deg"),
    (["invert", str(EXAMPLES_DIR / "two_sites.json"), "--floor", "0"], "--floor"),
    (["invert", str(EXAMPLES_DIR / "two_sites.json"), "--seed", "-5"], "--seed"),
    (["run", "--record", "GM20", "--out", ""], "--out is empty"),
])
def test_new_options_are_refused_before_any_work(tmp_path, monkeypatch, capsys, args, words):
    monkeypatch.chdir(tmp_path)
    if "--out" not in args:
        args = args + ["--out", str(tmp_path / "out")]
    err = one_line_error(capsys, cli.main(args))
    assert words in err
    assert not (tmp_path / "out").exists()
    assert list(tmp_path.iterdir()) == []


def test_a_gz_record_with_a_broken_deflate_stream_is_one_line(tmp_path, capsys):
    good = gzip.compress(b"PEER NGA STRONG MOTION DATABASE RECORD\n" * 200)
    broken = good[:20] + bytes(b ^ 0xFF for b in good[20:60]) + good[60:]
    path = tmp_path / "rec.AT2.gz"
    path.write_bytes(broken)
    err = one_line_error(capsys, cli.main(["records", str(path), "--out",
                                           str(tmp_path / "out")]))
    assert "rec.AT2.gz" in err
    assert not (tmp_path / "out").exists()


def test_invert_says_what_the_default_grid_costs_and_refuses_hours_of_work(tmp_path, capsys):
    code = cli.main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--out",
                     str(tmp_path / "out"), "--forward-dir", str(tmp_path / "forward")])
    captured = capsys.readouterr()
    assert "forward table: 6480 YADE runs" in captured.out
    assert code == 2 and captured.err.count("\n") == 1 and "--allow-long" in captured.err
    assert not (tmp_path / "out").exists() and not (tmp_path / "forward").exists()


def test_a_child_whose_parent_died_before_it_armed_the_death_signal_exits():
    """The race a kill can hit: the parent gone before the child's initializer ran (its
    parent is then another process): the child exits at once; with its real parent it
    lives on."""
    import subprocess
    import sys
    code = ("import os, sys; from pipeline.files import die_with_parent; "
            "die_with_parent(int(sys.argv[1])); print('alive')")
    orphan = subprocess.run([sys.executable, "-c", code, "1"], capture_output=True, text=True,
                            timeout=60)
    assert orphan.returncode == 1 and orphan.stdout == ""
    own = subprocess.run([sys.executable, "-c", code.replace("int(sys.argv[1])", "os.getppid()")],
                         capture_output=True, text=True, timeout=60)
    assert own.returncode == 0 and own.stdout == "alive\n"


def test_pool_workers_die_with_their_parent(tmp_path):
    """kill -9 of a command leaves no pool worker (pyprop8's) running: the initializer
    the pools use ties each worker to its parent."""
    import os
    import signal
    import subprocess
    import sys
    import time
    script = ("import time\nfrom multiprocessing import Pool\n"
              "from pipeline.files import die_with_parent\n"
              "import os\n"
              "pool = Pool(2, initializer=die_with_parent, initargs=(os.getpid(),))\n"
              "print(' '.join(str(p.pid) for p in pool._pool), flush=True)\n"
              "pool.map(time.sleep, [60, 60])\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    workers = [int(p) for p in proc.stdout.readline().split()]
    assert len(workers) == 2
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=10)
    deadline = time.monotonic() + 10
    alive = workers
    while alive and time.monotonic() < deadline:
        alive = [p for p in workers if os.path.exists(f"/proc/{p}")
                 and "Z" not in open(f"/proc/{p}/stat").read().split()[2]]
        time.sleep(0.05)
    assert not alive


def test_a_run_that_cannot_finish_in_its_wall_clock_limit_is_refused_before_it_starts(
        tmp_path, capsys):
    """60 drums of 2 cm (column files allow 2 cm): a time step 4x finer and 8x the
    bodies of the paper's column; on a 290 s record the estimate says before anything
    runs that it cannot finish; on 120 s it notes the time it may take."""
    import json
    column = {"name": "thin drums", "density": 2700.0,
              "blocks": [{"shape": "frustum", "height": 0.02, "bottom_diameter": 0.58,
                          "top_diameter": 0.58}] * 60}
    path = tmp_path / "thin.json"
    path.write_text(json.dumps(column))
    record = tmp_path / "pulse.npz"
    from pipeline.motion.pulses import one_sine_pulse
    from pipeline.motion import Motion
    m = one_sine_pulse(0.0, 5.0, duration=290.0, dt=0.01)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": "p"}).save(record)
    err = one_line_error(capsys, cli.main(["run", "--record", str(record), "--column",
                                           "drums", "--column-file", str(path),
                                           "--out", str(tmp_path / "out")]))
    assert "60 bodies" in err and "wall-clock limit" in err
    assert not (tmp_path / "out").exists()
    from pipeline.scenario import ColumnGeometry, ColumnSpec, scene_params
    from pipeline.scenario.time_step import check_cost
    sixty = ColumnGeometry.from_dict(column)
    params = scene_params(columns=[ColumnSpec("drums", "drums", 0.0, 0.0, sixty)],
                          motion_duration=120.0)
    assert check_cost(params, 1e9) > 600.0
    assert "note: 60 bodies" in capsys.readouterr().out


@pytest.mark.parametrize("window, words", [(("0", "400"), "--window spans"),
                                           (("500", "600"), "after the motion ends")])
def test_run_window_errors_say_what_is_wrong(tmp_path, capsys, window, words):
    from pipeline.motion import Motion
    from pipeline.motion.pulses import one_sine_pulse
    m = one_sine_pulse(0.0, 5.0, duration=400.0, dt=0.05)
    record = Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": "p"}).save(tmp_path / "p.npz")
    err = one_line_error(capsys, cli.main(["run", "--record", str(record), "--window", *window,
                                           "--out", str(tmp_path / "out")]))
    assert words in err and not (tmp_path / "out").exists()


def test_a_refused_campaign_leaves_nothing(tmp_path, capsys):
    """An unknown record after a good one: the good one was processed into the campaign's
    motion cache before the refusal; nothing of it stays."""
    err = one_line_error(capsys, cli.main(["campaign", "records", "--records", "GM20,NOPE",
                                           "--out", str(tmp_path / "camp")]))
    assert "NOPE" in err and not (tmp_path / "camp").exists()


def test_an_unreachable_scheduler_leaves_nothing(tmp_path, capsys):
    code = cli.main(["campaign", "records", "--records", "GM20", "--scheduler",
                     "tcp://127.0.0.1:9", "--out", str(tmp_path / "camp")])
    err = capsys.readouterr().err
    assert code == 1 and err.strip().splitlines()[-1].startswith("error: cannot reach")
    assert not (tmp_path / "camp").exists()
