"""The one-cosine pulse (Makris & Roussos 2000, type B) against their published numbers:
Fig. 11's overturning threshold, eq. 43 and the safe band above the threshold."""
import math
import subprocess
import sys

import pytest

from pipeline.rocking.housner import block_constants
from pipeline.files import InputError
from pipeline.verification import Check, CheckResult
from pipeline.verification import one_cosine as oc

H, B = 3.0, 1.0          # their Fig. 11: half-width 0.5 m, half-height 1.5 m


def test_the_block_of_fig_11_has_their_alpha_p_and_restitution():
    c = block_constants(H, B)
    assert math.degrees(c["alpha"]) == pytest.approx(18.43, abs=0.01)
    assert c["p"] == pytest.approx(2.157, abs=0.001)
    assert c["restitution"] == pytest.approx(1 - 1.5 * math.sin(math.atan(0.5 / 1.5)) ** 2)


def test_the_2d_block_stands_and_overturns_where_fig_11_says_within_half_a_percent():
    tol = oc.TOLERANCE_2D
    assert not oc.overturns_2d(0.6245 * (1 - tol), 1.0, H, B)
    assert oc.overturns_2d(0.6255 * (1 + tol), 1.0, H, B)
    threshold = oc.min_overturning_g(1.0, H, B)
    assert 0.6245 * (1 - tol) <= threshold <= 0.6255 * (1 + tol)


@pytest.mark.parametrize("w", [1.0, 1.5, 2.0, 2.5, 3.0])
def test_eq_43_holds_within_its_16_percent_where_the_block_overturns_after_an_impact(w):
    c = block_constants(H, B)
    period = 2 * math.pi / (w * c["p"])
    a = oc.min_overturning_g(period, H, B)
    assert a / c["alpha"] == pytest.approx(1 + w / 4, rel=0.16)
    assert oc.eq43_g(period, H, B) == pytest.approx(c["alpha"] * (1 + w / 4))


def test_above_the_threshold_the_paper_block_stands_again_before_it_overturns_again():
    """Overturning is not monotone in amplitude: a safe band lies above the first
    overturning interval (Makris & Roussos: overturning after one impact, then a safe
    region, then overturning without impact)."""
    spans = oc.overturning_intervals(1.0, H, B, 5.0)
    assert len(spans) >= 2
    (a0, a1), (b0, _) = spans[0], spans[1]
    assert a0 == pytest.approx(0.625, rel=oc.TOLERANCE_2D) and a1 < b0
    mid = math.sqrt(a1 * b0)
    assert not oc.overturns_2d(mid, 1.0, H, B)
    assert oc.overturns_2d(math.sqrt(a0 * a1), 1.0, H, B)


def test_the_sp1_block_is_its_stated_critical_angle_and_pivot_distance():
    b = oc.SP1_BLOCK
    c = block_constants(b["height"], b["width"])
    assert math.degrees(c["alpha"]) == pytest.approx(14.7)
    assert c["R"] == pytest.approx(0.302)


@pytest.mark.parametrize("setting, words", [({"period_s": 0.01}, "--period"),
                                            ({"period_s": 1.0, "mu_s": 0.5}, "exactly period_s")])
def test_a_bad_one_cosine_check_is_refused_in_one_line(setting, words):
    with pytest.raises(InputError, match=words) as err:
        Check.create("one-cosine", "code", **setting)
    assert "\n" not in str(err.value)


def test_a_one_cosine_result_without_its_numbers_is_refused():
    with pytest.raises(InputError, match="lacks"):
        CheckResult({"test": "one-cosine", "passed": True, "yade": {}})


@pytest.mark.parametrize("flags", [["--runs", "1"], ["--period", "0"], ["--width", "-1"]])
def test_verify_one_cosine_refuses_a_bad_option_in_one_line_before_any_run(tmp_path, flags):
    out = tmp_path / "o.json"
    proc = subprocess.run([sys.executable, "-m", "pipeline", "verify", "one-cosine", *flags,
                           "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0 and len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.yade
def test_the_yade_block_stands_below_and_overturns_above_fig_11_within_its_tolerance(tmp_path):
    """Two YADE runs, 2 tolerances either side of their threshold (0.625 g)."""
    k = 2 * oc.TOLERANCE_YADE
    assert not oc.overturns_yade(0.6245 * (1 - k), 1.0, tmp_path / "below")[0]
    assert oc.overturns_yade(0.6255 * (1 + k), 1.0, tmp_path / "above")[0]


@pytest.mark.parametrize("flags, words", [
    (["--height", "inf"], "--height must be a finite number, got inf"),
    (["--height", "1e300"], "--height 1e+300 outside the allowed range [0.01, 30] m"),
    (["--width", "1e-300"], "--width 1e-300 outside the allowed range [0.005, 30] m"),
    (["--width", "inf"], "--width must be a finite number"),
    (["--depth", "nan"], "--depth must be a finite number"),
    (["--height", "1", "--width", "3"], "the block is wider than tall"),
    (["--height", "30", "--width", "0.5"], "more slender than the check takes"),
    (["--height", "0.3", "--width", "0.01", "--period", "10"], "a quasi-static pulse"),
    (["--damping", "5"], "--damping 5 outside the allowed range [0, 1]"),
    (["--kn", "-1"], "--kn -1 outside the allowed range"),
])
def test_verify_one_cosine_names_the_range_of_a_bad_option_before_any_work(
        tmp_path, monkeypatch, capsys, flags, words):
    from pipeline.cli import main

    def no_work(*args, **kwargs):
        raise AssertionError("worked before its options were checked")
    monkeypatch.setattr(oc, "min_overturning_g", no_work)
    monkeypatch.setattr(oc, "run_block", no_work)
    out = tmp_path / "o.json"
    assert main(["verify", "one-cosine", *flags, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err
    assert not out.exists()


def test_verify_refuses_an_out_file_it_cannot_write_before_any_work(tmp_path, monkeypatch,
                                                                    capsys):
    from pipeline.cli import main

    def no_work(*args, **kwargs):
        raise AssertionError("worked before --out was checked")
    monkeypatch.setattr(oc, "min_overturning_g", no_work)
    (tmp_path / "file").write_text("x")
    for out, words in ((tmp_path / "file" / "sub" / "o.json", "is a file, not a folder"),
                       (tmp_path, "is a directory, not a file")):
        assert main(["verify", "one-cosine", "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and words in err, err


@pytest.mark.parametrize("hb", [3.0, 30.0])
def test_at_the_slowest_pulse_taken_the_threshold_in_g_does_not_depend_on_the_size(hb):
    # a_po / g depends on alpha and omega_p / p alone (dimensional analysis): the same at
    # the slowest pulse the check takes on a 0.1 m and a 3 m block, above the uplift
    tan_alpha = 1 / hb
    found = []
    for h in (0.1, 3.0):
        p = block_constants(h, h / hb)["p"]
        found.append(oc.min_overturning_g(2 * math.pi / (oc.MIN_OMEGA_RATIO * p), h, h / hb))
    assert found[0] == pytest.approx(found[1], rel=1e-4)
    assert tan_alpha < found[0] < 1.1 * tan_alpha


@pytest.mark.parametrize("test", [["housner"], ["sine-pulse", "--amplitude-ratio", "6.5"]])
def test_the_other_block_checks_name_a_size_out_of_range(tmp_path, capsys, test):
    from pipeline.cli import main
    out = tmp_path / "o.json"
    assert main(["verify", *test, "--height", "inf", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "error: --height must be a finite number, got inf"
    assert not out.exists()
