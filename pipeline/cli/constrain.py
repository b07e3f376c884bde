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

from pipeline.cli._fields import add_arguments, from_args
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import display_path, file_set, result_json_text, write_text
from pipeline.assessment.options import AGE_FLAGS, ConstrainOptions

NAME = "constrain"
ORDER = 46
FILES = ("branch_weights.csv", "prior_curves.csv", "constrained_curves.csv", "constrain.json",
         "constrain.png")                # every file constrain writes (a run replaces them)
HELP = "a hazard model's logic tree reweighted by the specimens still standing at its site"
DESCRIPTION = (
    "Reads a logic tree (OpenQuake's realizations.csv with one hazard curve per realisation, "
    "or a plain table of branches, weights and annual rates), computes for each branch the "
    "probability that the specimens (one fragility each, each its age) survived, and "
    "updates the branches' weights: Bayes (w P_s, the headline) and elimination (branches "
    "with P_s below --floor dropped).  Writes the prior and the constrained mean and "
    "fractile curves, the ground motion at 1e-3, 4e-4 and 1e-4 per year before and after, "
    "the weights per branch and a figure.  See docs/constrained-hazard.md.")


def setup(p):
    """The flags of :class:`~pipeline.assessment.options.ConstrainOptions`, in the
    order of the help; ``--logic-tree`` by hand (a required flag)."""
    o = ConstrainOptions
    field = o.__dataclass_fields__["logic_tree"]
    p.add_argument("--logic-tree", dest="logic_tree", type=Path, required=True,
                   metavar=field.metadata["metavar"], help=field.metadata["help"])
    add_arguments(p, o, ("site",))
    add_arguments(p, o, o.FRAGILITY_FLAGS)
    add_arguments(p.add_argument_group(o.AGE_GROUP), o, AGE_FLAGS)
    add_arguments(p, o, ("rule", "floor"))
    add_arguments(p.add_argument_group(o.RATIO_GROUP), o, o.RATIO_FLAGS)
    add_arguments(p, o, (*o.DRAW_FLAGS, "out"))


def run(args):
    o = from_args(ConstrainOptions, args)
    ages = o.age_models()
    from pipeline.hazard.constrain_assess import constrain_tree
    from pipeline.hazard.logictree import load_logic_tree
    tree = load_logic_tree(o.logic_tree, o.site)
    specimens = o.specimens()
    ratio = o.ratio_model(specimens)
    summary, rows, figure = constrain_tree(tree, specimens, ratio, ages, o.rule,
                                           o.floor, o.draws, o.seed)
    summary["hazard_component"] = o.hazard_component
    files = {"branch_weights.csv": _branch_table(rows),
             "prior_curves.csv": _curve_table(summary, summary["prior"], "prior")}
    if summary["posterior"] is not None:
        files["constrained_curves.csv"] = _curve_table(summary, summary["posterior"],
                                                       f"constrained ({o.rule})")
    summary["files"] = [*files, "constrain.json", "constrain.png"]
    files["constrain.json"] = result_json_text(summary, "constrain.json")   # before any file
    from pipeline.figures.constrain import plot_constrain
    out = o.out
    with file_set(out, FILES, ("constrain.json",)) as stage:
        plot_constrain(figure, stage / "constrain.png")
        for name, text in files.items():
            write_text(stage / name, text)
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
