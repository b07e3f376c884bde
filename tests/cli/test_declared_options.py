"""Options declared once (``param`` fields) of records, synthetics, verify and invert's
grid: a value out of its range, not a number, or a flag given twice is refused in one line
before any work, with nothing written; the help states each option's default (or what
unset means) and its range, from the declaration."""
import pytest

from pipeline import cli
from tests.refusal import refused


def cases(table):
    """(argv, words) of each line ``ARGS | WORDS`` of a table of refusals."""
    return [(args.split(), words) for args, words in
            (line.split(" | ") for line in table.splitlines())]


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
BACK_AZIMUTH = """\
360 | --back-azimuth 360 outside the allowed range [0, 360) deg
-0.5 | --back-azimuth -0.5 outside the allowed range [0, 360) deg
nan | --back-azimuth must be a finite number, got nan
10 --back-azimuth 20 | --back-azimuth given more than once (10.0 and 20.0)
"""


@pytest.mark.parametrize("values, words", cases(BACK_AZIMUTH))
def test_records_back_azimuth_refused_before_any_record(tmp_path, capsys, monkeypatch,
                                                        values, words):
    from pipeline.cli import records
    monkeypatch.setattr(records, "resolve", lambda spec: pytest.fail("a record was read"))
    out = tmp_path / "out"
    refused(capsys, ["records", "GM20", "--out", out, "--back-azimuth", *values], words, out)


STEP = """\
0.001 | --step 0.001 outside the allowed range [0.01, 360] deg
inf | --step must be a finite number, got inf
30 --step 60 | --step given more than once (30.0 and 60.0)
"""


@pytest.mark.parametrize("values, words", cases(STEP))
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
VERIFY = """\
housner --theta0-ratio 1 | --theta0-ratio 1 outside the allowed range (0, 1)
housner --impacts 21 | --impacts 21 outside the allowed range [1, 20]
housner --depth nan | --depth must be a finite number, got nan
housner --kn 1e12 | --kn 1e+12 outside the allowed range [100000, 1e+11] N/m
housner --width 0.1 --width 0.2 | --width given more than once
sine-pulse | give --amplitude-ratio
sine-pulse --amplitude-ratio 0 | --amplitude-ratio 0 outside the allowed range (0, 50]
sine-pulse --amplitude-ratio 6 --omega-ratio nan | --omega-ratio must be a finite number
sliding --theta0-deg 90 | --theta0-deg 90 outside the allowed range
sliding --mu-s 0.1 nan | --mu-s must be a finite number, got nan
sliding --mu-s 0.1 --mu-s 0.2 | --mu-s given more than once (0.1 and 0.2)
sliding --damping -0.1 | --damping -0.1 outside the allowed range [0, 1]
one-cosine --runs 21 | --runs 21 outside the allowed range [3, 20]
one-cosine --period inf | --period must be a finite number
frame --gamma 1001 | --gamma 1001 outside the allowed range [0, 1000]
frame --columns 1 | --columns 1 outside the allowed range [2, inf]
frame --period 1 --period 2 | --period given more than once
"""


@pytest.mark.parametrize("argv, words", cases(VERIFY))
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


# ---------------------------------------------------------------- invert's grid options
INVERT = """\
--depths 6,nan | --depths must be a finite number, got nan
--depths 6,41 | --depths 41 outside the allowed range (0, 40] km
--magnitudes 4 | --magnitudes 4 outside the allowed range [4.5, 7.5]
--distances 0,5 | --distances 0 outside the allowed range (0, 100] km
--azimuth-step nan | --azimuth-step must be a finite number
--members 1001 | --members 1001 outside the allowed range [0, 1000]
--fmax 0.1 | --fmax 0.1 outside the allowed range [0.5, 20] Hz
--duration inf | --duration must be a finite number
--radius 101 | --radius 101 outside the allowed range (0, 100] km
--step 0 | --step 0 outside the allowed range (0, inf] km
--strike-step -30 | --strike-step -30 outside the allowed range (0, 360] deg
--gr-b nan | --gr-b must be a finite number
--depths 6 --depths 12 | --depths given more than once (6 and 12)
--radius 10 --radius 20 | --radius given more than once (10.0 and 20.0)
--grid demo --grid quick | --grid given more than once (demo and quick)
--mechanisms thrust --mechanisms normal | --mechanisms given more than once
"""


@pytest.mark.parametrize("values, words", cases(INVERT))
def test_invert_grid_options_refused_before_any_work(tmp_path, capsys, monkeypatch, values,
                                                     words):
    from pipeline.inversion import EXAMPLES_DIR, workflows
    monkeypatch.setattr(workflows, "invert_file", lambda *a, **k: pytest.fail("work started"))
    out, forward = tmp_path / "out", tmp_path / "forward"
    refused(capsys, ["invert", EXAMPLES_DIR / "two_sites.json", "--out", out, "--forward-dir",
                     forward, *values], words, out)
    assert not forward.exists()


def test_invert_help_states_each_presets_value_and_the_range(capsys):
    """An option left unset takes the preset's value: the help says each preset's (the
    presets of docs/inversion.md) and the range."""
    text = help_text(capsys, ["invert"])
    for phrase in [
            "--grid {demo,full,quick,study} forward-grid and candidates preset",
            "unset: full; --quick: quick; --member-study: study",
            "--depths KM,KM hypocentre depths (km); unset: the --grid preset's (full 6,12; "
            "demo 10; study 10; quick 10); 0-40 (above 0)",
            "--magnitudes MW,MW moment magnitudes; unset: the --grid preset's (full 6.5,7; "
            "demo 6.5; study 6,7; quick 6.5); 4.5-7.5",
            "(full 2.5,5,10,20,30; demo 2.5,5,10,20; study 2.5,5,10,20; quick 2.5,6); "
            "0-100 (above 0)",
            "(full 8; demo 6; study 64; quick 2); 0-1000",
            "--seed SEED Latin-hypercube seed; unset: the --grid preset's (20091001 in each)",
            "(full 30; demo 25; study 15; quick 12); 0-100 (above 0)",
            "--step KM epicentre grid spacing (at most half the radius) (km); unset: the "
            "--grid preset's (1 in each); above 0",
            "(full 30; demo 30; study 30; quick 90); 0-360 (above 0)",
            "--gr-b B Gutenberg-Richter prior on magnitude, 10^(-B M); unset: uniform; 0-3",
            "rings 2.5,6 km every 90 deg, 2 members, 15 s motions to 5 Hz; candidates "
            "within 12 km, strike every 90 deg"]:
        assert phrase in text, phrase


@pytest.mark.parametrize("argv, preset", [([], "full"), (["--quick"], "quick"),
                                          (["--grid", "demo"], "demo")])
def test_an_unset_grid_option_is_its_presets_value(argv, preset):
    from pipeline.cli import build_parser
    from pipeline.cli._fields import from_args
    from pipeline.inversion.grid_options import GridOptions
    from pipeline.inversion.presets import PRESETS
    args = build_parser().parse_args(["invert", "obs.json", *argv])
    assert from_args(GridOptions, args).grids() == (preset, PRESETS[preset].table,
                                                     PRESETS[preset].candidates)
    args = build_parser().parse_args(["invert", "obs.json", *argv, "--radius", "7",
                                      "--depths", "8,4"])
    _, table, candidates = from_args(GridOptions, args).grids()
    assert table.depths_km == (4.0, 8.0) and candidates.radius_km == 7.0
    assert candidates.step_km == PRESETS[preset].candidates.step_km
    assert table.members == PRESETS[preset].table.members
