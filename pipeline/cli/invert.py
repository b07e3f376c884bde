"""``invert``: a posterior over earthquake sources from fallen and standing columns.

    python -m pipeline invert OBSERVATIONS.json [--out DIR] [--quick] [--scheduler ADDRESS]
    python -m pipeline invert --demo [--grid demo]          # make invert-demo
    python -m pipeline invert --member-study                # make invert-study
    python -m pipeline invert --hidden-truth TRUTH.json --table FILE
"""
from pathlib import Path

from pipeline.cli._fields import add_arguments, from_args
from pipeline.files import InputError
from pipeline.inversion.grid_options import GridOptions
from pipeline.inversion.options import InversionOptions, SiteMotionOptions

TABLE_OPTIONS = ("mechanisms", "depths", "magnitudes", "distances", "azimuth_step", "members",
                 "seed", "fmax", "duration")
CANDIDATE_OPTIONS = ("radius", "step", "strike_step", "mechanism_prior", "gr_b")
NAME = "invert"
ORDER = 45
HELP = "invert fallen columns for the earthquake source (posterior map, back azimuth)"
DESCRIPTION = (
    "Bayesian source inversion: candidate epicentres on a grid around the sites, mechanisms "
    "(strike sampled), depths and magnitudes; the likelihood of each observed column (fallen "
    "toward an azimuth, or standing) from a forward table of twin-model ensembles shaken by "
    "pyprop8 synthetics (campaign inversion-forward, cached by content: a second inversion "
    "reuses every run). Writes posterior.csv, inversion_summary.json, posterior_map.png and "
    "marginals.png (and with --site-fragility site_motion.json, the PGA range each site's "
    "columns allow). Observations schema: docs/inversion.md.")


def setup(p):
    _what_to_run(p)
    add_arguments(p.add_argument_group("forward grid (the table: one ensemble per node)"),
                  GridOptions, names=TABLE_OPTIONS)
    c = p.add_argument_group("candidates and prior")
    add_arguments(c, GridOptions, names=CANDIDATE_OPTIONS)
    add_arguments(c, InversionOptions, names=("kernel_deg", "floor", "likelihood", "trials"))
    add_arguments(p.add_argument_group("the motion at each site from its standing and "
                                       "fallen columns (with an OBSERVATIONS.json)"),
                  SiteMotionOptions)


def _what_to_run(p):
    """The observations, the modes (--demo, --hidden-truth, --member-study), the preset,
    the table and where runs go."""
    p.add_argument("observations", nargs="?", type=Path, metavar="OBSERVATIONS.json",
                   help="sites with their fallen and standing columns (schema: docs/inversion.md)")
    add_arguments(p, InversionOptions, names=("out",))
    add_arguments(p, GridOptions, names=("quick", "grid"))
    p.add_argument("--demo", action="store_true",
                   help="synthetic truth tests and the paper's scenario (make invert-demo)")
    p.add_argument("--hidden-truth", type=Path, default=None, metavar="TRUTH.json",
                   help="a hidden-truth test: the source you choose, twin models simulated "
                   "at your sites (members no table uses), inverted with the forward table; "
                   "writes observations.json and the inversion with the truth checked "
                   "(schema: docs/inversion.md)")
    p.add_argument("--member-study", action="store_true",
                   help="truth tests at 3, 6, 12, 24 and 48 likelihood members per node "
                   "(observed columns from 16 members no likelihood uses): how many fallen "
                   "columns bound the back azimuth, the epicentre and the magnitude (default "
                   "--grid study: 3,072 runs; make invert-study)")
    add_arguments(p, InversionOptions,
                  names=("scheduler", "jobs", "allow_long", "table", "extend_table", "forward_dir"))


def run(args):
    from pipeline.inversion import workflows  # lazy: the stage runs only with the command (light start-up and --help)
    if (args.demo + args.member_study + (args.observations is not None)
            + (args.hidden_truth is not None)) != 1:
        raise InputError("give one of an OBSERVATIONS.json file, --demo, --member-study or "
                         "--hidden-truth TRUTH.json")
    if args.trials is not None and not (args.demo or args.member_study):
        raise InputError("--trials goes with --demo or --member-study")
    options = from_args(InversionOptions, args)
    site_fragility = _check_site_motion(args)
    preset, grid, candidates = from_args(GridOptions, args).grids(args.member_study)
    if args.demo:
        return workflows.demo(options, preset, grid, candidates)
    if args.member_study:
        return workflows.member_study(options, grid, candidates)
    if args.hidden_truth is not None:
        return workflows.hidden_truth(args.hidden_truth, options, grid, candidates)
    return workflows.invert_file(args.observations, options, grid, candidates, site_fragility)


def _check_site_motion(args):
    """The site-motion options checked before any work: (fragility_for(column type),
    at_pgv_pga) or None."""
    if args.site_fragility is not None and args.observations is None:
        raise InputError("--site-fragility goes with an OBSERVATIONS.json file")
    site = from_args(SiteMotionOptions, args)
    if site.site_fragility is None:
        return None
    from pipeline.hazard.fragility import load_campaign_fragility  # lazy: the stage runs only with the command (light start-up and --help)
    from pipeline.inversion.observations import load_observations  # lazy: the stage runs only with the command (light start-up and --help)
    from pipeline.records import rotd50_fraction  # lazy: the stage runs only with the command (light start-up and --help)
    cache = {}

    def fragility_for(column):
        if column not in cache:
            cache[column] = load_campaign_fragility(
                site.site_fragility, column, site.site_fragility_form, component="rotd50",
                record_fraction=rotd50_fraction, members=False)
        return cache[column]
    for column in load_observations(args.observations).column_types():
        fragility_for(column)                  # a missing column type refused before work
    return fragility_for, site.at_pgv_pga
