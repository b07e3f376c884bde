"""``constrain``: a hazard model's logic tree reweighted by the specimens still standing.

    python -m pipeline constrain --logic-tree records/hazard/openquake_logictree_case_11 \\
        --median-g 0.3 --beta 0.4 --age-ka 2 --age-sd-ka 0.3

Writes ``branch_weights.csv``, ``branch_test.csv``, ``prior_curves.csv``,
``constrained_curves.csv``, ``constrain.json`` and ``constrain.png`` to ``--out`` (the
workflow: :mod:`pipeline.assessment.constrain`).
"""
import math
from pathlib import Path

from pipeline.cli._fields import add_arguments, from_args
from pipeline.assessment.constrain import constrain_files
from pipeline.files import display_path
from pipeline.assessment.constrain_options import ConstrainOptions
from pipeline.hazard.ratio_described import SitesRatio

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
    "the weights per branch, the branch test (P that every specimen survived per branch, "
    "the branches below --floor) and a figure.  Specimens may stand at several sites of "
    "the tree (--specimen-site).  See docs/constrained-hazard.md.")


def setup(p):
    """The flags of :class:`~pipeline.assessment.constrain_options.ConstrainOptions`, in the
    order of the help; ``--logic-tree`` by hand (a required flag)."""
    o = ConstrainOptions
    field = o.__dataclass_fields__["logic_tree"]
    p.add_argument("--logic-tree", dest="logic_tree", type=Path, required=True,
                   metavar=field.metadata["metavar"], help=field.metadata["help"])
    add_specimen_arguments(p)


def add_specimen_arguments(p):
    """Every flag of ``ConstrainOptions`` but ``--logic-tree`` (``hazard-job`` shares them)."""
    o = ConstrainOptions
    add_arguments(p, o, ("site", "specimen_site"))
    add_arguments(p, o, o.FRAGILITY_FLAGS)
    add_arguments(p.add_argument_group(o.AGE_GROUP), o, o.AGE_FLAGS)
    add_arguments(p, o, ("rule", "floor"))
    add_arguments(p.add_argument_group(o.RATIO_GROUP), o, o.RATIO_FLAGS)
    add_arguments(p, o, (*o.DRAW_FLAGS, "out"))


def run(args):
    o = from_args(ConstrainOptions, args)
    summary = constrain_files(o)
    _print(summary, o.out)
    return 0


def _print(summary, out):
    for line in summary.warnings:
        print(f"warning: {line}")
    print(f"{summary.branch_count} branches, {summary.specimen_count} specimen(s); "
          f"rule {summary.rule}")
    ratio = summary.pgv_pga
    if isinstance(ratio, SitesRatio):
        print(f"PGV/PGA: {ratio.source} (sites "
              f"{', '.join(str(s) for s in ratio.site_indices)}), each site's in "
              "constrain.json sites[].pgv_pga")
    for row in summary.ground_motion_at_rates:
        if row.curve not in ("mean", "range 0.05-0.95"):
            continue
        change = row.change_percent
        print(f"  {row.curve} PGA at {row.annual_rate_per_yr:g} /yr: "
              f"{_g(row.prior_g)} g -> {_g(row.posterior_g)} g"
              + ("" if change is None else f" ({change:+.0f} %)"))
    test = summary.branch_test
    print(f"branch test: P(every specimen survived) below {test.level:g} under "
          f"{len(test.branches_below_level)} of {summary.branch_count} branches "
          f"(prior weight {test.prior_weight_below_level:.3g})")
    print(f"wrote {display_path(out / 'constrain.json')}, branch_weights.csv, "
          "branch_test.csv, the curves and constrain.png")


def _g(value):
    return "-" if value is None or not math.isfinite(value) else f"{value:.3g}"
