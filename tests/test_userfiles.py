"""The one reading helper of user files refuses what is not a regular file before it opens
it (a named pipe without a writer would block a reader for ever), and the loaders that
took paths of their own go through it.  Each test has a generous hang bound, so that a
regression fails instead of hanging."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from pipeline import PROJECT_ROOT
from pipeline.files import InputError
from pipeline.userfiles import (check_regular, read_bytes, read_json, read_text,
                                read_user_bytes, read_user_text, Unreadable)
from tests.hang import hang_bound as bound

HANG_S = 60       # far beyond what refusing a file takes; reached only by a blocked open


def hang_bound(seconds=HANG_S):
    """Raise AssertionError once ``seconds`` pass (a blocked open of a named pipe is
    interrupted by the signal)."""
    return bound(seconds, AssertionError, ": a blocked read")


def command(*args, timeout=3 * HANG_S):
    """(exit status, stderr) of ``python -m pipeline args``; a hang fails the test."""
    try:
        done = subprocess.run([sys.executable, "-m", "pipeline", *map(str, args)],
                              cwd=PROJECT_ROOT, capture_output=True, text=True,
                              timeout=timeout, env={**os.environ, "PYTHONPATH": str(PROJECT_ROOT)})
    except subprocess.TimeoutExpired:
        pytest.fail(f"no answer within {timeout} s: {' '.join(map(str, args))}")
    return done.returncode, done.stderr.strip()


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "pipe.csv"
    os.mkfifo(path)                           # no writer: opening it to read blocks
    return path


def test_the_helpers_refuse_a_named_pipe_before_opening_it(fifo):
    with hang_bound():
        for reader in (read_bytes, read_text):
            with pytest.raises(Unreadable, match="is not a regular file") as caught:
                reader(fifo)
            assert caught.value.kind == "type"
        for reader in (read_user_bytes, read_user_text, read_json):
            with pytest.raises(InputError, match=f"{fifo} is not a regular file"):
                reader(fifo, "table")
        with pytest.raises(InputError, match=f"table {fifo} is not a regular file"):
            check_regular(fifo, "table")


def test_the_helpers_read_regular_files_and_pass_over_directories(tmp_path):
    path = tmp_path / "a.csv"
    path.write_bytes(b"\xef\xbb\xbfa,b\n")
    assert read_bytes(path) == b"\xef\xbb\xbfa,b\n"
    assert read_text(path) == "a,b\n"                       # the BOM dropped
    with pytest.raises(Unreadable, match="larger than"):
        read_bytes(path, limit=3)
    check_regular(path, "table")
    check_regular(tmp_path, "table")                        # a directory: its own message
    check_regular(tmp_path / "absent", "table")             # absent: its own message
    with pytest.raises(InputError, match="is a directory"):
        read_user_bytes(tmp_path, "table")


def test_a_named_pipe_among_a_logic_trees_curves_is_refused(tmp_path):
    tree = tmp_path / "tree"
    shutil.copytree(PROJECT_ROOT / "records/hazard/openquake_logictree_case_11", tree)
    os.mkfifo(tree / "hazard_curve-rlz-000_PGA.csv")
    out = tmp_path / "out"
    status, err = command("constrain", "--logic-tree", tree, "--median-g", "0.3", "--beta",
                          "0.4", "--age-ka", "2", "--age-sd-ka", "0.3", "--out", out)
    assert status == 2 and len(err.splitlines()) == 1, err
    assert "hazard_curve-rlz-000_PGA.csv is not a regular file" in err
    assert not out.exists()


def test_a_named_pipe_as_the_providers_table_is_refused(tmp_path, fifo):
    out = tmp_path / "out"
    status, err = command("campaign", "shake-table", "--members", "8", "--providers", fifo,
                          "--out", out)
    assert status == 2, err
    assert err.splitlines()[-1] == f"error: --providers {fifo} is not a regular file " \
                                   "(a named pipe, device or socket)"
    assert not any(out.glob("*.csv")) if out.exists() else True


@pytest.mark.parametrize("loader", ["records", "motion", "experiments", "free_rocking"])
def test_other_loaders_refuse_a_named_pipe(fifo, loader):
    from pipeline.campaign.shake_table_experiments import load_experiments
    from pipeline.motion import Motion
    from pipeline.records import resolve
    from pipeline.verification.contact_workflow import load_free_rocking
    load = {"records": resolve, "motion": Motion.load, "experiments": load_experiments,
            "free_rocking": load_free_rocking}[loader]
    with hang_bound(), pytest.raises(InputError, match="is not a regular file"):
        load(Path(fifo))


def test_a_named_pipe_as_the_forward_table_is_refused(fifo):
    from pipeline.inversion.table import ForwardTable
    with hang_bound(), pytest.raises(InputError, match="forward table .* is not a regular file"):
        ForwardTable.load(fifo)
