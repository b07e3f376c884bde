"""A set of result files written as one (:func:`pipeline.files.file_set`): the new set
replaces the command's files (what it no longer writes removed, other files left alone),
a failure leaves the directory as it was, and a stop that comes while the set is put in
place comes after it is whole."""
import os
import signal

import pytest

from pipeline.files import file_set

NAMES = ("a.csv", "b.csv", "summary.json")


def test_what_the_new_set_does_not_hold_is_removed_and_other_files_kept(tmp_path):
    for name in (*NAMES, "notes.txt"):
        (tmp_path / name).write_text("old")
    with file_set(tmp_path, NAMES, ("summary.json",)) as stage:
        (stage / "a.csv").write_text("new")
        (stage / "summary.json").write_text("new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "notes.txt",
                                                           "summary.json"]
    assert (tmp_path / "a.csv").read_text() == "new"
    assert (tmp_path / "notes.txt").read_text() == "old"


def test_a_failure_leaves_the_directory_as_it_was(tmp_path):
    for name in NAMES:
        (tmp_path / name).write_text("old")
    with pytest.raises(RuntimeError):
        with file_set(tmp_path, NAMES, ("summary.json",)) as stage:
            (stage / "a.csv").write_text("new")
            raise RuntimeError("failed half way")
    assert sorted(p.name for p in tmp_path.iterdir()) == list(NAMES)
    assert all((tmp_path / n).read_text() == "old" for n in NAMES)
    fresh = tmp_path / "fresh"
    with pytest.raises(RuntimeError):
        with file_set(fresh, NAMES, ()):
            raise RuntimeError("failed")
    assert not fresh.exists()


def test_a_file_outside_the_set_is_a_programming_error(tmp_path):
    with pytest.raises(ValueError, match="outside the set"):
        with file_set(tmp_path, NAMES, ()) as stage:
            (stage / "other.csv").write_text("x")
    assert list(tmp_path.iterdir()) == []


def test_a_stop_during_the_swap_comes_after_the_set_is_whole(tmp_path, monkeypatch):
    """SIGINT sent while the files are renamed into place: the handler runs once the
    last one is in, not between two."""
    seen = []
    real_replace = os.replace

    def replace_and_interrupt(src, dst):
        real_replace(src, dst)
        if not seen:
            os.kill(os.getpid(), signal.SIGINT)
        seen.append(sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")))

    monkeypatch.setattr(os, "replace", replace_and_interrupt)
    with pytest.raises(KeyboardInterrupt):
        with file_set(tmp_path, NAMES, ("summary.json",)) as stage:
            for name in NAMES:
                (stage / name).write_text("new")
    assert seen[-1] == list(NAMES) and len(seen) == len(NAMES)
    assert all((tmp_path / n).read_text() == "new" for n in NAMES)


def test_a_result_that_json_cannot_hold_is_one_line_naming_its_key():
    import math

    import numpy as np

    from pipeline.files import ToolError, result_json_text
    assert result_json_text({"a": [1.0, 2]}, "x.json").startswith("{")
    with pytest.raises(ToolError, match=r"^x.json: branches\[1\].p is not a finite number; "
                                        "nothing written"):
        result_json_text({"branches": [{"p": 0.5}, {"p": math.nan}]}, "x.json")
    with pytest.raises(ToolError, match=r"^x.json: rates\[2\] is not"):
        result_json_text({"rates": np.array([1.0, 2.0, np.inf])}, "x.json")


def test_a_stage_left_by_a_killed_command_is_removed_and_a_running_ones_kept(tmp_path):
    """SIGKILL leaves a command's staging directory behind; the next command in the folder
    removes it, and leaves the stage of a command still running."""
    import subprocess
    import sys
    killed = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    (tmp_path / f".staging.{killed.pid}.abc.tmp").mkdir()
    killed.kill()
    killed.wait()
    running = tmp_path / f".staging.{os.getppid()}.def.tmp"
    running.mkdir()
    with file_set(tmp_path, NAMES, ("summary.json",)) as stage:
        (stage / "a.csv").write_text("new")
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(["a.csv", running.name])
