"""``synthetics``: synthetic near-field motions (pyprop8) around two M 6.5 sources."""
import time

from pipeline.cli._fields import add_arguments, from_args
from pipeline.cli._record_options import SyntheticsOptions
from pipeline.files import LONG_RUN_S, InputError, check_jobs
from pipeline.motion.synthetics import (AZIMUTH_STEP_DEG, GMM_VS30_M_S, QUICK_DURATION_S,
                                        QUICK_FMAX_HZ, RINGS_KM, SOURCES, generate_sources,
                                        source_parameters, write_gmm_summary)

NAME = "synthetics"
ORDER = 50
HELP = "generate synthetic near-field motions (pyprop8) around two M6.5 sources"
DESCRIPTION = ("Compute 3-component synthetic ground motions (pyprop8, layered crust) at sites on "
               "rings around a vertical strike-slip and a thrust source, write them as processed "
               "motions under results/synthetics/<source>/ (cached by parameter hash), and compare "
               "PGA/PGV with NGA-West2 models (results/synthetics/gmm_check.csv).")


def _float_list(text):
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError(f"--rings: not a comma-separated list of km: {text!r}") from None
    return values


def setup(parser):
    parser.add_argument("--source", default="all", help=f"one of {', '.join(SOURCES)} or 'all'")
    parser.add_argument("--rings", default=",".join(f"{r:g}" for r in RINGS_KM),
                        help="ring radii in km (default %(default)s)")
    add_arguments(parser, SyntheticsOptions)
    parser.add_argument("--quick", action="store_true",
                        help=f"fmax {QUICK_FMAX_HZ:g} Hz, {QUICK_DURATION_S:g} s, "
                        "written to results/synthetics-quick")
    parser.add_argument("--jobs", type=int, default=None,
                        help="parallel processes (default: all cores)")
    parser.add_argument("--allow-long", action="store_true",
                        help=f"start a computation estimated to take over "
                        f"{LONG_RUN_S / 3600:g} h on --jobs cores (refused otherwise, before "
                        "it starts)")
    parser.add_argument("--ship", action="store_true",
                        help="compute the sources anew (no cache) and write their pyprop8 "
                        "displacements to records/synthetics/ (maintainers: after a change of "
                        "the generator, its settings or pyprop8; see records/synthetics/README.md)")


def run(args):
    step = from_args(SyntheticsOptions, args).step
    jobs = check_jobs(args.jobs)
    names = list(SOURCES) if args.source == "all" else [args.source]
    for name in names:
        source_parameters(name)
    rings = _float_list(args.rings)
    if args.ship and (args.quick or rings != RINGS_KM or step != AZIMUTH_STEP_DEG):
        raise InputError("--ship writes the displacements of the default settings only: "
                         "drop --quick, --rings and --step")
    started = time.monotonic()
    generated = generate_sources(names, rings, step, quick=args.quick,
                                 jobs=jobs, ship=args.ship, allow_long=args.allow_long)
    for name, paths in generated.items():
        print(f"{name}: {len(paths)} sites in {paths[0].parent}")
    print(f"{time.monotonic() - started:.0f} s (cached when ~0)")
    base = paths[0].parent.parent
    summary = write_gmm_summary(base)
    shown = summary[summary["source"].isin(names)]
    print("synthetic / GMM median (median over sites of each ring; RotD50 unless 'geomean'; "
          f"Vs30 {GMM_VS30_M_S:g} m/s):")
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"written: {base / 'gmm_check.csv'}")
    return 0
