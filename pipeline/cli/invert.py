"""``invert``: a posterior over earthquake sources from fallen and standing columns.

    python -m pipeline invert OBSERVATIONS.json [--out DIR] [--quick] [--scheduler ADDRESS]
    python -m pipeline invert --demo [--grid demo]          # make invert-demo
    python -m pipeline invert --member-study                # make invert-study
    python -m pipeline invert --hidden-truth TRUTH.json --table FILE
"""
import math
from pathlib import Path

from pipeline.cli._fields import add_arguments, from_args
from pipeline.files import InputError
from pipeline.inversion.options import CANDIDATE_PRESETS, InversionOptions, SiteMotionOptions

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


def _floats(name):
    def parse(text):
        try:
            values = tuple(float(v) for v in text.split(",") if v.strip())
        except ValueError:
            raise InputError(f"--{name}: not a comma-separated list of numbers: {text!r}") \
                from None
        if not values or not all(math.isfinite(v) for v in values):
            raise InputError(f"--{name}: give finite numbers, got {text!r}")
        return values
    return parse


def _weights(text):
    out = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"--mechanism-prior {item!r}: expected NAME=WEIGHT") from None
        if not (math.isfinite(out[name.strip()]) and out[name.strip()] >= 0):
            raise InputError(f"--mechanism-prior {item!r}: weights must be >= 0")
    if not any(out.values()):
        raise InputError("--mechanism-prior: at least one weight must be positive")
    return out


def setup(p):
    from pipeline.inversion.grid import GRIDS, MECHANISMS  # lazy: the stage runs only with the command (light start-up and --help)
    _what_to_run(p, GRIDS)
    _forward_grid(p.add_argument_group("forward grid (the table: one ensemble per node)"),
                  GRIDS["full"], MECHANISMS)
    _candidates(p.add_argument_group("candidates and prior"))
    add_arguments(p.add_argument_group("the motion at each site from its standing and "
                                       "fallen columns (with an OBSERVATIONS.json)"),
                  SiteMotionOptions)


def _what_to_run(p, grids):
    """The observations, the modes (--demo, --hidden-truth, --member-study), the table and
    where runs go."""
    quick = grids["quick"]
    p.add_argument("observations", nargs="?", type=Path, metavar="OBSERVATIONS.json",
                   help="sites with their fallen and standing columns (schema: docs/inversion.md)")
    add_arguments(p, InversionOptions, names=("out",))
    p.add_argument("--quick", action="store_true",
                   help=f"coarse smoke run (a few minutes): {len(quick.slices())} slices, "
                   f"rings {','.join(f'{v:g}' for v in quick.distances_km)} km every "
                   f"{quick.azimuth_step_deg:g} deg, {quick.members} members, "
                   f"{quick.duration_s:g} s motions to {quick.fmax_hz:g} Hz; candidates "
                   "within 12 km, strike every 90 deg")
    p.add_argument("--grid", choices=sorted(grids), default=None,
                   help="forward-grid preset (default full; --quick = quick; the demo "
                   "machine ran 'demo'); the options below override it")
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


def _forward_grid(g, full, mechanisms):
    """The forward grid's options; their defaults from the ``full`` preset."""
    g.add_argument("--mechanisms", default=None, metavar="LIST",
                   help="comma-separated, of " + ", ".join(
                       f"{k} (dip {v[0]:g}, rake {v[1]:g})" for k, v in mechanisms.items())
                   + " or NAME:DIP:RAKE (default: " + ",".join(m[0] for m in full.mechanisms)
                   + ")")
    g.add_argument("--depths", default=None, metavar="KM,KM",
                   help="hypocentre depths (default "
                   + ",".join(f"{v:g}" for v in full.depths_km) + ")")
    g.add_argument("--magnitudes", default=None, metavar="MW,MW",
                   help="moment magnitudes 4.5-7.5 (default "
                   + ",".join(f"{v:g}" for v in full.magnitudes) + ")")
    g.add_argument("--distances", default=None, metavar="KM,KM",
                   help="table rings: epicentral distances (default "
                   + ",".join(f"{v:g}" for v in full.distances_km) + ")")
    g.add_argument("--azimuth-step", type=float, default=None, metavar="DEG",
                   help=f"table node spacing in azimuth from strike (default "
                   f"{full.azimuth_step_deg:g})")
    g.add_argument("--members", type=int, default=None,
                   help=f"ensemble members per node (default {full.members}; plus the "
                   "nominal run)")
    g.add_argument("--seed", type=int, default=None, help="Latin-hypercube seed")
    g.add_argument("--fmax", type=float, default=None, metavar="HZ",
                   help=f"synthetics up to this frequency (default {full.fmax_hz:g})")
    g.add_argument("--duration", type=float, default=None, metavar="S",
                   help=f"motion duration (default {full.duration_s:g} s)")


def _candidates(c):
    """The candidate sources, the prior and the likelihood's options."""
    c.add_argument("--radius", type=float, default=None, metavar="KM",
                   help="epicentres within this distance of a site (default 30; quick 12; "
                   "demo 25) and within the forward table's last ring of every site")
    c.add_argument("--step", type=float, default=None, metavar="KM",
                   help="epicentre grid spacing (default 1)")
    c.add_argument("--strike-step", type=float, default=None, metavar="DEG",
                   help="strikes sampled every DEG from 0 (default 30; quick 90)")
    c.add_argument("--mechanism-prior", default=None, metavar="NAME=W,...",
                   help="prior weights of the mechanisms (default: equal)")
    c.add_argument("--gr-b", type=float, default=None, metavar="B",
                   help="Gutenberg-Richter prior on magnitude, 10^(-B M) (default uniform)")
    add_arguments(c, InversionOptions, names=("kernel_deg", "floor", "likelihood", "trials"))


def build_grids(args):
    """(preset name, TableGrid, CandidateGrid) from the options; InputError if impossible."""
    from pipeline.inversion.grid import GRIDS, parse_mechanisms  # lazy: the stage runs only with the command (light start-up and --help)
    from pipeline.campaign.ensemble_members import check_seed  # lazy: the stage runs only with the command (light start-up and --help)
    from pipeline.inversion.candidates import CandidateGrid  # lazy: the stage runs only with the command (light start-up and --help)
    if args.quick and args.grid not in (None, "quick"):
        raise InputError("--quick is --grid quick: give one of them")
    preset = "quick" if args.quick else (
        args.grid or ("study" if getattr(args, "member_study", False) else "full"))
    mechanisms = parse_mechanisms(args.mechanisms) if args.mechanisms else None
    depths = _floats("depths")(args.depths) if args.depths else None
    magnitudes = _floats("magnitudes")(args.magnitudes) if args.magnitudes else None
    distances = _floats("distances")(args.distances) if args.distances else None
    prior = _weights(args.mechanism_prior) if args.mechanism_prior else None
    grid = GRIDS[preset].replace(
        mechanisms=mechanisms, depths_km=depths, magnitudes=magnitudes,
        distances_km=distances, azimuth_step_deg=args.azimuth_step,
        members=args.members, seed=check_seed(args.seed), fmax_hz=args.fmax,
        duration_s=args.duration)
    values = dict(CANDIDATE_PRESETS[preset])
    for key, option in (("radius_km", args.radius), ("step_km", args.step),
                        ("strike_step_deg", args.strike_step)):
        if option is not None:
            values[key] = option
    candidates = CandidateGrid(
        **values, mechanisms=None if mechanisms is None else tuple(m[0] for m in mechanisms),
        depths_km=depths, magnitudes=magnitudes, mechanism_prior=prior, gr_b=args.gr_b)
    return preset, grid, candidates


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
    preset, grid, candidates = build_grids(args)
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
