"""YADE block model against rigid-block rocking theory (pipeline.rocking)."""
import json
import subprocess
import sys

import pytest

from pipeline import verification as verify

pytestmark = pytest.mark.yade


@pytest.mark.libm
def test_free_rocking_matches_housner_within_two_percent(tmp_path):
    result = verify.verify_housner(theta0_ratio=0.5, run_dir=tmp_path / "h")
    assert len(result["yade"]["impact_times_s"]) == 5
    assert result["max_rel_error_impact_times"] < 0.02
    assert result["max_rel_error_peaks"] < 0.02
    assert result["max_rel_error_peaks_closed_form"] < 0.03
    assert result["effective_restitution"] == pytest.approx(result["housner_restitution"], rel=0.005)


def test_paper_damping_keeps_impact_times_and_restitution_close(tmp_path):
    """With the paper's damping ratio 0.36 impacts lose slightly less energy than Housner's."""
    result = verify.verify_housner(theta0_ratio=0.5, damping=0.36, run_dir=tmp_path / "h")
    assert result["max_rel_error_impact_times"] < 0.02
    assert result["housner_restitution"] < result["effective_restitution"] < \
        1.01 * result["housner_restitution"]


@pytest.mark.libm
def test_sine_pulse_gives_the_three_modes_in_order(tmp_path):
    """Zhang & Makris (2000) at omega = 5p: overturning after one impact (away from the
    first push, East), a safe band, then overturning without impact (West)."""
    outcomes = [verify.verify_sine_pulse(amplitude_ratio=k, run_dir=tmp_path / str(k))
                for k in (5.5, 7.0, 8.0)]
    assert [o["yade"]["mode"] for o in outcomes] == [
        "overturn_after_impact", "no_overturn", "overturn_without_impact"]
    assert [o["yade"]["direction"] for o in outcomes] == [1, 0, -1]
    assert all(o["passed"] for o in outcomes)


def test_sliding_starts_below_the_augusti_sinopoli_limit(tmp_path):
    result = verify.verify_sliding(mu_values=(0.4, 0.1), run_dir=tmp_path)
    by_mu = {r["mu_s"]: r for r in result["runs"]}
    assert by_mu[0.4]["pure_rocking"] and not by_mu[0.1]["pure_rocking"]
    assert result["augusti_sinopoli_mu_min"] == pytest.approx(0.6 / 4.04)


def test_verify_cli_writes_json(tmp_path):
    out = tmp_path / "housner.json"
    proc = subprocess.run([sys.executable, "-m", "pipeline", "verify", "housner",
                           "--theta0-ratio", "0.4", "--out", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(out.read_text())["passed"] is True
    bad = subprocess.run([sys.executable, "-m", "pipeline", "verify", "housner",
                          "--theta0-ratio", "1.5", "--out", str(tmp_path / "bad.json")],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1
    assert not (tmp_path / "bad.json").exists()


@pytest.mark.parametrize("mu_s, message", [
    (["0.4"], "--mu-s needs a value at or below 0.134"),       # 0.9 x 0.6 / 4.04
    (["0.1", "0"], "--mu-s 0 outside")])
def test_verify_sliding_refuses_what_it_cannot_check_before_any_run(tmp_path, capsys,
                                                                    monkeypatch, mu_s, message):
    """mu_s values that cannot show where sliding starts (none below the Augusti & Sinopoli
    limit) or out of range: one line, exit 2, no run and nothing written."""
    from pipeline import cli
    from pipeline.cli import verify as command

    def no_run(**kwargs):
        raise AssertionError("a run started")
    monkeypatch.setattr(command, "verify_sliding", no_run)
    out = tmp_path / "sliding.json"
    assert cli.main(["verify", "sliding", "--mu-s", *mu_s, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert not out.exists()
