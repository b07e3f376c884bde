"""Bounds before work: lab tables bounded in rows and duration and read by their header
alone, the shake-table campaign's experiments, tests and grid checked before any run, a
hidden-truth file's mechanism, the synthetics' azimuth step, and one long-run gate
(--allow-long) for every long command.  Each refusal is one `error:` line, exit 2, and
writes nothing."""
import json
from dataclasses import replace

import numpy as np
import pytest

from pipeline import campaign, cli
from pipeline.campaign.spec import RunSpec
from pipeline.files import LONG_RUN_S, InputError, check_long
from pipeline.scenario import RunParams


def one_line_error(capsys, code):
    captured = capsys.readouterr()
    assert code == 2, captured.err
    assert captured.err.count("\n") == 1 and captured.err.startswith("error: "), captured.err
    return captured.err, captured.out


def lab_table(path, header, dt=0.005, n=1200, pga_g=0.1):
    """A 2 Hz sine of ``pga_g`` along East, sampled every ``dt`` s."""
    t = dt * np.arange(n)
    rows = "\n".join(f"{a:.6f} {pga_g * np.sin(2 * np.pi * 2.0 * a):.6f}" for a in t)
    path.write_text("\n".join(header) + "\n" + rows + "\n")
    return path


HEADER = ["# lab-table: test", "# units: g", "# axes: 90"]


# ---------------------------------------------------------------- lab tables
@pytest.mark.parametrize("header, dt, words", [
    (HEADER, 3600.0, "more than the 3600 s a lab table may last"),
    (HEADER[1:], 0.005, "without its first line '# lab-table: TITLE'"),
    (HEADER + ["# axes: 0"], 0.005, "'# axes:' given twice"),
    (HEADER[:2] + ["# units: m/s^2"] + HEADER[2:], 0.005, "'# units:' given twice"),
])
@pytest.mark.parametrize("command", ["records", "run"])
def test_bad_lab_tables_are_one_line_through_records_and_run(tmp_path, capsys, header, dt,
                                                            words, command):
    path = lab_table(tmp_path / "lab.txt", header, dt=dt, n=120)
    out = tmp_path / "out"
    args = ([command, str(path)] if command == "records" else
            [command, "--record", str(path)]) + ["--out", str(out)]
    err, _ = one_line_error(capsys, cli.main(args))
    assert words in err and "lab.txt" in err
    assert not out.exists()


def test_a_lab_table_is_bounded_in_rows_before_it_is_parsed(tmp_path, monkeypatch):
    from pipeline.records.readers import lab_table as reader
    from pipeline.records.readers import read_record
    path = lab_table(tmp_path / "lab.txt", HEADER, n=300)
    monkeypatch.setattr(reader, "MAX_SAMPLES", 299)
    monkeypatch.setattr(reader.np, "loadtxt", lambda *a, **k: pytest.fail("parsed"))
    with pytest.raises(InputError, match="300 rows, more than the 299"):
        read_record(path)


def test_a_table_at_its_bounds_is_read(tmp_path):
    """Exactly MAX_DURATION_S long: read (the bound is inclusive), the values as written."""
    from pipeline.records.readers import read_record
    from pipeline.records.readers.lab_table import MAX_DURATION_S
    path = lab_table(tmp_path / "lab.txt", HEADER, dt=MAX_DURATION_S / 199, n=200)
    stream, info = read_record(path)
    assert info["format"] == "lab-table"
    assert stream[0].stats.delta * (stream[0].stats.npts - 1) == pytest.approx(MAX_DURATION_S)


# ---------------------------------------------------------------- shake-table
def experiments(tmp_path, rows, motions=True):
    """An experiment table of ``rows`` (test, date, observed) with a lab table each."""
    lines = ["test,date,pga_g,pgv_pga_s,sp1_overturned,motion_file"]
    for k, (test, day, observed) in enumerate(rows):
        name = ""
        if motions:
            name = f"{test}.txt"
            lab_table(tmp_path / name, HEADER, pga_g=0.1 + 0.01 * k)
        lines.append(f"{test},{day},0.1,0.05,{observed},{name}")
    path = tmp_path / "tests.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("options, words", [
    (["--tests", "NOPE"], "unknown test(s) NOPE"),
    (["--tests", "A,NOPE"], "unknown test(s) NOPE"),
    (["--tests", "A,A"], "--tests names A twice"),
    (["--grid", "damping=0.1,0.1"], "damping: value 0.1 given twice"),
    (["--grid", "mu_s=0.3;mu_k=0.9"], "mu_k 0.9 above mu_s 0.3"),
    (["--grid", "mu_k=0.8"], "mu_k 0.8 above mu_s 0.7 (default)"),
    (["--validate-from", "2000-01-01"], "nothing to calibrate on"),
    (["--tests", "B"], "nothing to calibrate on"),
])
def test_shake_table_options_are_refused_before_any_run(tmp_path, capsys, options, words):
    table = experiments(tmp_path, [("A", "2021-06-01", 1), ("B", "2021-08-02", 0)])
    out = tmp_path / "out"
    err, _ = one_line_error(capsys, cli.main(["campaign", "shake-table", "--experiments",
                                              str(table), "--out", str(out), *options]))
    assert words in err
    assert not out.exists()


def test_an_experiment_table_without_rows_is_one_line(tmp_path, capsys):
    table = tmp_path / "tests.csv"
    table.write_text("test,date,pga_g,pgv_pga_s,sp1_overturned,motion_file\n")
    out = tmp_path / "out"
    err, _ = one_line_error(capsys, cli.main(["campaign", "shake-table", "--experiments",
                                              str(table), "--out", str(out)]))
    assert "tests.csv: no experiments" in err
    assert not out.exists()


def still_worker(spec, run_dir):
    """Stands in for YADE: the specimen stands."""
    from pipeline.outcome.summary import RunSummary
    RunSummary.still(spec.record_id, [{"name": "monolithic", "x": 0.0, "y": 0.0}]).save(
        run_dir / "summary.json")


def test_without_validation_tests_the_calibration_is_scored_alone(tmp_path, capsys,
                                                                   monkeypatch):
    """Every test before --validate-from: the calibration runs and is scored (a specimen
    that always stands: accuracy = the fraction of tests that stood), no validation run,
    shake_table.json written."""
    campaign.discover()
    monkeypatch.setitem(campaign.CAMPAIGNS, "shake-table",
                        replace(campaign.CAMPAIGNS["shake-table"], worker=still_worker))
    table = experiments(tmp_path, [("A", "2021-06-01", 1), ("B", "2021-06-02", 0),
                                   ("C", "2021-06-03", 0)])
    out = tmp_path / "out"
    assert cli.main(["campaign", "shake-table", "--experiments", str(table), "--out",
                     str(out), "--grid", "damping=0.1,0.2", "--jobs", "1",
                     "--validate-from", "2030-01-01", "--animations", "0"]) == 0
    assert "the calibration's scores alone" in capsys.readouterr().out
    result = json.loads((out / "shake_table.json").read_text())
    assert result["splits"]["calibration"]["model"]["accuracy"] == pytest.approx(2 / 3)
    assert result["splits"]["validation"]["model"]["n"] == 0
    assert result["chosen"]["label"] == "damping=0.1"           # a tie: the first
    assert len(list((out / "runs").glob("*/summary.json"))) == 6  # 2 sets x 3 tests
    assert not (out / "validation.csv").exists()


# ---------------------------------------------------------------- invert, synthetics
@pytest.mark.parametrize("mechanism", [{"name": "strike-slip"}, ["strike-slip"]])
def test_a_truth_mechanism_of_the_wrong_type_is_one_line(tmp_path, capsys, mechanism):
    truth = tmp_path / "truth.json"
    truth.write_text(json.dumps({"source": {
        "mechanism": mechanism, "strike_deg": 30, "depth_km": 10, "mw": 6.5, "east_km": 4,
        "north_km": -3}, "sites": [{"name": "A", "east_km": 0, "north_km": 0, "twins": 1}]}))
    out = tmp_path / "out"
    err, _ = one_line_error(capsys, cli.main(["invert", "--hidden-truth", str(truth),
                                              "--out", str(out)]))
    assert "source mechanism must be one of" in err
    assert not out.exists()


@pytest.fixture
def synthetics_dir(tmp_path, monkeypatch):
    from pipeline.motion.synthetics import sites
    monkeypatch.setattr(sites, "DEFAULT_OUT_DIR", tmp_path / "synthetics")
    return tmp_path / "synthetics"


@pytest.mark.parametrize("step, words", [
    ("1e-7", "outside the allowed range [0.01, 360] deg"),
    ("0", "outside the allowed range [0.01, 360] deg"),
    ("400", "outside the allowed range [0.01, 360] deg"),
    ("nan", "--step must be a finite number")])
def test_synthetics_step_is_refused_by_its_range(synthetics_dir, capsys, step, words):
    err, _ = one_line_error(capsys, cli.main(["synthetics", "--step", step]))
    assert words in err
    assert not synthetics_dir.exists()


# ---------------------------------------------------------------- the long-run gate
def test_the_gate_refuses_over_an_hour_and_warns_when_allowed(capsys):
    assert check_long("x", 400, 9.0, 1, False) == 3600.0            # an hour: no gate
    with pytest.raises(InputError, match=r"x \(401 runs, 9 core-s each\) would take about "
                                         r"60 min on 1 core\(s\), over 1 h: add --allow-long"):
        check_long("x", 401, 9.0, 1, False)
    assert check_long("x", 802, 9.0, 2, True) == pytest.approx(3609.0)
    assert capsys.readouterr().out.startswith("warning: x (802 runs")


def test_synthetics_of_108000_sites_hit_the_gate(synthetics_dir, capsys):
    err, _ = one_line_error(capsys, cli.main(["synthetics", "--step", "0.01", "--jobs", "2"]))
    assert "216000 sites" in err and "would take about" in err   # 108,000 a source and "--allow-long" in err
    assert not synthetics_dir.exists()


def test_synthetics_with_allow_long_start(synthetics_dir, capsys, monkeypatch):
    """Past the gate the computation starts (the first pyprop8 call stands in here)."""
    from pipeline.motion.synthetics import compute

    def started(call):
        raise InputError("started")
    monkeypatch.setattr(compute, "_point_source_task", started)
    assert cli.main(["synthetics", "--step", "1", "--jobs", "1", "--source", "strike_slip",
                     "--allow-long"]) == 2
    captured = capsys.readouterr()          # stderr: the progress bar, then the line
    assert "error: started\n" in captured.err
    assert "warning: synthetics of strike_slip (1080 sites" in captured.out


def toy_campaign(run_core_s):
    """A campaign of 100 runs whose worker writes a summary and nothing else."""
    from pipeline.outcome.summary import RunSummary

    def specs(records, campaign_dir):
        return [RunSpec("toy", "toy", "/toy.npz", RunParams(), f"run{k:03d}")
                for k in range(100)]

    def worker(spec, run_dir):
        RunSummary.still("toy", []).save(run_dir / "summary.json")

    def outputs(specs_, campaign_dir, failures, animations, figures=True):
        return {}
    return campaign.Campaign("toy-long", "toy", specs, worker, outputs,
                             run_core_s=run_core_s)


def test_a_long_campaign_is_refused_before_any_run_and_starts_with_allow_long(
        tmp_path, capsys, monkeypatch):
    """100 runs of 40 core-s on 1 core: 67 min, refused naming the estimate and the flag;
    with --allow-long every run is done; 36 core-s a run (an hour) passes."""
    campaign.discover()
    monkeypatch.setitem(campaign.CAMPAIGNS, "toy-long", toy_campaign(40.0))
    out = tmp_path / "out"
    args = ["campaign", "toy-long", "--jobs", "1", "--out", str(out), "--animations", "0"]
    err, _ = one_line_error(capsys, cli.main(args))
    assert "campaign toy-long (100 runs, 40 core-s each) would take about 67 min" in err
    assert "--allow-long" in err
    assert not out.exists()
    assert cli.main(args + ["--allow-long"]) == 0
    assert len(list((out / "runs").glob("*/summary.json"))) == 100
    monkeypatch.setitem(campaign.CAMPAIGNS, "toy-long", toy_campaign(LONG_RUN_S / 100))
    hour = tmp_path / "hour"
    assert cli.main(["campaign", "toy-long", "--jobs", "1", "--out", str(hour)]) == 0
    assert len(list((hour / "runs").glob("*/summary.json"))) == 100


def sp1_grid(points):
    """A grid of ``points`` (a cube) parameter sets with mu_k <= mu_s."""
    side = round(points ** (1 / 3))
    values = {"damping": np.linspace(0.05, 0.5, side), "kn": np.geomspace(1e7, 1e9, side),
              "mu_s": np.linspace(0.6, 1.5, side)}
    return ";".join(f"{k}=" + ",".join(f"{v:.6g}" for v in vs) for k, vs in values.items())


def test_a_1000_point_shake_table_grid_is_refused_before_any_run(tmp_path, capsys,
                                                                  monkeypatch):
    """The shipped 490 tests x a 1000-point grid: refused naming its estimate; with
    --allow-long the calibration starts (run_campaign stands in)."""
    out = tmp_path / "out"
    args = ["campaign", "shake-table", "--grid", sp1_grid(1000), "--jobs", "2", "--out",
            str(out)]
    err, _ = one_line_error(capsys, cli.main(args))
    assert "shake-table (" in err and "would take about" in err and "--allow-long" in err
    assert not out.exists()
    stages = []

    def started(name, **kwargs):
        stages.append(kwargs["options"]["stage"])
        raise InputError("started")
    monkeypatch.setattr(campaign, "run_campaign", started)
    err, out_text = one_line_error(capsys, cli.main(args + ["--allow-long"]))
    assert err == "error: started\n" and stages == ["calibration"]
    assert "warning: shake-table (" in out_text


def hidden_truth(tmp_path, sites, twins):
    truth = tmp_path / "truth.json"
    truth.write_text(json.dumps({"source": {
        "mechanism": "strike-slip", "strike_deg": 30, "depth_km": 10, "mw": 6.5,
        "east_km": 0, "north_km": 0},
        "sites": [{"name": f"S{k}", "east_km": 1.0 + 0.1 * k, "north_km": 0.0,
                   "twins": twins} for k in range(sites)]}))
    return truth


def test_a_hidden_truth_of_thousands_of_runs_hits_the_gate(tmp_path, capsys, monkeypatch):
    """100 sites x 50 twins with the quick table: the truth's 5,000 runs take hours:
    refused before any run; with --allow-long the forward table starts."""
    from pipeline.inversion import forward
    truth = hidden_truth(tmp_path, 100, 50)
    out, fwd = tmp_path / "out", tmp_path / "forward"
    args = ["invert", "--hidden-truth", str(truth), "--quick", "--jobs", "2", "--out",
            str(out), "--forward-dir", str(fwd)]
    err, _ = one_line_error(capsys, cli.main(args))
    assert "and the hidden truth's runs" in err and "--allow-long" in err
    assert not out.exists() and not fwd.exists()

    def started(*args, **kwargs):
        raise InputError("started")
    monkeypatch.setattr(forward, "run_forward", started)
    err, out_text = one_line_error(capsys, cli.main(args + ["--allow-long"]))
    assert err == "error: started\n" and "warning: this forward table" in out_text
    small = hidden_truth(tmp_path, 2, 1)                 # the quick table alone: no gate
    err, out_text = one_line_error(capsys, cli.main(
        ["invert", "--hidden-truth", str(small), "--quick", "--jobs", "2", "--out", str(out),
         "--forward-dir", str(fwd)]))
    assert err == "error: started\n" and "warning" not in out_text


def test_a_units_line_in_words_is_a_comment_beside_the_units(tmp_path):
    """As the shipped SP1 tables have it: '# units: g', then '# units: time_s = s, ...'
    describing the columns; read, in g."""
    from pipeline.constants import STANDARD_GRAVITY
    from pipeline.records.readers import read_record
    path = lab_table(tmp_path / "lab.txt", HEADER + ["# units: time_s = s, accel_g = g"],
                     n=200, pga_g=0.5)
    stream, _ = read_record(path)
    assert np.abs(stream[0].data).max() == pytest.approx(0.5 * STANDARD_GRAVITY, rel=1e-5)


def test_every_campaign_without_records_passes_the_gate_before_its_runs(tmp_path, monkeypatch):
    """The gate reads each run's cost from its spec: the verification campaign (runs that
    are checks, not RunSpecs) and the paper's sweeps reach their runs (stood in for)."""
    reached = []
    monkeypatch.setattr(campaign, "_run_specs",
                        lambda c, name, specs, *a, **k: reached.append((name, len(specs))))
    for name in ("verification", "slenderness", "friction"):
        campaign.run_campaign(name, campaign_dir=tmp_path / name, jobs=2, allow_long=False)
    assert [name for name, _ in reached] == ["verification", "slenderness", "friction"]
    assert all(n > 0 for _, n in reached)


def test_a_negative_number_of_animations_is_refused_before_any_run(tmp_path, capsys):
    """--animations -1 animated every toppled run but the last, without a word."""
    out = tmp_path / "out"
    err, _ = one_line_error(capsys, cli.main(["campaign", "verification", "--out", str(out),
                                              "--animations", "-1"]))
    assert "--animations -1" in err and "0 or more" in err
    assert not out.exists()
