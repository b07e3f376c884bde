"""Options declared once (``param`` fields) of records, synthetics and verify: a value
out of its range, not a number, or a flag given twice is refused in one line before any
work, with nothing written; the help states each option's default (or what unset means)
and its range, from the declaration."""
import pytest

from pipeline import cli
from tests.refusal import refused


def help_text(capsys, argv):
    """The help of ``argv`` on one line (argparse wraps it)."""
    with pytest.raises(SystemExit):
        cli.main([*argv, "--help"])
    return " ".join(capsys.readouterr().out.split())


@pytest.fixture
def nothing_done(tmp_path, monkeypatch):
    """A working directory that must stay empty, and no verification run started."""
    from pipeline.cli import verify
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(verify, "check_out_file", lambda out: pytest.fail("work started"))
    return tmp_path


# ---------------------------------------------------------------- records, synthetics
@pytest.mark.parametrize("values, words", [
    (["360"], "--back-azimuth 360 outside the allowed range [0, 360) deg"),
    (["-0.5"], "--back-azimuth -0.5 outside the allowed range [0, 360) deg"),
    (["nan"], "--back-azimuth must be a finite number, got nan"),
    (["10", "--back-azimuth", "20"], "--back-azimuth given more than once (10.0 and 20.0)"),
])
def test_records_back_azimuth_refused_before_any_record(tmp_path, capsys, monkeypatch,
                                                        values, words):
    from pipeline.cli import records
    monkeypatch.setattr(records, "resolve", lambda spec: pytest.fail("a record was read"))
    out = tmp_path / "out"
    refused(capsys, ["records", "GM20", "--out", out, "--back-azimuth", *values], words, out)


@pytest.mark.parametrize("values, words", [
    (["0.001"], "--step 0.001 outside the allowed range [0.01, 360] deg"),
    (["inf"], "--step must be a finite number, got inf"),
    (["30", "--step", "60"], "--step given more than once (30.0 and 60.0)"),
])
def test_synthetics_step_refused_before_any_motion(tmp_path, capsys, monkeypatch, values,
                                                   words):
    from pipeline.cli import synthetics
    from pipeline.motion.synthetics import sites
    monkeypatch.setattr(sites, "DEFAULT_OUT_DIR", tmp_path / "synthetics")
    monkeypatch.setattr(synthetics, "generate_sources", lambda *a, **k: pytest.fail("ran"))
    refused(capsys, ["synthetics", "--step", *values], words, tmp_path / "synthetics")


def test_records_and_synthetics_help_state_default_and_range(capsys):
    assert ("--back-azimuth DEG back azimuth of the records whose file and catalogue give "
            "none (coordinates or a catalogued value win) (deg); unset: such a record's "
            "back azimuth is unknown; 0-360 (below 360)") in help_text(capsys, ["records"])
    assert ("--step DEG azimuth step between the sites of a ring (deg); default 30; "
            "0.01-360") in help_text(capsys, ["synthetics"])


# ---------------------------------------------------------------- verify
@pytest.mark.parametrize("argv, words", [
    (["housner", "--theta0-ratio", "1"], "--theta0-ratio 1 outside the allowed range (0, 1)"),
    (["housner", "--impacts", "21"], "--impacts 21 outside the allowed range [1, 20]"),
    (["housner", "--depth", "nan"], "--depth must be a finite number, got nan"),
    (["housner", "--kn", "1e12"], "--kn 1e+12 outside the allowed range [100000, 1e+11] N/m"),
    (["housner", "--width", "0.1", "--width", "0.2"], "--width given more than once"),
    (["sine-pulse"], "give --amplitude-ratio"),
    (["sine-pulse", "--amplitude-ratio", "0"], "--amplitude-ratio 0 outside the allowed range "
     "(0, 50]"),
    (["sine-pulse", "--amplitude-ratio", "6", "--omega-ratio", "nan"],
     "--omega-ratio must be a finite number"),
    (["sliding", "--theta0-deg", "90"], "--theta0-deg 90 outside the allowed range"),
    (["sliding", "--mu-s", "0.1", "nan"], "--mu-s must be a finite number, got nan"),
    (["sliding", "--mu-s", "0.1", "--mu-s", "0.2"], "--mu-s given more than once (0.1 and "
     "0.2)"),
    (["sliding", "--damping", "-0.1"], "--damping -0.1 outside the allowed range [0, 1]"),
    (["one-cosine", "--runs", "21"], "--runs 21 outside the allowed range [3, 20]"),
    (["one-cosine", "--period", "inf"], "--period must be a finite number"),
    (["frame", "--gamma", "1001"], "--gamma 1001 outside the allowed range [0, 1000]"),
    (["frame", "--columns", "1"], "--columns 1 outside the allowed range [2, inf]"),
    (["frame", "--period", "1", "--period", "2"], "--period given more than once"),
])
def test_verify_options_refused_before_any_run(nothing_done, capsys, argv, words):
    out = nothing_done / "out.json"
    refused(capsys, ["verify", *argv, "--out", out], words, out)
    assert list(nothing_done.iterdir()) == []


@pytest.mark.parametrize("test, phrases", [
    ("housner", ["--height HEIGHT block height (m); default 0.4; 0.01-30",
                 "--theta0-ratio THETA0_RATIO initial tilt over the critical angle, theta0 / "
                 "alpha; default 0.5; 0-1 (above 0 and below 1)",
                 "--impacts IMPACTS impacts compared; default 5; 1-20",
                 "unset: 1.2e+07, the marble block's; 100000-1e+11",
                 "--damping DAMPING contact damping ratio (1 = critical); unset: 1, critical"]),
    ("sine-pulse", ["--depth DEPTH block depth (North) (m); default 0.5; 0.005-30",
                    "A / (alpha g); 0-50 (above 0)", "omega / p; default 5; 0-50 (above 0)",
                    "unset: 0.36, the paper's; 0-1"]),
    ("sliding", ["unset: 0.7 down to 0.1; 0.01-2", "(deg); default 10;",
                 "default switch"]),
    ("one-cosine", ["--width WIDTH block width (East) (m); default 1; 0.005-30",
                    "--period PERIOD pulse period T_p (s); default 1; 0.1-10",
                    "--runs RUNS YADE runs of the bisection; default 10; 3-20"]),
    ("frame", ["--columns COLUMNS columns under the beam; default 2; at least 2",
               "--gamma GAMMA beam mass over the columns' mass; default 1; 0-1000",
               "unset: 1.2e+08 x (1 + 3 gamma)"]),
])
def test_verify_help_states_default_and_range(capsys, test, phrases):
    text = help_text(capsys, ["verify", test])
    for phrase in phrases:
        assert phrase in text, text
