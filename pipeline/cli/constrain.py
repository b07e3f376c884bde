"""``constrain``: a hazard model's logic tree reweighted by the specimens still standing.

    python -m pipeline constrain --logic-tree records/hazard/openquake_logictree_case_11 \\
        --median-g 0.3 --beta 0.4 --age-ka 2 --age-sd-ka 0.3

Writes ``branch_weights.csv``, ``prior_curves.csv``, ``constrained_curves.csv``,
``constrain.json`` and ``constrain.png`` to ``--out``.
"""
import csv
import io
import math
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.cli._fragility_options import (add_draw_options, add_fragility_options,
                                             add_ratio_options, check_fragility_options,
                                             load_specimens, ratio_model)
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError, display_path, write_json, write_text
from pipeline.userfiles import number

NAME = "constrain"
ORDER = 46
HELP = "a hazard model's logic tree reweighted by the specimens still standing at its site"
DESCRIPTION = (
    "Reads a logic tree (OpenQuake's realizations.csv with one hazard curve per realisation, "
    "or a plain table of branches, weights and annual rates), computes for each branch the "
    "probability that the specimens (one fragility each, each its age) survived, and "
    "updates the branches' weights: Bayes (w P_s, the headline) and elimination (branches "
    "with P_s below --floor dropped).  Writes the prior and the constrained mean and "
    "fractile curves, the ground motion at 1e-3, 4e-4 and 1e-4 per year before and after, "
    "the weights per branch and a figure.  See docs/constrained-hazard.md.")
DEFAULT_OUT = RESULTS_DIR / "constrain"
MAX_SPECIMENS = 20


def setup(p):
    p.add_argument("--logic-tree", type=Path, required=True, metavar="PATH",
                   help="OpenQuake's export (the directory, or its realizations.csv, with "
                   "one hazard_curve CSV per realisation) or a plain table branch,weight,"
                   "pga_<g|m_s2|cm_s2>,annual_rate_per_yr (one row per branch and level)")
    p.add_argument("--site", type=int, default=None, metavar="N",
                   help="row (0-based) of OpenQuake curves with several sites")
    add_fragility_options(p)
    p.add_argument("--age-ka", type=float, action="append", default=[], metavar="KA",
                   help="a specimen's age in thousand years (above 0, at most 10000): one "
                   "per specimen, in the order of the fragilities, or one for all")
    p.add_argument("--age-sd-ka", type=float, action="append", default=[], metavar="KA",
                   help="its standard deviation (ka, 0-10000; normal truncated at 0): one "
                   "per specimen or one for all; default 0")
    p.add_argument("--rule", choices=("bayes", "eliminate"), default="bayes",
                   help="the headline's rule: bayes (weights x survival probability; "
                   "default) or eliminate (branches of survival below --floor dropped); "
                   "both are written")
    p.add_argument("--floor", type=float, default=0.05, metavar="P",
                   help="survival probability below which elimination drops a branch "
                   "(0-1, above 0 and below 1); default 0.05")
    add_ratio_options(p)
    add_draw_options(p)
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, metavar="DIR",
                   help=f"output directory (default {display_path(DEFAULT_OUT)})")


def check(args):
    """Every option range-checked before any work (InputError, one line); returns the
    ages and their sds (ka), one per specimen."""
    check_fragility_options(args)
    n = len(args.fragility) + len(args.median_g) + len(args.logistic)
    if n > MAX_SPECIMENS:
        raise InputError(f"{n} specimens (at most {MAX_SPECIMENS})")
    if args.column is not None and not args.fragility:
        raise InputError("--column applies to --fragility files")
    if args.site is not None and args.site < 0:
        raise InputError(f"--site must be 0 or more, got {args.site}")
    if not args.age_ka:
        raise InputError("give --age-ka (one per specimen, or one for all)")
    ages = _per_specimen(args.age_ka, n, "--age-ka")
    sds = _per_specimen(args.age_sd_ka or [0.0], n, "--age-sd-ka")
    for a in ages:
        number(a, "--age-ka", 0, 10000, "ka", low_open=True)
    for s in sds:
        number(s, "--age-sd-ka", 0, 10000, "ka")
    number(args.floor, "--floor", 0, 1, low_open=True)
    if args.floor >= 1:
        raise InputError(f"--floor must be below 1, got {args.floor:g}")
    if args.out.exists() and not args.out.is_dir():
        raise InputError(f"--out {args.out} exists and is not a directory")
    return ages, sds


def _per_specimen(values, n, flag):
    if len(values) == 1:
        return list(values) * n
    if len(values) != n:
        raise InputError(f"give one {flag} per specimen ({n}) or one for all, got "
                         f"{len(values)}")
    return list(values)


def run(args):
    ages, sds = check(args)
    from pipeline.hazard.constrain_assess import constrain_tree
    from pipeline.hazard.logictree import load_logic_tree
    tree = load_logic_tree(args.logic_tree, args.site)
    specimens = load_specimens(args)
    ratio = ratio_model(args, specimens)
    summary, rows, figure = constrain_tree(tree, specimens, ratio, ages, sds, args.rule,
                                           args.floor, args.draws, args.seed)
    summary["hazard_component"] = args.hazard_component
    summary["files"] = ["branch_weights.csv", "prior_curves.csv", "constrained_curves.csv",
                        "constrain.json", "constrain.png"]
    from pipeline.figures.constrain import plot_constrain
    out = args.out
    plot_constrain(figure, out / "constrain.png")
    write_text(out / "branch_weights.csv", _branch_table(rows))
    write_text(out / "prior_curves.csv", _curve_table(summary, summary["prior"], "prior"))
    if summary["posterior"] is not None:
        write_text(out / "constrained_curves.csv",
                   _curve_table(summary, summary["posterior"], f"constrained ({args.rule})"))
    else:
        summary["files"].remove("constrained_curves.csv")
    write_json(out / "constrain.json", summary)
    _print(summary, out)
    return 0


def _branch_table(rows):
    """branch_weights.csv: one row per branch."""
    names = ["branch", "path", "prior_weight", "survival_probability", "posterior_bayes",
             "posterior_eliminate"]
    if rows and "survival_interval" in rows[0]:
        names += ["survival_lo_2.5pct", "survival_hi_97.5pct"]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(names)
    for row in rows:
        values = [row[k] for k in names[:6]]
        if "survival_interval" in row:
            values += row["survival_interval"]
        writer.writerow(["" if v is None else (f"{v:.9g}" if isinstance(v, float) else v)
                         for v in values])
    return buf.getvalue()


def _curve_table(summary, stats, what):
    """A curve file: comment lines, then pga_g, pga_m_s2, the mean and each fractile's
    annual rate of exceedance (1/yr) per level."""
    fractiles = list(stats["fractiles"])
    lines = [f"# {what} hazard curves of the logic tree {summary['hazard'].get('file')}: "
             "annual rates of exceeding PGA (1/yr)",
             "# mean: the weighted mean of the branches' rates; fractile_q: OpenQuake's "
             "weighted quantile over the branches",
             ",".join(["pga_g", "pga_m_s2", "mean_annual_rate_per_yr"]
                      + [f"fractile_{q}_annual_rate_per_yr" for q in fractiles])]
    for k, level in enumerate(summary["levels_m_s2"]):
        values = [level / STANDARD_GRAVITY, level, stats["mean_rates_per_yr"][k]] + \
            [stats["fractiles"][q][k] for q in fractiles]
        lines.append(",".join(f"{v:.9g}" for v in values))
    return "\n".join(lines) + "\n"


def _print(summary, out):
    for line in summary["warnings"]:
        print(f"warning: {line}")
    print(f"{summary['branch_count']} branches, {summary['specimen_count']} specimen(s); "
          f"rule {summary['rule']}")
    for row in summary["ground_motion_at_rates"]:
        if row["curve"] not in ("mean", "range 0.05-0.95"):
            continue
        change = row["change_percent"]
        print(f"  {row['curve']} PGA at {row['annual_rate_per_yr']:g} /yr: "
              f"{_g(row['prior_g'])} g -> {_g(row['posterior_g'])} g"
              + ("" if change is None else f" ({change:+.0f} %)"))
    print(f"wrote {display_path(out / 'constrain.json')}, branch_weights.csv, the curves "
          "and constrain.png")


def _g(value):
    return "-" if value is None or not math.isfinite(value) else f"{value:.3g}"
