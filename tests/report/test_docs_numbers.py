"""The docs' measured numbers come from the files the runs write: the macros read what a
bench.json / run-all-steps.tsv states, say which command to run when there is none, and
every macro a docs page calls exists."""
import json
import re
from pathlib import Path

from pipeline.report import docs_numbers

ROOT = Path(__file__).resolve().parents[2]
MACROS = ("bench_convergence_table", "bench_value", "column_examples", "column_sources",
          "bench_speed_table", "engine_shares", "run_all_steps", "run_all_minutes",
          "setting", "time_step_table", "twin_time_step", "value", "report", "report_section",
          "record_value", "record_rocking_hd", "member_ranges_table", "table_motion_value")


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


def test_time_step_table_takes_the_worse_libm_path(tmp_path):
    rows = [{"libm": libm, "damping": 0.36, "ratio_to_limit": ratio, "model": "twin",
             "dt_factor": 0.235 * ratio, "rotation_deg": rotation}
            for libm, ratio, rotation in (("native", 1.0, 1e-4), ("second", 1.0, 3e-4),
                                          ("native", 1.3, 2.5), ("second", 1.3, 1.5))]
    path = tmp_path / "bench.json"
    path.write_text(json.dumps({"time_step_limit": {"seconds": 5.0, "rows": rows}}))
    table = docs_numbers.time_step_table(path)
    assert "| twin | 0.36 | 0.235 | 0.0003 | 2.5 |" in table
    assert "make bench" in docs_numbers.time_step_table(tmp_path / "none.json")


def test_a_setting_is_quoted_from_its_module():
    from pipeline.campaign import executor
    assert docs_numbers.setting("pipeline.campaign.executor.RUN_CORE_S", "{:.3f}") == \
        f"{executor.RUN_CORE_S:.3f}"
    assert docs_numbers.setting("pipeline.campaign.executor.FORECAST_FROM_S", "{:g}", 1 / 60) \
        == f"{executor.FORECAST_FROM_S / 60:g}"


def test_convergence_table_has_a_row_per_setting_and_a_cell_per_column(tmp_path):
    rows = [{"parameter": parameter, "value": value, "column": column, "toppled": toppled,
             "downfall_azimuth_deg": azimuth, "impact_time_s": 3.0, "wall_s": wall}
            for parameter, value, column, toppled, azimuth, wall in (
                ("dt_factor", 0.235, "drums", True, 27.55, 4.0),
                ("dt_factor", 0.235, "monolithic", True, 32.87, 4.0),
                ("rim_points", 8, "drums", True, 58.43, 3.79),
                ("rim_points", 8, "monolithic", False, None, 3.79))]
    path = tmp_path / "bench.json"
    path.write_text(json.dumps({"convergence": rows}))
    table = docs_numbers.bench_convergence_table(path).splitlines()
    assert table[0] == "| setting | drums azimuth (deg) | monolithic azimuth (deg) | wall (s) |"
    assert table[2:] == ["| time-step factor 0.235 | 27.6 | 32.9 | 4.0 |",
                         "| rim points 8 | 58.4 | standing | 3.8 |"]
    assert "make bench" in docs_numbers.bench_convergence_table(tmp_path / "none.json")


def test_column_table_states_what_a_cylinder_is(tmp_path):
    # a marble cylinder: mass rho pi d^2 h / 4, uplift ratio d / h (statics of one block)
    path = tmp_path / "cylinder.json"
    path.write_text(json.dumps({"name": "cylinder", "density": 2500.0, "blocks": [
        {"shape": "frustum", "height": 2.0, "bottom_diameter": 0.5, "top_diameter": 0.5}]}))
    row = docs_numbers.column_examples([str(path)]).splitlines()[-1]
    cells = [c.strip() for c in row.strip("|").split("|")]
    mass_t = 2500.0 * 3.141592653589793 * 0.25 ** 2 * 2.0 / 1000.0
    assert cells[:4] == ["`cylinder`", "1 -> 1", f"{mass_t:.3g} t", "0.250 (0.250)"]


def test_column_sources_are_the_files_words():
    for path in sorted((ROOT / "pipeline" / "scenario" / "columns").glob("*.json")):
        stated = json.loads(path.read_text())
        line = docs_numbers.column_sources([str(path)])
        assert stated["source"] in line and stated.get("notes", "") in line


def test_record_values_are_table_1(tmp_path):
    path = tmp_path / "records.csv"
    path.write_text("id,label,pga_h\nGM20,Izmit,2.4525\n")
    assert docs_numbers.record_value("GM20", "pga_h", path=path) == "2.45"
    assert docs_numbers.record_rocking_hd("GM20", path=path) == "4.0"   # 9.81 / 2.4525
    assert "make run-all" in docs_numbers.record_value("NF99", "pga_h", path=path)
    assert "make run-all" in docs_numbers.record_rocking_hd("GM20", path=tmp_path / "x.csv")


def test_table_motion_values_are_the_shipped_table():
    """The docs' numbers of what the 200 Hz motions lose: the shipped table's, counted here
    from its rows."""
    from pipeline.campaign.shake_table_motion import load_table_motion
    rows = load_table_motion()
    assert docs_numbers.table_motion_value("tests", "{}") == str(len(rows)) == "490"
    higher = sum(row.pga_200hz_g > row.pga_800hz_g for row in rows)
    assert docs_numbers.table_motion_value("higher_at_200hz", "{}") == str(higher)
    largest = max(row.above_shipped_s for row in rows) * 1000
    assert docs_numbers.table_motion_value("above_max_ms") == f"{largest:.1f}"


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
    assert docs_numbers.run_all_minutes(path) == "9"


def test_values_of_the_quoted_files(tmp_path):
    target = tmp_path / "shake-table" / "shake_table.json"
    target.parent.mkdir()
    target.write_text(json.dumps({"splits": {"validation": {"model": {
        "accuracy": 0.8614, "accuracy_95": [0.81, 0.9]}}}, "validate_from": "2021-08-01"}))
    value = docs_numbers.value
    source = "shake-table/shake_table.json"
    assert value(source, "splits.validation.model.accuracy", "{:.3f}", root=tmp_path) == "0.861"
    assert value(source, "splits.validation.model.accuracy", "{:.0f}", 100,
                 root=tmp_path) == "86"
    assert value(source, "splits.validation.model.accuracy_95.1", root=tmp_path) == "0.90"
    assert value(source, "validate_from", "{}", root=tmp_path) == "2021-08-01"
    assert "make shake-table" in value(source, "splits.nothing", root=tmp_path)
    assert "make invert-study" in value("inversion/member-study/member_study.json", "x",
                                        root=tmp_path)
    try:
        value("somewhere/else.json", "x", root=tmp_path)
    except ValueError as error:
        assert "somewhere/else.json" in str(error)
    else:
        raise AssertionError("a file the docs do not quote was accepted")


REPORT_TEXT = """# Toppling columns: results report

## Verification against rocking theory

- Housner free rocking: impact times within 2.2 %

### A table

![Fig. 4](verification/fig4_housner.png)

## Slenderness sweep (hd)

- drums topple from h/d 7
"""


def test_a_report_section_is_quoted_whole_and_only(tmp_path):
    path = tmp_path / "REPORT.md"
    path.write_text(REPORT_TEXT)
    section = docs_numbers.report_section("Verification", path)
    assert section.startswith("- Housner free rocking: impact times within 2.2 %")
    assert "##### A table" in section and "h/d 7" not in section
    assert docs_numbers.figures(section) == ["verification/fig4_housner.png"]
    assert "make run-all" in docs_numbers.report_section("Fragility", path)
    assert "make invert-study" in docs_numbers.report_section(
        "How many", tmp_path / "none.md", command="make invert-study")


def test_the_site_shows_the_figures_of_the_quoted_sections(tmp_path, monkeypatch):
    from pipeline.report import docs_macros
    results = tmp_path / "results"
    (results / "verification").mkdir(parents=True)
    (results / "verification" / "fig4_housner.png").write_bytes(b"png")
    (results / "REPORT.md").write_text(REPORT_TEXT)
    monkeypatch.setattr(docs_macros, "RESULTS_DIR", results)

    class Page:
        url = "campaigns/"

    class Env:
        def __init__(self):
            self.macros, self.variables, self.page = {}, {}, Page()
            self.conf = {"site_dir": str(tmp_path / "site")}

        def macro(self, function, name):
            self.macros[name] = function

    env = Env()
    docs_macros.define_env(env)
    text = env.macros["report_section"]("Verification", results / "REPORT.md")
    # an HTML image: mkdocs --strict checks Markdown links against docs/, and the figure
    # is copied beside the page only after the build
    assert '<img alt="' in text and 'src="verification/fig4_housner.png"' in text
    assert "![" not in text
    docs_macros.on_post_build(env)
    assert (tmp_path / "site" / "campaigns" / "verification" / "fig4_housner.png").is_file()


def test_every_macro_the_docs_call_exists():
    called = {m for page in (ROOT / "docs").glob("*.md")
              for m in re.findall(r"\{\{\s*(\w+)\(", page.read_text())}
    assert called and called <= set(MACROS)
    from pipeline.report import docs_macros

    class Env:
        def __init__(self):
            self.macros, self.variables = {}, {}

        def macro(self, function, name):
            self.macros[name] = function

    env = Env()
    docs_macros.define_env(env)
    assert set(env.macros) == set(MACROS)


def test_a_null_in_a_quoted_file_is_said_as_none(tmp_path):
    bench = tmp_path / "bench.json"
    bench.write_text(json.dumps({"section": {"diff_g": None, "runs": 3}}))
    assert docs_numbers.bench_value("section.diff_g", "{:.2f}", path=bench) == "none"
    assert docs_numbers.bench_value("section.runs", "{:d}", path=bench) == "3"


def test_every_file_the_docs_quote_is_one_of_the_quoted_files():
    """value("FILE", ...) in a page names a file of SOURCES (with the command writing it)."""
    quoted = {m for page in (ROOT / "docs").glob("*.md")
              for m in re.findall(r"\{\{\s*value\(\s*\"([^\"]+)\"", page.read_text())}
    assert "field-rock-quick-survival-bradley2012/survival.json" in quoted
    assert quoted <= set(docs_numbers.SOURCES)
