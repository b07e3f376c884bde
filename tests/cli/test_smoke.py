"""Whole chain on a short excerpt: record -> scenario -> YADE -> summary -> campaign table."""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from pipeline import campaign, records

pytestmark = pytest.mark.yade
WINDOW = (9.0, 15.0)     # s: the displacement pulse of NF04 (Superstition Hills, Parachute)


def test_chain_on_pulse_excerpt(tmp_path, capsys):
    record = campaign.pulse_record()
    specs = campaign.resolve_specs([campaign.column_spec(record, window=list(WINDOW))])
    failures = campaign.execute(specs, tmp_path, jobs=1)
    assert not failures
    runs, impacts = campaign.collect(specs, "smoke", tmp_path)
    assert sorted(runs["column"]) == ["drums", "monolithic"]

    motion = records.load_motion(specs[0]["motion_file"])
    acc_h = np.hypot(motion["acc"][:, 0], motion["acc"][:, 1])
    peak_time = acc_h.argmax() * motion["dt"] - WINDOW[0]
    params = records.record_parameters(motion)
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
    summary = tmp_path / "runs" / specs[0]["run_id"] / "summary.json"
    stamp = summary.stat().st_mtime_ns
    capsys.readouterr()
    assert not campaign.execute(specs, tmp_path, jobs=1)
    assert "1 already done, 0 to run" in capsys.readouterr().out
    assert summary.stat().st_mtime_ns == stamp
    assert json.loads(summary.read_text())["parameters"]["window_s"] == list(WINDOW)


@pytest.mark.parametrize("args, message", [
    (["--record", "no/such/file.mseed"], "no such file"),
    (["--record", "GM20", "--hd", "-6"], "h/d"),
    (["--record", "GM20", "--mu-s", "0.5", "--mu-k", "0.6"], "mu_k"),
])
def test_run_bad_input_one_line_and_nothing_written(tmp_path, args, message):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "pipeline", "run", *args, "--out", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and message in proc.stderr
    assert not (out / "summary.json").exists()
