"""The same outputs from the same inputs at two checkouts of the project.

Runs, at each checkout, small fragility campaigns (a few YADE runs: the field rock Double
Rock over a 3 x 2 pulse grid, the same grid adaptive, the twin model under one record at
``make run-all``'s four levels), then ``survival`` and ``constrain`` as ``make run-all``
runs them on the field rock's fragility (and ``survival`` under the shipped USGS curve, as
``make rock-survival``, on it and on the twin model's fits), then the REPORT sections those results feed; and compares every JSON
and CSV file and the REPORT text, value by value (JSON by key, not key order)::

    python bench/same_outputs.py BEFORE AFTER [--out /tmp/same-outputs] [--rtol 0]

BEFORE and AFTER are checkouts (e.g. a ``git worktree add --detach`` of the older
revision); each runs with ``PYTHONPATH`` set to it and this interpreter.  Every output
goes under ``--out``/before and ``--out``/after (campaigns outside ``results/``: their
processed motions in the campaign directory).  ``--pga-pgv-correlation`` is passed to
both (default 0.733, the default of the revisions before 0.654 became it).

Printed per file: keys added and removed, and each value that differs (before, after,
relative difference); values that hold code versions, run ids or wall times
(``VOLATILE``) are counted and named apart, and the checkout's and the output's own
directories are read as ``<checkout>`` and ``<out>`` in every value.  Exit status 1 when a value differs by more than
``--rtol``.
"""
import argparse
import csv
import difflib
import io
import json
import math
import os
import subprocess
import sys
from pathlib import Path

ROCK = "records/field_rocks/double_rock/double_rock.json"
TREE = "records/hazard/openquake_logictree_case_19"
USGS = "records/hazard/usgs_nshm2014r1_curves_-118_34_vs760.json"
GRID = "pga_g=0.1:0.5:3;pgv_pga_s=0.2:0.8:2"
SITE = ["--magnitude", "6.5", "--distance-km", "55", "--vs30", "800", "--age-ka", "15",
        "--age-sd-ka", "3"]
# keys whose values say which code ran, where, when or how fast (run ids and the motion
# cache's file names hash the code): compared, counted apart
VOLATILE = {"run_id", "provenance", "code_hash", "code_version", "software", "versions", "created",
            "created_utc", "yade_wall_s", "yade_wall_s_total", "wall_s", "campaign_wall_s",
            "python", "git", "command", "path", "out", "directory", "fragility_file",
            "elapsed_s", "core_s", "block2d_wall_s", "run_dir", "motion_file"}
REPORT_SNIPPET = """
import sys
from pathlib import Path
from pipeline.report.field_rock import field_rock_section
from pipeline.report.fragility import fragility_section, rock_fragility_section
from pipeline.report.hazard import survival_section
r = Path(sys.argv[1])
print(field_rock_section(r, "field-rock-quick"))
print(rock_fragility_section(r, "field-rock-adaptive-fragility"))
print(survival_section(r, "rock-survival"))
print(fragility_section(r))
for form in ("pga-pgv", "pga"):
    print(survival_section(r, f"fragility-survival-{form}"))
"""


def commands(results, rho):
    """(name, argv after ``-m pipeline``) of every step, in order; ``results`` absolute."""
    quick = results / "field-rock-quick-fragility" / "fragility.json"
    tiny = ["--members", "1", "--headings", "1", "--animations", "0", "--jobs", "1"]
    corr = ["--pga-pgv-correlation", rho]
    usgs_site = ["--magnitude", "6.5", "--distance-km", "10", "--age-ka", "15",
                 "--age-sd-ka", "3"]
    hazards = [a for q in ("hazard_curve-mean", "quantile_curve-0.1", "quantile_curve-0.9")
               for a in ("--hazard", f"{TREE}/{q}-PGA_13.csv")]
    return [
        ("field-rock-quick-fragility", ["campaign", "fragility", "--column-file", ROCK,
                                        "--pulses", GRID, *tiny]),
        ("field-rock-adaptive-fragility", ["campaign", "fragility", "--column-file", ROCK,
                                           "--pulses", GRID, "--adaptive", *tiny]),
        ("fragility", ["campaign", "fragility", "--records", "GM20", "--levels", "1,2,4,8",
                       "--members", "1", "--animations", "0", "--jobs", "1"]),
        ("field-rock-quick-survival", ["survival", *hazards, "--fragility", str(quick),
                                       *SITE, *corr]),
        ("field-rock-quick-constrain", ["constrain", "--logic-tree", TREE, "--fragility",
                                        str(quick), *SITE, *corr]),
        ("rock-survival", ["survival", "--hazard", USGS, "--fragility", str(quick),
                           *usgs_site, *corr]),
        *[(f"fragility-survival-{form}", ["survival", "--hazard", USGS, "--fragility",
                                          str(results / "fragility" / "fragility.json"),
                                          "--fragility-form", form, *usgs_site, *corr])
          for form in ("pga-pgv", "pga")],
    ]


def run_checkout(checkout, out, python, rho):
    """Every step at ``checkout`` into ``out``/results; the REPORT text to report.md."""
    results = (out / "results").resolve()
    results.mkdir(parents=True, exist_ok=True)
    (out / "checkout.txt").write_text(f"{checkout}\n")
    env = dict(os.environ, PYTHONPATH=str(checkout))
    for name, argv in commands(results, rho):
        argv = [python, "-m", "pipeline", *argv, "--out", str(results / name)]
        print(f"[{checkout}] {' '.join(argv[1:])}", flush=True)
        done = subprocess.run(argv, cwd=checkout, env=env, capture_output=True, text=True)
        (out / f"{name}.log").write_text(done.stdout + done.stderr)
        if done.returncode != 0:
            sys.exit(f"{name} failed at {checkout} (exit {done.returncode}): "
                     f"{(done.stderr.strip().splitlines() or [''])[-1]}")
    report = subprocess.run([python, "-c", REPORT_SNIPPET, str(results)], cwd=checkout,
                            env=env, capture_output=True, text=True, check=True)
    (out / "report.md").write_text(report.stdout)


def number(text):
    """A CSV cell as a float, or None when it is not a number."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def compare_values(a, b, path, found):
    """Differences between two JSON values, by key for objects, appended to ``found``
    as (kind, path, before, after)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a.keys() - b.keys():
            found.append(("removed", f"{path}/{k}", a[k], None))
        for k in b.keys() - a.keys():
            found.append(("added", f"{path}/{k}", None, b[k]))
        for k in a.keys() & b.keys():
            compare_values(a[k], b[k], f"{path}/{k}", found)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            compare_values(x, y, f"{path}[{i}]", found)
    elif a != b and not (_nan(a) and _nan(b)):
        found.append(("value", path, a, b))


def _nan(x):
    return isinstance(x, float) and math.isnan(x)


def read_csv(text):
    """Rows of a CSV text as dicts of cells (by header)."""
    return list(csv.DictReader(io.StringIO(text, newline="")))


def read_text(path, roots):
    """A file's text with each (directory, placeholder) of ``roots`` replaced."""
    text = path.read_text()
    for directory, placeholder in roots:
        text = text.replace(str(directory), placeholder)
    return text


def compare_file(before, after, roots_before=(), roots_after=()):
    """Differences between two output files (JSON or CSV), as compare_values gives;
    ``roots_*``: (directory, placeholder) pairs read as their placeholder."""
    found = []
    text_a, text_b = read_text(before, roots_before), read_text(after, roots_after)
    if before.suffix == ".json":
        compare_values(json.loads(text_a), json.loads(text_b), "", found)
        return found
    rows_a, rows_b = read_csv(text_a), read_csv(text_b)
    if len(rows_a) != len(rows_b):
        return [("value", "rows", len(rows_a), len(rows_b))]
    for i, (ra, rb) in enumerate(zip(rows_a, rows_b)):
        cells_a = {k: number(v) if number(v) is not None else v for k, v in ra.items()}
        cells_b = {k: number(v) if number(v) is not None else v for k, v in rb.items()}
        compare_values(cells_a, cells_b, f"row {i}", found)
    return found


def relative(a, b):
    """|a - b| / max(|a|, |b|) for two numbers, else None."""
    if isinstance(a, bool) or isinstance(b, bool) or \
            not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return None
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0 else abs(a - b) / scale


def volatile(path):
    """True for a key path that names a volatile key (VOLATILE) anywhere along it."""
    parts = path.replace("[", "/").split("/")
    return any(p in VOLATILE for p in parts)


def outputs(root):
    """Relative paths of the JSON and CSV files under ``root``/results (no run dirs)."""
    base = root / "results"
    return sorted(p.relative_to(base) for p in base.rglob("*")
                  if p.suffix in (".json", ".csv") and "runs" not in p.parts
                  and "motions" not in p.parts)


def short(value):
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 90 else text[:87] + "..."


def report_file(rel, found, rtol):
    """Print one file's differences; return how many values differ beyond rtol."""
    moving = [f for f in found if f[0] == "value" and volatile(f[1])]
    real = [f for f in found if f[0] == "value" and not volatile(f[1])]
    keys = [f for f in found if f[0] != "value"]
    beyond = [f for f in real if (relative(f[2], f[3]) is None
                                  or relative(f[2], f[3]) > rtol)]
    print(f"{rel}: {len(real)} value(s) differ ({len(beyond)} beyond rtol {rtol:g}), "
          f"{len(keys)} key(s) added or removed, {len(moving)} volatile value(s) differ")
    if moving:
        names = sorted({path.split("/")[-1] for _, path, _, _ in moving})
        print(f"    volatile: {', '.join(names)[:200]}")
    for kind, path, a, b in keys:
        print(f"    {kind:7s} {path}: {short(a if kind == 'removed' else b)}")
    for _, path, a, b in real:
        rel_diff = relative(a, b)
        tail = "" if rel_diff is None else f"  (relative {rel_diff:.3g})"
        print(f"    value   {path}: {short(a)} -> {short(b)}{tail}")
    return len(beyond)


def roots(out):
    """The checkout and output directories of one side, with their placeholders."""
    checkout = (out / "checkout.txt").read_text().strip()
    return ((checkout, "<checkout>"), (str(out.resolve()), "<out>"))


def compare(out, rtol):
    """Compare every output and the REPORT text of out/before and out/after."""
    before, after = out / "before", out / "after"
    rel_a, rel_b = set(outputs(before)), set(outputs(after))
    for rel in sorted(rel_a ^ rel_b):
        print(f"{rel}: only {'before' if rel in rel_a else 'after'}")
    beyond = 0
    roots_a, roots_b = roots(before), roots(after)
    for rel in sorted(rel_a & rel_b):
        found = compare_file(before / "results" / rel, after / "results" / rel, roots_a,
                             roots_b)
        beyond += report_file(rel, found, rtol)
    text_a = read_text(before / "report.md", roots_a).splitlines()
    text_b = read_text(after / "report.md", roots_b).splitlines()
    diff = list(difflib.unified_diff(text_a, text_b, "before/report.md", "after/report.md",
                                     lineterm="", n=0))
    print(f"REPORT sections: {'the same text' if not diff else 'differ'}")
    print("\n".join(diff))
    return beyond + (1 if diff else 0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=Path, help="the older checkout")
    ap.add_argument("after", type=Path, help="the newer checkout")
    ap.add_argument("--out", type=Path, default=Path("/tmp/same-outputs"))
    ap.add_argument("--python", default=sys.executable,
                    help="interpreter with the project's dependencies")
    ap.add_argument("--pga-pgv-correlation", default="0.733", dest="rho")
    ap.add_argument("--rtol", type=float, default=0.0,
                    help="relative difference of a number taken as the same (default 0: "
                         "exact)")
    ap.add_argument("--compare-only", action="store_true",
                    help="compare what an earlier call wrote under --out")
    args = ap.parse_args(argv)
    for checkout in (args.before, args.after):
        if not (checkout / "pipeline" / "__init__.py").is_file():
            ap.error(f"{checkout} is not a checkout of this project (no pipeline/)")
    if not args.rtol >= 0:
        ap.error(f"--rtol must be >= 0, got {args.rtol}")
    if not args.compare_only:
        for label, checkout in (("before", args.before), ("after", args.after)):
            run_checkout(checkout.resolve(), args.out / label, args.python, args.rho)
    return 1 if compare(args.out, args.rtol) else 0


if __name__ == "__main__":
    sys.exit(main())
