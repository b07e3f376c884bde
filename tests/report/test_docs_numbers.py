"""The docs' measured numbers come from the files the runs write: the macros read what a
bench.json / run-all-steps.tsv states, say which command to run when there is none, and
every macro a docs page calls exists."""
import json
import re
from pathlib import Path

from pipeline.report import docs_numbers

ROOT = Path(__file__).resolve().parents[2]
MACROS = ("bench_value", "bench_speed_table", "engine_shares", "run_all_steps", "report")


def _bench(tmp_path):
    scene = {"scene": "twin, no motion", "us_per_step": 57.12, "cost_vs_still": 1.0,
             "sim_s_per_wall_s": 1.868, "sim_s_per_wall_s_with_startup": 1.638}
    data = {"speed": {"scenes": {"still": scene}},
            "engine_timing": {"engines": [{"engine": "A", "share_pct": 1.0},
                                          {"engine": "B", "share_pct": 61.4},
                                          {"engine": "C", "share_pct": 37.6}]},
            "two_x": {"scenes": {"no friction switch": {"x_default": 1.1756}}}}
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(data))
    return path


def test_bench_numbers_are_the_files(tmp_path):
    path = _bench(tmp_path)
    table = docs_numbers.bench_speed_table(path)
    assert "| still: twin, no motion | 57.1 | 1.00 | 1.87 (1.64) |" in table
    assert docs_numbers.engine_shares(path) == "B 61 %, C 38 %"
    assert docs_numbers.bench_value("two_x.scenes.no friction switch.x_default",
                                    path=path) == "1.18"
    assert docs_numbers.bench_value("engine_timing.engines.1.engine", "{}", path) == "B"


def test_without_the_files_the_docs_say_what_to_run(tmp_path):
    missing = tmp_path / "none.json"
    assert "make bench" in docs_numbers.bench_speed_table(missing)
    assert "make bench" in docs_numbers.bench_value("speed.x", path=_bench(tmp_path))
    assert "make run-all" in docs_numbers.run_all_steps(tmp_path / "none.tsv")
    assert "make run-all" in docs_numbers.report(tmp_path / "none.md")


def test_run_all_steps_add_up(tmp_path):
    path = tmp_path / "steps.tsv"
    path.write_text("step\twall_s\texit\nrecords\t60.0\t0\nsynthetic\t480.0\t0\n")
    table = docs_numbers.run_all_steps(path)
    assert "| records | 1.0 |" in table and "| **total** | **9.0** |" in table


def test_every_macro_the_docs_call_exists():
    called = {m for page in (ROOT / "docs").glob("*.md")
              for m in re.findall(r"\{\{\s*(\w+)\(", page.read_text())}
    assert called and called <= set(MACROS)
    from pipeline.report import docs_macros

    class Env:
        def __init__(self):
            self.macros = {}

        def macro(self, function, name):
            self.macros[name] = function

    env = Env()
    docs_macros.define_env(env)
    assert set(env.macros) == set(MACROS)
