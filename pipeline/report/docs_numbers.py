"""Numbers and tables of the documentation, read from the files the project writes
(``results/bench/bench.json`` from ``make bench``, ``results/run-all-steps.tsv`` and
``results/REPORT.md`` from ``make run-all``, the JSON summaries of :data:`SOURCES`), so no
measurement is typed by hand.  The docs pages call these through the mkdocs-macros hook
:mod:`pipeline.report.docs_macros`; a file not written yet renders as a note saying which
command writes it."""
import importlib
import json
import re
from functools import cache, reduce

import pandas as pd

from pipeline import RESULTS_DIR, paper
from pipeline.constants import MODEL_GRAVITY
from pipeline.campaign.column_file import matched_kn
from pipeline.campaign.shake_table_experiments import SPECIMEN, load_experiments
from pipeline.campaign.shake_table_motion import load_table_motion, table_motion_summary
from pipeline.report import campaigns
from pipeline.scenario import Column, Contact, scene_params
from pipeline.scenario.column_format import example_names
from pipeline.scenario.geometry import ColumnGeometry

BENCH_JSON = RESULTS_DIR / "bench" / "bench.json"
RUN_ALL_STEPS = RESULTS_DIR / "run-all-steps.tsv"
RECORDS_TABLE = RESULTS_DIR / "records" / "records.csv"
REPORT = RESULTS_DIR / "REPORT.md"
# the JSON summaries the docs quote (paths under results/) and the command writing each
SOURCES = {
    "bench/bench.json": "make bench",
    "verification/verification.json": "make run-all",
    "shake-table/shake_table.json": "make shake-table",
    "contact-convergence/convergence.json": "make contact-convergence",
    "inversion/demo_summary.json": "make run-all",
    "inversion/member-study/member_study.json": "make invert-study",
    "rock-survival/survival.json": "make rock-survival",
    "field-rock-quick-survival/survival.json": "make run-all",
    "field-rock-quick-survival-bradley2012/survival.json": "make run-all",
}
FIGURE = re.compile(r"!\[([^\]]*)\]\(([^)\s]+)\)")     # ![alt](path)


def _not_yet(command):
    return f"*(not measured yet: run `{command}`)*"


def _read_json(path=BENCH_JSON):
    return json.loads(path.read_text()) if path.is_file() else None


def _json_value(path, key, fmt, times, command):
    data = _read_json(path)
    if data is None:
        return _not_yet(command)
    try:
        found = reduce(lambda v, k: v[int(k)] if isinstance(v, list) else v[k],
                       key.split("."), data)
    except (KeyError, IndexError, ValueError, TypeError):
        return _not_yet(command)
    if found is None:               # a file's null: nothing to quote (e.g. no crossing)
        return "none"
    return fmt.format(found * times if isinstance(found, (int, float))
                      and not isinstance(found, bool) else found)


def bench_value(key, fmt="{:.2f}", path=BENCH_JSON):
    """One number of ``bench.json`` by its dotted ``key`` (list items by index), formatted
    with ``fmt``; a note while ``make bench`` has not run or the key is missing."""
    return _json_value(path, key, fmt, 1, "make bench")


def value(source, key, fmt="{:.2f}", times=1, root=RESULTS_DIR):
    """One value of the JSON file ``source`` (a key of :data:`SOURCES`, a path under
    ``results/``) by its dotted ``key``, multiplied by ``times`` (100 for a percentage) and
    formatted with ``fmt``; a note naming the command while the file or the key is not
    there."""
    if source not in SOURCES:
        raise ValueError(f"docs: {source!r} is not one of the quoted files {sorted(SOURCES)}")
    return _json_value(root / source, key, fmt, times, SOURCES[source])


def bench_speed_table(path=BENCH_JSON):
    """Markdown table of bench section 2: microseconds per step, cost against the still
    scene and simulated seconds per wall second (with YADE's start-up) per scene."""
    data = _read_json(path)
    if data is None or "speed" not in data:
        return _not_yet("make bench")
    lines = ["| scene | us/step | x still | simulated s per wall s (with start-up) |",
             "|---|---|---|---|"]
    for name, row in data["speed"]["scenes"].items():
        lines.append(f"| {name}: {row['scene']} | {row['us_per_step']:.1f} | "
                     f"{row['cost_vs_still']:.2f} | {row['sim_s_per_wall_s']:.2f} "
                     f"({row['sim_s_per_wall_s_with_startup']:.2f}) |")
    return "\n".join(lines)


def engine_shares(path=BENCH_JSON, least_pct=2.0):
    """'engine share %' of bench section 1 (twin model, shaking), largest first, engines
    below ``least_pct`` left out."""
    data = _read_json(path)
    if data is None or "engine_timing" not in data:
        return _not_yet("make bench")
    rows = sorted(data["engine_timing"]["engines"], key=lambda e: -e["share_pct"])
    return ", ".join(f"{e['engine']} {e['share_pct']:.0f} %" for e in rows
                     if e["share_pct"] >= least_pct)


def time_step_table(path=BENCH_JSON):
    """Markdown table of bench section 9: per model and contact damping, the allowed time
    step factor and the largest body rotation (deg) of a still column held on a still
    pedestal at that factor and at 1.3x it, the larger of the two libm paths."""
    data = _read_json(path)
    if data is None or "time_step_limit" not in data:
        return _not_yet("make bench")
    rows = data["time_step_limit"]["rows"]
    ratios = sorted({r["ratio_to_limit"] for r in rows})
    largest = {}
    for r in rows:
        key = (r["model"], r["damping"], r["ratio_to_limit"])
        largest[key] = max(largest.get(key, 0.0), r["rotation_deg"])
    factor = {(r["model"], r["damping"]): r["dt_factor"] for r in rows
              if r["ratio_to_limit"] == 1.0}
    lines = ["| model | damping | allowed factor | "
             + " | ".join(f"rotation (deg) at {k:g}x" for k in ratios) + " |",
             "|---|---|---|" + "---|" * len(ratios)]
    for model, damping in sorted(factor):
        cells = " | ".join(f"{largest[(model, damping, k)]:.3g}" for k in ratios)
        lines.append(f"| {model} | {damping:g} | {factor[(model, damping)]:.3f} | {cells} |")
    return "\n".join(lines)


def setting(name, fmt="{:g}", times=1):
    """A setting of the code by its dotted ``name`` (``package.module.NAME``), multiplied by
    ``times`` (1/60: seconds as minutes) and formatted: the docs quote it from its one
    home."""
    module, _, attribute = name.rpartition(".")
    return fmt.format(getattr(importlib.import_module(module), attribute) * times)


@cache
def _table_motion_summary():
    return table_motion_summary(load_table_motion(), load_experiments(),
                                ColumnGeometry.load(SPECIMEN).to_dict())


def table_motion_value(name, fmt="{:.1f}"):
    """One number of what the shipped 200 Hz table motions lose against the 800 Hz records,
    by its field ``name`` of :class:`~pipeline.campaign.shake_table_motion.TableMotionSummary`
    (computed from the shipped files of records/shake_table/)."""
    return fmt.format(getattr(_table_motion_summary(), name))


def member_ranges_table():
    """Markdown table of the members' ranges from their one declaration
    (:data:`pipeline.campaign.member_ranges.MEMBER_RANGES`): name, range, unit, source."""
    from pipeline.campaign.member_ranges import MEMBER_RANGES, number_text
    rows = ["| drawn | range | unit | where the range comes from |", "|---|---|---|---|"]
    rows += [f"| `{r.name}` | {number_text(r.low)} to {number_text(r.high)} | {r.unit or '-'} "
             f"| {r.source} |" for r in MEMBER_RANGES]
    return "\n".join(rows)


def bench_convergence_table(path=BENCH_JSON):
    """Markdown table of bench section 5: the twin model's downfall azimuth (deg) per
    column under the one-sine pulse toward N30E at each time-step factor and number of rim
    points, with the wall time of the run (s)."""
    data = _read_json(path)
    if data is None or "convergence" not in data:
        return _not_yet("make bench")
    rows = {}
    for r in data["convergence"]:
        row = rows.setdefault((r["parameter"], r["value"]), {"wall_s": r["wall_s"]})
        row[r["column"]] = r["downfall_azimuth_deg"] if r["toppled"] else None
    columns = sorted({r["column"] for r in data["convergence"]})
    lines = ["| setting | " + " | ".join(f"{c} azimuth (deg)" for c in columns)
             + " | wall (s) |", "|---|" + "---|" * (len(columns) + 1)]
    for (parameter, setting), row in rows.items():
        cells = " | ".join("standing" if row.get(c) is None else f"{row[c]:.1f}"
                           for c in columns)
        name = "time-step factor" if parameter == "dt_factor" else parameter.replace("_", " ")
        lines.append(f"| {name} {setting:.3g} | {cells} | {row['wall_s']:.1f} |")
    return "\n".join(lines)


def twin_time_step(fmt="factor {factor:.3f}, {step_us:.0f} us"):
    """The twin model's time step with the paper's contact, as ``run`` computes it."""
    params = scene_params(columns=Column("both").specs(), contact=Contact(),
                          motion_duration=1.0, t_max=1.0)
    return fmt.format(factor=params.dt_factor, step_us=1e6 * params.time_step_s)


def column_examples(names=None):
    """Markdown table of the shipped column descriptions (or ``names``, a file or a name
    each), computed from the files as ``run`` computes them: blocks and rigid bodies, mass
    (t), uplift ratio (rocking threshold / g) beside base diameter / height, the frequency
    (Hz) of the column rocking on the paper's contact stiffness and the stiffness that
    ``campaign columns`` matches to the paper's column."""
    lines = ["| name | blocks -> bodies | mass | uplift ratio (d/h) | rocking on the "
             f"paper's kn ({paper.COLUMN_KN_N_M:.2g} N/m) | matched kn |",
             "|---|---|---|---|---|---|"]
    for name in names or example_names():
        column = ColumnGeometry.load(name)
        bodies = column.bodies()
        mass_t = sum(body.mass for body in bodies) / 1000.0
        lines.append(f"| `{column.name}` | {len(column.blocks)} -> {len(bodies)} | "
                     f"{mass_t:.3g} t | {column.uplift_ratio():.3f} "
                     f"({column.base_width / column.height:.3f}) | "
                     f"{column.contact_rocking_hz(paper.COLUMN_KN_N_M):.1f} Hz | "
                     f"{matched_kn(column):.2g} N/m |")
    return "\n".join(lines)


def column_sources(names=None):
    """Markdown list of the shipped column descriptions' (or ``names``') ``source`` and
    ``notes``, as the files state them."""
    lines = []
    for name in names or example_names():
        column = ColumnGeometry.load(name)
        lines.append(f"- `{column.name}`: {column.source or '(no source given)'}"
                     + (f" *Notes:* {column.notes}" if column.notes else ""))
    return "\n".join(lines)


def _record_row(record, path):
    if not path.is_file():
        return None
    table = pd.read_csv(path).set_index("id")
    return table.loc[record] if record in table.index else None


def record_value(record, column, fmt="{:.2f}", path=RECORDS_TABLE):
    """One value of a processed record's row in ``records.csv`` (Table 1, written by
    ``records``): e.g. ``pga_h`` (m/s^2) of ``GM20``."""
    row = _record_row(record, path)
    if row is None or column not in row:
        return _not_yet("make run-all")
    return fmt.format(row[column])


def record_rocking_hd(record, fmt="{:.1f}", path=RECORDS_TABLE):
    """The slenderness h/d below which a rigid cylinder cannot rock on a record's strongest
    horizontal acceleration: uplift needs a_h >= g d/h, so h/d < g / PGA_h."""
    row = _record_row(record, path)
    if row is None:
        return _not_yet("make run-all")
    return fmt.format(MODEL_GRAVITY / row["pga_h"])


def run_all_steps(path=RUN_ALL_STEPS):
    """Markdown table of ``make run-all``'s steps and their wall minutes, with the total
    (read by :func:`pipeline.report.campaigns.run_all_steps`, as the REPORT reads them)."""
    frame = campaigns.run_all_steps(path)
    if frame is None or frame.empty:
        return _not_yet("make run-all")
    lines = ["| step | wall (min) |", "|---|---|"]
    lines += [f"| {r.step} | {r.wall_s / 60:.1f} |" for r in frame.itertuples()]
    lines.append(f"| **total** | **{frame['wall_s'].sum() / 60:.1f}** |")
    return "\n".join(lines)


def run_all_minutes(path=RUN_ALL_STEPS):
    """The last ``make run-all``'s wall time in minutes (the sum of its steps)."""
    frame = campaigns.run_all_steps(path)
    if frame is None or frame.empty:
        return _not_yet("make run-all")
    return f"{frame['wall_s'].sum() / 60:.0f}"


def report(path=REPORT):
    """``results/REPORT.md`` itself, its headings moved one level down."""
    if not path.is_file():
        return _not_yet("make run-all")
    return "\n".join("#" + line if line.startswith("#") else line
                     for line in path.read_text().splitlines())


def report_section(heading, path=REPORT, command="make run-all"):
    """The section of ``results/REPORT.md`` whose ``## `` heading starts with ``heading``,
    without that heading and with its inner headings two levels down (for a page's
    ``###``); a note naming ``command`` while the REPORT or the section is not there."""
    if not path.is_file():
        return _not_yet(command)
    lines, inside = [], False
    for line in path.read_text().splitlines():
        if line.startswith("## "):
            inside = line[3:].startswith(heading)
            continue
        if inside:
            lines.append("##" + line if line.startswith("#") else line)
    return "\n".join(lines).strip() or _not_yet(command)


def figures(text):
    """The figure paths (relative to ``results/``) a piece of the REPORT shows."""
    return [path for _, path in FIGURE.findall(text)]
