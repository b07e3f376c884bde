"""A campaign says how long its rest takes, measured on its first runs, and warns before
hours of work; short campaigns say nothing."""
import contextlib
import io
import math
import re
import signal
import time
from pathlib import Path

import pytest

from pipeline.campaign import executor
from pipeline.campaign.executor import duration_text, execute
from pipeline.campaign.spec import RunSpec
from pipeline.files import write_json
from pipeline.scenario import RunParams


def sleeper(seconds):
    def worker(spec, run_dir):
        time.sleep(seconds)
        write_json(Path(run_dir) / "summary.json", {})
    return worker


def specs(n):
    """``n`` runs without a motion file (their length unknown: 0 s)."""
    return [RunSpec("r", "r", "/no/motion.npz", RunParams(), f"r{k}") for k in range(n)]


@pytest.mark.parametrize("warn_from_s, head", [(1e9, ""), (0.5, "warning: ")])
def test_a_long_campaign_says_its_rest_once_after_its_first_runs(tmp_path, capsys, monkeypatch,
                                                                 warn_from_s, head):
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 0.5)
    monkeypatch.setattr(executor, "WARN_FROM_S", warn_from_s)
    assert execute(specs(10), tmp_path, 2, sleeper(0.2)) == ([], False)
    lines = [line for line in capsys.readouterr().out.splitlines() if "take about" in line]
    assert len(lines) == 1
    found = re.fullmatch(rf"{head}{tmp_path.name}: the other (\d+) runs take about \d+ min at "
                         r"the pace of the first (\d+); Ctrl-C stops the campaign and the "
                         r"same command resumes it, keeping every finished run", lines[0])
    assert found, lines[0]
    rest, first = map(int, found.groups())
    assert first == 2 and rest == 8         # 2 run at once: said after the first 2


def test_a_short_campaign_says_nothing_more(tmp_path, capsys):
    assert execute(specs(4), tmp_path, 2, sleeper(0.05)) == ([], False)
    assert "take about" not in capsys.readouterr().out


def test_a_resumed_campaign_paces_only_the_runs_it_computes(tmp_path, capsys, monkeypatch):
    """Runs finished before the resume are not counted as done in no time."""
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 0.5)
    assert execute(specs(3), tmp_path, 1, sleeper(0.0)) == ([], False)
    capsys.readouterr()
    assert execute(specs(8), tmp_path, 1, sleeper(0.2)) == ([], False)
    line, = [x for x in capsys.readouterr().out.splitlines() if "take about" in x]
    assert "the other 4 runs" in line and "the first 1;" in line


@pytest.mark.parametrize("seconds, text", [(0, "0 min"), (2399, "40 min"), (5400, "1.5 h"),
                                           (9000, "2.5 h"), (3 * 86400, "3.0 d")])
def test_durations_as_people_say_them(seconds, text):
    assert duration_text(seconds) == text


@pytest.mark.parametrize("weights, rest_s", [([4, 4, 1, 1, 1, 1, 1, 1], 3.0),   # per motion s
                                             ([], 12.0),                        # per run
                                             ([4, 4, 0, 1, 1, 1, 1, 1], 12.0)])  # one unknown
def test_the_pace_is_per_second_of_motion_so_long_first_runs_do_not_stretch_it(
        monkeypatch, capsys, weights, rest_s):
    """Two runs of 4 s of motion done in 4 s on 2 cores: six runs of 1 s left take 3 s,
    not the 12 s that a pace per run would say."""
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 0.0)
    said = []
    monkeypatch.setattr(executor, "duration_text", lambda s: said.append(s) or "x")
    bar = executor.ForecastBar(total=8, initial=0, name="c", first=2, weights=weights,
                               file=io.StringIO())
    bar.started, bar.clock = 0.0, lambda: 4.0
    bar.update()
    bar.update()
    assert said == [pytest.approx(rest_s)]


def forecast_lines(paces_s, first=2, weights=()):
    """The lines a ForecastBar of len(paces_s) runs says (tqdm.write: on stdout) when run k
    finishes paces_s[k] wall seconds after run k - 1 (a fake clock)."""
    clock = [0.0]
    bar = executor.ForecastBar(total=len(paces_s), initial=0, name="c", first=first,
                               weights=weights, file=io.StringIO())
    bar.started, bar.clock = 0.0, lambda: clock[0]
    with contextlib.redirect_stdout(io.StringIO()) as out:
        for pace in paces_s:
            clock[0] += pace
            bar.update()
    return [line for line in out.getvalue().splitlines() if "take about" in line]


def test_a_steady_pace_is_said_once(monkeypatch):
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 60.0)
    lines = forecast_lines([100.0] * 20)
    assert len(lines) == 1 and "the other 18 runs take about 30 min" in lines[0]


def test_a_pace_that_slows_is_said_again_with_what_was_said_before(monkeypatch):
    """Two runs of 10 s say 18 x 10 s = 3 min; after the third, of 100 s, all three
    put the other 17 at 17 x 40 s = 11 min where the forecast left 80 s: said again.
    The pace of all runs lags a change, so later lines follow, but each at least twice
    as late as the one before: a few in hours."""
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 60.0)
    paces = [10.0, 10.0] + [100.0] * 18
    lines = forecast_lines(paces)
    assert "the other 18 runs take about 3 min at the pace of the first 2;" in lines[0]
    assert ("the other 17 runs take about 11 min at the pace of all 3 so far, not the 1 min "
            "said before; Ctrl-C stops") in lines[1]
    assert len(lines) <= 1 + math.log2(sum(paces) / sum(paces[:2]))


def test_a_pace_that_speeds_up_is_said_again_and_nothing_below_the_threshold(monkeypatch):
    """Two runs of 100 s say 63 min; runs of 10 s follow.  Not said again before the
    campaign has run twice as long (t = 400 s, 22 runs): then 18 x 400/22 s = 5 min."""
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 60.0)
    lines = forecast_lines([100.0, 100.0] + [10.0] * 38)
    assert len(lines) == 2, lines
    assert lines[0].startswith("warning: c: the other 38 runs take about 63 min")
    assert ("c: the other 18 runs take about 5 min at the pace of all 22 so far, not the 60 "
            "min said before") in lines[1]
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 1e9)
    assert forecast_lines([10.0, 10.0] + [100.0] * 18) == []


def test_the_revision_paces_per_second_of_motion(monkeypatch):
    """Runs of 4 s of motion, then of 1 s, each taking 20 s: first 18 x 1 s at 40/8 s per
    s = 90 s; at t = 100 s (twice the first forecast's time and 60 s on) the other 15
    runs take 15 s of motion at 100/11 s per s, not the 30 s the forecast left."""
    monkeypatch.setattr(executor, "FORECAST_FROM_S", 60.0)
    said = []
    monkeypatch.setattr(executor, "duration_text", lambda s: said.append(s) or "x")
    forecast_lines([20.0] * 20, weights=[4, 4] + [1] * 18)
    # said: the first forecast, then the revision's "not the ... said before", then its rest
    assert said[:3] == [pytest.approx(90.0), pytest.approx(30.0), pytest.approx(15 * 100 / 11)]


@pytest.fixture
def swallowed_ctrl_c():
    """A Ctrl-C whose KeyboardInterrupt a library lost: raised in a ``__del__`` (as in the
    import machinery's weakref callbacks), where Python only prints it."""
    import pipeline

    class Swallower:
        def __del__(self):
            pipeline.stop(signal.SIGINT)

    Swallower()                                # collected at once: the exception is lost
    yield
    pipeline._STOP_ASKED.clear()


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_ctrl_c_a_library_swallowed_still_stops_the_campaign(tmp_path, swallowed_ctrl_c):
    failures, interrupted = execute(specs(6), tmp_path, 1, sleeper(0.3))
    assert interrupted and failures == []
    assert len(list(tmp_path.glob("runs/*/summary.json"))) < 6
