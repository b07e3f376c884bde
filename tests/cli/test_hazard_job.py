"""hazard-job: without the engine one line says how to install it and nothing is written;
options are range-checked before the engine is looked for; with an engine environment
(OQ_PYTHON, or .venv-oq of make oq-case-mrd) the shipped QA case run again gives the
shipped per-realisation curves and constrain's result on them."""
import csv
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
JOB = CASE / "input" / "job.ini"
SPECIMEN = ["--median-g", "0.3", "--beta", "0.4", "--age-ka", "2", "--draws", "0"]


def _engine_python():
    given = os.environ.get("OQ_PYTHON")
    python = Path(given) if given else RECORDS_DIR.parent / ".venv-oq" / "bin" / "python"
    return python if python.is_file() else None


def _run(capsys, *argv):
    code = main(["hazard-job", "--oq-job", str(JOB), *argv])
    return code, capsys.readouterr().err.strip().splitlines()


def test_without_the_engine_one_line_how_to_install(tmp_path, capsys):
    out = tmp_path / "out"
    code, err = _run(capsys, "--oq-python", str(tmp_path / "python"), *SPECIMEN,
                     "--out", str(out))
    assert code != 0 and len(err) == 1
    assert "no OpenQuake engine" in err[0] and "make oq-case-mrd" in err[0]
    assert not out.exists()


def test_a_python_without_the_engine_one_line(tmp_path, capsys):
    code, err = _run(capsys, "--oq-python", sys.executable, *SPECIMEN,
                     "--out", str(tmp_path / "out"))
    assert code != 0 and len(err) == 1, err
    assert "no OpenQuake engine in" in err[0] and "pip install" in err[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv, message", [
    (["--oq-site", "200", "0", *SPECIMEN], "longitude"),
    (["--median-g", "0.3", "--beta", "-1", "--age-ka", "2"], "--beta"),
    (["--median-g", "0.3", "--beta", "0.4", "--age-range-ka", "3", "1"], "age"),
    (["--oq-site", "11.2", "42.4", "--specimen-site", "1", *SPECIMEN], "--specimen-site 1"),
    (["--oq-site", "11.2", "42.4", "--site", "2", *SPECIMEN], "--site 2")])
def test_options_checked_before_the_engine(tmp_path, capsys, argv, message):
    out = tmp_path / "out"
    code, err = _run(capsys, "--oq-python", str(tmp_path / "python"), *argv,
                     "--out", str(out))
    assert code != 0 and len(err) == 1 and message in err[0], err
    assert "OpenQuake engine" not in err[0]
    assert not out.exists()


def _curve(path):
    rows = list(csv.reader(path.read_text().splitlines()[1:]))
    return np.array([float(v) for v in rows[1][3:]])


@pytest.mark.skipif(_engine_python() is None, reason="no OpenQuake engine environment "
                    "(OQ_PYTHON or .venv-oq of make oq-case-mrd): the engine run of "
                    "hazard-job is not tested; the rest is")
def test_the_qa_case_run_gives_the_shipped_curves(tmp_path, capsys, monkeypatch):
    """The engine's Python given relative to the working directory, as `make
    oq-hazard-job` gives it (the engine runs in a directory of its own)."""
    out = tmp_path / "out"
    monkeypatch.chdir(tmp_path)
    python = os.path.relpath(os.path.abspath(_engine_python()), tmp_path)
    code, err = _run(capsys, "--oq-python", python, "--oq-site", "11.202",
                     "42.424", *SPECIMEN, "--out", str(out))
    assert code == 0, err
    export = out / "openquake"
    for rlz in ("000", "001"):
        got, = export.glob(f"hazard_curve-rlz-{rlz}-PGA_*.csv")
        shipped, = CASE.glob(f"hazard_curve-rlz-{rlz}-PGA_*.csv")
        np.testing.assert_allclose(_curve(got), _curve(shipped), rtol=1e-4)
    assert (export / "mrd_pga_pgv.hdf5").is_file()
    assert list((export / "disaggregation").glob("Mag_Dist-*.csv"))
    summary = json.loads((out / "constrain.json").read_text())
    assert summary["branch_count"] == 2
    assert summary["pgv_pga"]["file"].endswith("mrd_pga_pgv.hdf5")
