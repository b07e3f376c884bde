"""Whole chain on a short excerpt: record -> scenario -> YADE -> summary -> campaign table."""
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pipeline.campaign.runs import column_specs, pulse_record, run_column_spec, twin
from pipeline.campaign.executor import execute
from pipeline.campaign.tables import collect
from pipeline.motion import Motion
from pipeline.motion.measures import record_parameters

pytestmark = pytest.mark.yade
FILE_WINDOW = (9.0, 15.0)   # s in the file: the displacement pulse of NF04 (Superstition Hills)


def test_chain_on_pulse_excerpt(tmp_path, capsys):
    record = pulse_record()
    window = list(FILE_WINDOW)          # on the record's clock, as the times it gives
    specs = column_specs([(record, twin(window=window))], tmp_path)
    failures, interrupted = execute(specs, tmp_path, 1, run_column_spec)
    assert not failures and not interrupted
    runs, impacts = collect(specs, "smoke", tmp_path)
    assert sorted(runs["column"]) == ["drums", "monolithic"]

    motion = Motion.load(specs[0].motion_file)
    acc_h = np.hypot(motion.acc[:, 0], motion.acc[:, 1])
    peak_time = acc_h.argmax() * motion.dt + motion.meta["start_in_file_s"]   # record's clock
    assert window[0] < peak_time < window[1]
    params = record_parameters(motion)
    for _, row in runs.iterrows():
        # the strongest pulse (about 0.5 g here, g tan(alpha) = 0.17 g) topples both columns
        assert row["toppled"]
        # ... after the largest acceleration, within the few seconds a 3.5 m column takes
        assert peak_time < row["impact_time_s"] < peak_time + 4.0
        # the centre of mass lands between its own height and the column's length away
        assert 1.0 < math.hypot(row["impact_x_m"], row["impact_y_m"]) < 3.5
        assert 0 <= row["downfall_azimuth_deg"] < 360
        assert row["pga_h"] == pytest.approx(params["pga_h"])
    # every drum of the toppled drum column struck the pedestal at or after the first impact
    drums = impacts[impacts["column"] == "drums"]
    first = runs.loc[runs["column"] == "drums", "impact_time_s"].iloc[0]
    assert len(drums) >= 4 and (drums["impact_time_s"] >= first).all()

    # a second campaign pass finds the run done and does not repeat it
    summary = tmp_path / "runs" / specs[0].run_id / "summary.json"
    stamp = summary.stat().st_mtime_ns
    capsys.readouterr()
    assert execute(specs, tmp_path, 1, run_column_spec) == ([], False)
    assert "1 already done, 0 to run" in capsys.readouterr().out
    assert summary.stat().st_mtime_ns == stamp
    assert json.loads(summary.read_text())["parameters"]["window"] == window


@pytest.mark.parametrize("args, message", [
    (["--record", "no/such/file.mseed"], "no such file"),
    (["--record", "GM20", "--hd", "-6"], "--hd"),
    (["--record", "GM20", "--mu-s", "0.5", "--mu-k", "0.6"], "mu_k"),
    (["--record", "GM20", "--column-file", "parthenon-north-flank", "--column", "monolithic"],
     "a colonnade, which places its own columns: drop --column"),
])
def test_run_bad_input_one_line_and_nothing_written(tmp_path, args, message):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "pipeline", "run", *args, "--out", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and message in proc.stderr
    assert not (out / "summary.json").exists()


def test_campaign_runs_start_longest_motion_first(tmp_path):
    """One worker thread: runs start in order of decreasing motion length (a window's
    length when the run has one), equal lengths in the campaign's order."""
    from pipeline.files import write_json
    from pipeline.campaign.spec import RunSpec
    from pipeline.motion.pulses import one_sine_pulse
    from pipeline.scenario import Drive, RunParams
    specs = []
    for name, seconds, window in (("a", 4.0, None), ("b", 9.0, None), ("c", 9.0, [0.0, 2.0]),
                                  ("d", 6.0, None), ("e", 9.0, None)):
        path = tmp_path / f"{name}.npz"
        one_sine_pulse(duration=seconds).save(path)
        specs.append(RunSpec(name, name, str(path), RunParams(drive=Drive(window)), name))
    started = []

    def worker(spec, run_dir):
        started.append(spec.run_id)
        write_json(Path(run_dir) / "summary.json", {})

    assert execute(specs, tmp_path, 1, worker) == ([], False)
    assert started == ["b", "e", "d", "a", "c"]
