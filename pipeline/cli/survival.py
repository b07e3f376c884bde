"""``survival``: what a standing rock or column says about its site's hazard.

    python -m pipeline survival --site 0 --median-g 0.3 --beta 0.4 --age-ka 15 \\
        --age-sd-ka 3 --hazard records/hazard/oq_classical_case_14_hazard_curve-rlz-000_PGA.csv
    python -m pipeline survival --hazard curve.csv --fragility results/campaigns/fragility \\
        --column monolithic --pgv-pga-median 0.1 --pgv-pga-sigma 0.4 --age-ka 2.5

Writes ``survival.json`` and ``survival.png`` to ``--out`` (the workflow:
:mod:`pipeline.report.survival`).
"""
import math
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError, display_path
from pipeline.cli._fragility_options import (add_draw_options, add_fragility_options,
                                             add_ratio_options, check_fragility_options,
                                             load_specimens, parse_logistic, ratio_model)
from pipeline.report.survival import site_motion_result, survival_files, write_site_motion
from pipeline.userfiles import number

NAME = "survival"
ORDER = 45
HELP = "survival of a standing specimen under a site's hazard curve: rate, probability, bounds"
DESCRIPTION = (
    "The annual rate at which a specimen (or a set at one site) overturns under a site's "
    "hazard curve, the probability that it survived its age, the contribution by intensity "
    "and the largest factor on the hazard's rates (and intensities) that leaves survival "
    ">= 5 %. Fragility: a stated lognormal over PGA (--median-g, --beta) or campaign "
    "fragility's fragility.json (--fragility) or a stated logistic surface in PGA and PGV/PGA "
    "(--logistic). See docs/survival.md.")
DEFAULT_OUT = RESULTS_DIR / "survival"


def setup(p):
    p.add_argument("--hazard", type=Path, action="append", default=[], metavar="FILE",
                   help="hazard curve: OpenQuake hazard-curve CSV, USGS hazard web service "
                   "JSON (static curves) or a plain table pga_<g|m_s2|cm_s2>,"
                   "annual_rate_per_yr; repeat for several curves of the site (e.g. an "
                   "engine's mean and quantile curves): the first gives the headline, "
                   "survival.json's hazard_curves the result under each")
    p.add_argument("--site", type=int, default=None, metavar="N",
                   help="row (0-based) of an OpenQuake file with several sites")
    add_fragility_options(p)
    p.add_argument("--age-ka", type=float, default=None, metavar="KA",
                   help="the specimen's age in thousand years (above 0, at most 10000); "
                   "needed with --hazard")
    p.add_argument("--age-sd-ka", type=float, default=0.0, metavar="KA",
                   help="its standard deviation (ka; normal truncated at 0); default 0")
    add_ratio_options(p)
    o = p.add_argument_group("the motion at a site from its standing and fallen columns")
    o.add_argument("--observations", type=Path, default=None, metavar="FILE",
                   help="an observations file of invert (sites with fallen and standing "
                   "columns): writes site_motion.json, the PGA range consistent with the "
                   "site's outcome; fragility per column type from --fragility (a column "
                   "fragility.json) or one stated --median-g/--beta or --logistic for all")
    o.add_argument("--observation-site", default=None, metavar="NAME",
                   help="the site's name in --observations (default: its only site)")
    o.add_argument("--at-pgv-pga", type=float, default=None, metavar="S",
                   help="the PGV/PGA (s, 0.001-10) at which the PGA range is stated (for a "
                   "fragility over PGA and PGV/PGA)")
    add_draw_options(p)
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, metavar="DIR",
                   help=f"output directory (default {display_path(DEFAULT_OUT)})")


def check(args):
    """Every option range-checked before any work (InputError, one line)."""
    if not args.hazard and args.observations is None:
        raise InputError("give --hazard (survival under a hazard curve) or --observations "
                         "(the motion at a site from its columns), or both")
    if args.hazard and args.age_ka is None:
        raise InputError("--hazard needs --age-ka (the specimen's age)")
    if not args.hazard and args.age_ka is not None:
        raise InputError("--age-ka applies with --hazard")
    if args.observations is None and (args.observation_site is not None
                                      or args.at_pgv_pga is not None):
        raise InputError("--observation-site and --at-pgv-pga apply with --observations")
    if args.at_pgv_pga is not None:
        number(args.at_pgv_pga, "--at-pgv-pga", 0.001, 10, "s")
    if args.observations is not None and len(args.fragility) + len(args.median_g) \
            + len(args.logistic) != 1:
        raise InputError("--observations: give one fragility (--fragility, one "
                         "--median-g/--beta or one --logistic), used by column type")
    if args.age_ka is not None:
        number(args.age_ka, "--age-ka", 0, 10000, "ka", low_open=True)
    number(args.age_sd_ka, "--age-sd-ka", 0, 10000, "ka")
    check_fragility_options(args)
    _distinct_fragilities(args.fragility)
    if args.observations is not None and args.column is not None:
        raise InputError("--column does not apply with --observations (each column's own "
                         "type is read from the file)")
    if args.column is not None and not args.fragility:
        raise InputError("--column applies to --fragility files")
    if args.site is not None and args.site < 0:
        raise InputError(f"--site must be 0 or more, got {args.site}")
    if args.out.exists() and not args.out.is_dir():
        raise InputError(f"--out {args.out} exists and is not a directory")


def _distinct_fragilities(paths):
    """Refuse the same fragility file named twice (as a file or its directory, by another
    path or link): one specimen is not a set."""
    seen = {}
    for path in paths:
        file = path / "fragility.json" if path.is_dir() else path
        try:
            stat = file.stat()
            key = (stat.st_dev, stat.st_ino)
        except OSError:
            key = file.resolve()
        if key in seen:
            raise InputError(f"--fragility {path} and {seen[key]} are one file: the same "
                             "specimen twice (a set needs distinct specimens)")
        seen[key] = path


def run(args):
    check(args)
    site_motion = None
    if args.observations is not None:
        site_motion = _site_motion(args)
    if not args.hazard:
        write_site_motion(args.out, site_motion)
        _print_site_motion(site_motion)
        print(f"wrote {display_path(args.out / 'site_motion.json')}")
        return 0
    from pipeline.hazard import load_hazard
    curves = [load_hazard(path, args.site) for path in args.hazard]
    specimens = load_specimens(args)
    ratio = ratio_model(args, specimens)
    summary = survival_files(args.out, curves, specimens, ratio, args.age_ka, args.age_sd_ka,
                             args.draws, args.seed, args.hazard_component, site_motion)
    for line in summary["warnings"]:
        print(f"warning: {line}")
    interval = summary["survival_interval"]
    bound = summary["intensity_scale_bound_5pct"]
    print(f"overturning rate {summary['annual_overturning_rate_per_yr']:.3g} /yr; survived "
          f"{args.age_ka:g} ka with P = {summary['survival_probability']:.3g}"
          + ("" if interval is None else f" [{interval[0]:.3g}, {interval[1]:.3g}]")
          + f"; hazard rates x {_g(summary['rate_scale_bound_5pct'])} or intensities x "
          f"{_g(bound)} leave 5 %")
    for row in summary.get("hazard_curves", [])[1:]:
        print(f"under {row['kind'] or row['file']}: rate {row['annual_overturning_rate_per_yr']:.3g}"
              f" /yr, survival P = {row['survival_probability']:.3g}")
    if site_motion is not None:
        _print_site_motion(site_motion)
    print(f"wrote {display_path(args.out / 'survival.json')} and survival.png")
    return 0


def _site_motion(args):
    """site_motion.json's content: the PGA range consistent with one site's columns, each
    column type's fragility from the options."""
    from pipeline.hazard.fragility import Logistic, Lognormal, load_campaign_fragility
    from pipeline.records import rotd50_fraction
    if args.fragility:
        def fragility_for(column):
            return load_campaign_fragility(args.fragility[0], column, args.fragility_form,
                                           args.below_grid, args.hazard_component,
                                           args.magnitude, args.distance_km, rotd50_fraction)
    elif args.median_g:
        stated = Lognormal(args.median_g[0] * STANDARD_GRAVITY, args.beta[0],
                           label=f"stated lognormal: median {args.median_g[0]:g} g, "
                           f"beta {args.beta[0]:g} (every column)")
        def fragility_for(column):
            return stated
    else:
        stated = Logistic(parse_logistic(args.logistic[0]),
                          label=f"stated logistic surface {args.logistic[0]} (every column)")
        def fragility_for(column):
            return stated
    return site_motion_result(
        args.observations, args.observation_site, fragility_for, args.at_pgv_pga,
        f"{args.hazard_component}: a campaign's fragility put on it "
        "(fragilities.*.pga_measure)" if args.fragility else
        "the stated fragility's own PGA")


def _print_site_motion(result):
    lo, hi = result["pga_interval95_g"]
    ml = result["pga_ml_g"]
    print(f"site {result['site']}: {result['fallen']} of {result['columns']} columns fell; "
          f"PGA {'-' if ml is None else f'{ml:.3g}'} g, 95 % [{_g(lo)}, {_g(hi)}] g"
          + ("" if result["pgv_pga_s"] is None else f" at PGV/PGA {result['pgv_pga_s']:g} s")
          + ("" if result["note"] is None else f" ({result['note']})"))


def _g(value):
    return "-" if value is None or not math.isfinite(value) else f"{value:.3g}"
