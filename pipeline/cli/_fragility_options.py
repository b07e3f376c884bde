"""The fragility and PGV/PGA options that ``survival`` and ``constrain`` share: one
declaration (:func:`add_fragility_options`), one range check (:func:`check_fragility_options`)
and one reading of them (:func:`load_specimens`, :func:`ratio_model`)."""
import math
from pathlib import Path

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.components import COMPONENTS
from pipeline.hazard.fragility import BELOW_GRID
from pipeline.userfiles import number

COLUMNS = ("monolithic", "drums", "block2d", "block2d_worst")


def add_fragility_options(p):
    """The fragility options (``--fragility`` ... ``--logistic``) on parser ``p``."""
    p.add_argument("--hazard-component", choices=COMPONENTS, default="rotd50",
                   help="the horizontal component of the hazard curve's PGA: rotd50 (NGA-West2 "
                   "models, the USGS 2014 model; default) or rotd100 (the peak of the "
                   "horizontal vector, campaign fragility's PGA); a campaign's fragility is "
                   "put on it")
    p.add_argument("--fragility", type=Path, action="append", default=[], metavar="FILE",
                   help="fragility.json of campaign fragility (or its directory); repeat for "
                   "a set of specimens at the site")
    p.add_argument("--column", choices=COLUMNS, default=None,
                   help="which column entry of fragility.json (default: the first 3D one)")
    p.add_argument("--fragility-form", choices=("pga", "pga-pgv", "grid"), default=None,
                   help="from fragility.json: pga (its lognormal PGA fit), pga-pgv (its "
                   "logistic surface in PGA and PGV/PGA; default for columns) or grid (a "
                   "pulse grid's cells, bilinear in ln PGA and ln PGV/PGA, the logistic "
                   "surface outside; default for a pulse grid)")
    p.add_argument("--below-grid", choices=BELOW_GRID, default="ramp",
                   help="a pulse grid's P below its first PGA: ramp (0 at the uplift "
                   "acceleration g tan(alpha), rising linearly in ln PGA to the edge's P; "
                   "default), zero, edge (the edge's P held down to the uplift acceleration) "
                   "or logistic (the fitted surface)")
    p.add_argument("--median-g", type=float, action="append", default=[], metavar="G",
                   help="a stated lognormal fragility over PGA: median PGA (g), 0-10; repeat "
                   "with --beta for a set")
    p.add_argument("--beta", type=float, action="append", default=[], metavar="B",
                   help="its dispersion (natural log), 0.01-3")
    p.add_argument("--logistic", action="append", default=[], metavar="B0,B1,B2",
                   help="a stated logistic surface logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 "
                   "ln(PGV/PGA / 1 s) (b1 > 0); repeat for a set")


def add_ratio_options(p):
    """The PGV/PGA options (a stated lognormal or a ground-motion model) on ``p``."""
    g = p.add_argument_group("PGV/PGA at each PGA level (for a pga-pgv fragility)")
    g.add_argument("--pgv-pga-median", type=float, default=None, metavar="S",
                   help="stated lognormal PGV/PGA: median (s), 0.001-10")
    g.add_argument("--pgv-pga-sigma", type=float, default=None, metavar="LN",
                   help="its sigma (natural log), 0-3")
    g.add_argument("--magnitude", type=float, default=None, metavar="M",
                   help="or from Boore et al. (2014) at this moment magnitude (3-8.5), e.g. "
                   "the mode of the hazard's disaggregation")
    g.add_argument("--distance-km", type=float, default=None, metavar="KM",
                   help="and this Joyner-Boore distance (km, 0-300)")
    g.add_argument("--vs30", type=float, default=760.0, metavar="M_S",
                   help="Vs30 for the model (m/s, 150-1500); default 760")
    g.add_argument("--mechanism", choices=("SS", "NS", "RS"), default="SS",
                   help="fault mechanism for the model (SS strike-slip, NS normal, RS "
                   "reverse); default SS")
    g.add_argument("--pga-pgv-correlation", type=float, default=None, metavar="RHO",
                   help="correlation of ln PGA and ln PGV residuals (0-0.99); default 0.733 "
                   "(Bradley 2012)")


def add_draw_options(p):
    p.add_argument("--draws", type=int, default=400, metavar="N",
                   help="fragility parameter draws for the survival interval (0-20000; 0: "
                   "none); default 400")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws (>= 0); default 0")


def check_fragility_options(args):
    """The fragility, PGV/PGA and draw options range-checked (InputError, one line)."""
    for v in args.median_g:
        number(v, "--median-g", 0, 10, "g", low_open=True)
    for v in args.beta:
        number(v, "--beta", 0.01, 3)
    if len(args.median_g) != len(args.beta):
        raise InputError(f"give one --beta per --median-g ({len(args.median_g)} medians, "
                         f"{len(args.beta)} betas)")
    for text in args.logistic:
        parse_logistic(text)
    if not args.median_g and not args.fragility and not args.logistic:
        raise InputError("no fragility: give --median-g and --beta, --logistic or --fragility")
    stated = (args.pgv_pga_median, args.pgv_pga_sigma)
    modelled = (args.magnitude, args.distance_km)
    if any(v is not None for v in stated) and any(v is not None for v in modelled):
        raise InputError("PGV/PGA: give either --pgv-pga-median/--pgv-pga-sigma or "
                         "--magnitude/--distance-km, not both")
    if any(v is not None for v in stated):
        if None in stated:
            raise InputError("give both --pgv-pga-median and --pgv-pga-sigma")
        number(args.pgv_pga_median, "--pgv-pga-median", 0.001, 10, "s")
        number(args.pgv_pga_sigma, "--pgv-pga-sigma", 0, 3)
    if any(v is not None for v in modelled):
        if None in modelled:
            raise InputError("give both --magnitude and --distance-km")
        number(args.magnitude, "--magnitude", 3, 8.5)
        number(args.distance_km, "--distance-km", 0, 300, "km")
    elif args.pga_pgv_correlation is not None:
        raise InputError("--pga-pgv-correlation applies with --magnitude and --distance-km")
    number(args.vs30, "--vs30", 150, 1500, "m/s")
    if args.pga_pgv_correlation is not None:
        number(args.pga_pgv_correlation, "--pga-pgv-correlation", 0, 0.99)
    if not 0 <= args.draws <= 20000:
        raise InputError(f"--draws must be 0 to 20000, got {args.draws}")
    if args.seed < 0:
        raise InputError(f"--seed must be 0 or more, got {args.seed}")


def load_specimens(args):
    """The fragilities of the options, in order: --fragility files, --median-g/--beta,
    --logistic."""
    from pipeline.hazard.fragility import Logistic, Lognormal, load_campaign_fragility
    from pipeline.records import rotd50_fraction
    specimens = [load_campaign_fragility(path, args.column, args.fragility_form,
                                         args.below_grid, args.hazard_component,
                                         args.magnitude, args.distance_km, rotd50_fraction)
                 for path in args.fragility]
    if args.below_grid != "ramp" and all(f.grid_range() is None for f in specimens):
        raise InputError("--below-grid applies to a pulse-grid fragility (--fragility of "
                         "campaign fragility --pulses, --fragility-form grid)")
    specimens += [Lognormal(m * STANDARD_GRAVITY, b, label=f"stated lognormal: median "
                            f"{m:g} g, beta {b:g}") for m, b in zip(args.median_g, args.beta)]
    specimens += [Logistic(parse_logistic(text), label=f"stated logistic surface {text}")
                  for text in args.logistic]
    return specimens


def ratio_model(args, specimens):
    """The PGV/PGA model of the options, or None; InputError when a fragility needs one."""
    from pipeline.hazard.fragility import PGA_PGV_CORRELATION, RatioFromGmm, RatioLognormal
    ratio = None
    if args.pgv_pga_median is not None:
        ratio = RatioLognormal(args.pgv_pga_median, args.pgv_pga_sigma)
    elif args.magnitude is not None:
        rho = PGA_PGV_CORRELATION if args.pga_pgv_correlation is None \
            else args.pga_pgv_correlation
        ratio = RatioFromGmm(args.magnitude, args.distance_km, args.vs30, args.mechanism, rho)
    if ratio is None and any(f.uses_ratio for f in specimens):
        raise InputError("the fragility is over PGA and PGV/PGA: give --pgv-pga-median and "
                         "--pgv-pga-sigma, or --magnitude and --distance-km (or "
                         "--fragility-form pga)")
    return ratio


def parse_logistic(text):
    """'b0,b1,b2' -> (b0, b1, b2): finite numbers, b1 > 0 (P grows with PGA)."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError(f"--logistic {text!r}: expected three numbers B0,B1,B2")
    if not values[1] > 0:
        raise InputError(f"--logistic {text!r}: b1 must be positive (P grows with PGA)")
    return values
