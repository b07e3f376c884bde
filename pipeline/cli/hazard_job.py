"""``hazard-job``: from an OpenQuake job to the constrained hazard in one command.

    python -m pipeline hazard-job --oq-job job.ini --oq-site 11.2 42.4 \\
        --median-g 0.3 --beta 0.4 --age-ka 2 --age-sd-ka 0.3

The engine (its own environment, ``--oq-python``) runs the job at the given sites; then
``constrain`` on its per-realisation PGA curves (the workflow:
:mod:`pipeline.assessment.hazard_job`).  Writes what ``constrain`` writes and the
engine's export in ``<out>/openquake``.
"""
from pipeline.assessment.constrain_options import ConstrainOptions
from pipeline.assessment.hazard_job import EXPORT, HazardJobOptions, hazard_job
from pipeline.assessment.options import CONSTRAIN_OUT
from pipeline.cli import constrain
from pipeline.cli._fields import add_arguments, from_args

NAME = "hazard-job"
ORDER = 47
HELP = "an OpenQuake job run at the specimens' sites, then its logic tree constrained"
DESCRIPTION = (
    "Rewrites an OpenQuake job (its job.ini with source and ground-motion logic trees) "
    "for the specimens' sites (--oq-site) with PGA and PGV curves of every realisation, "
    "the ruptures' contexts for the PGA-PGV rate density, and the disaggregation of PGA "
    "by magnitude and distance; runs the engine's own command line in its environment "
    "(--oq-python; one process, no server), keeps its export in <out>/openquake and "
    "runs constrain on the per-realisation PGA curves.  Without the engine it says how "
    "to install it.  See docs/constrained-hazard.md.")


def setup(p):
    """``HazardJobOptions``' flags, then ``constrain``'s but --logic-tree."""
    add_arguments(p, HazardJobOptions)
    constrain.add_specimen_arguments(p)


def run(args):
    job = from_args(HazardJobOptions, args)
    out = args.out if args.out is not None else CONSTRAIN_OUT
    # every option range-checked before the engine runs (the logic tree: its export)
    options = from_args(ConstrainOptions, args, logic_tree=out / EXPORT)
    summary, times = hazard_job(job, options)
    print("OpenQuake engine wall time: " + ", ".join(
        f"{step} {seconds:.1f} s" for step, seconds in times.items()))
    constrain._print(summary, options.out)
    return 0
