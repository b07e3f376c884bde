"""``contact``: the rocking coefficient of restitution that reproduces a recorded
free-rocking decay of a block, a column or a scanned rock, written to a contact file
(JSON); with ``--damping-map`` also the contact damping that gives it in YADE, and the
damping interval of its standard error.

    python -m pipeline contact --free-rocking decay.csv --block 0.40,0.08 --out contact.json
    python -m pipeline contact --frequency-hz 2.5 --amplitude-ratio 0.62,0.60 --block 0.40,0.08
    python -m pipeline contact --free-rocking decay.csv --column-file rock.json --azimuth 90 \
        --damping-map

The decay file is a CSV with a header: ``time_s`` and ``tilt_rad`` or ``tilt_deg`` (the
block's tilt in its rocking plane, signed).
"""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import paper
from pipeline.files import InputError, write_json

NAME = "contact"
ORDER = 60
HELP = "contact parameters from a free-rocking test of a block (restitution, its uncertainty)"
MAX_ROWS = 1_000_000
TILT_COLUMNS = {"tilt_rad": 1.0, "tilt_deg": math.pi / 180.0}


def setup(p):
    p.add_argument("--free-rocking", type=Path, default=None, metavar="CSV",
                   help="recorded decay: columns time_s and tilt_rad or tilt_deg")
    p.add_argument("--frequency-hz", type=float, default=None, metavar="HZ",
                   help="instead of a record: the rocking frequency (full cycles per s) at "
                   "the amplitudes whose ratios --amplitude-ratio gives")
    p.add_argument("--amplitude-ratio", default=None, metavar="R,R",
                   help="ratios of successive amplitudes (the next over the previous), in (0, 1)")
    p.add_argument("--block", default=None, metavar="HEIGHT,WIDTH",
                   help="the block's height and width in its rocking plane (m)")
    p.add_argument("--column-file", default=None, metavar="NAME_OR_FILE",
                   help="instead of --block: the specimen tested, a column description (as "
                   "the monolith of its outline) or a mesh specimen (a scanned rock)")
    p.add_argument("--azimuth", type=float, default=None, metavar="DEG",
                   help="with --column-file: the direction it was tilted toward (deg "
                   "clockwise from North; default its weak side, where its critical angle "
                   "is smallest)")
    p.add_argument("--damping-map", action="store_true",
                   help="also find the contact damping ratio that gives this restitution in "
                   "the YADE model of the block or specimen (free-rocking runs, bisection: "
                   "minutes; measured restitutions are cached), and the damping interval "
                   "of the restitution +- its standard error, so that `run --contact-file` "
                   "and the campaigns take the file")
    p.add_argument("--depth", type=float, default=None, metavar="M",
                   help="the block's depth across the rocking plane (m; default its width)")
    p.add_argument("--density", type=float, default=None,
                   metavar="KG_M3", help=f"the block's density (default "
                   f"{paper.MARBLE_DENSITY_KG_M3:g} kg/m^3)")
    p.add_argument("--kn", type=float, default=None, metavar="N_M",
                   help=f"contact stiffness per point of the map (default the paper's block "
                   f"{paper.MARBLE_BLOCK_KN_N_M:g} N/m; with --column-file the model's "
                   f"{paper.COLUMN_KN_N_M:g} N/m)")
    p.add_argument("--out", type=Path, default=Path("contact.json"),
                   help="contact file written (JSON; default contact.json)")


def _numbers(text, what, count=None):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{what}: numbers separated by commas needed, got {text!r}") from None
    if count is not None and len(values) != count:
        raise InputError(f"{what}: {count} numbers needed, got {text!r}")
    if not values or not all(math.isfinite(v) for v in values):
        raise InputError(f"{what}: finite numbers needed, got {text!r}")
    return values


def load_free_rocking(path):
    """(time s, tilt rad) arrays of a decay CSV; one-line InputError otherwise."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"--free-rocking {path}: file not found")
    try:
        frame = pd.read_csv(path, nrows=MAX_ROWS + 1)
    except (OSError, ValueError, UnicodeDecodeError, pd.errors.ParserError) as exc:
        raise InputError(f"{path.name}: not a readable CSV ({str(exc).splitlines()[0][:100]})"
                         ) from None
    tilt = [c for c in TILT_COLUMNS if c in frame.columns]
    if "time_s" not in frame.columns or len(tilt) != 1:
        raise InputError(f"{path.name}: columns time_s and one of tilt_rad, tilt_deg needed "
                         f"(found {', '.join(map(str, frame.columns))})")
    if len(frame) > MAX_ROWS:
        raise InputError(f"{path.name}: more than {MAX_ROWS:,} rows")
    values = frame[["time_s", tilt[0]]].apply(pd.to_numeric, errors="coerce").to_numpy(float)
    if not np.all(np.isfinite(values)):
        raise InputError(f"{path.name}: time_s and {tilt[0]} must hold numbers in every row")
    return values[:, 0], values[:, 1] * TILT_COLUMNS[tilt[0]]


def _specimen(args):
    """(geometry, azimuth deg, critical angle rad, equivalent block height and width m:
    the block of the same critical angle and distance from the support line to the centre
    of mass) of ``--column-file``."""
    from pipeline.scenario import ColumnGeometry, Contact, Numerics
    from pipeline.scenario.scene_file import support_line
    from pipeline.verification.contact_map import _scene, weakest_azimuth
    if args.azimuth is not None and not (math.isfinite(args.azimuth) and
                                         0.0 <= args.azimuth < 360.0):
        raise InputError(f"--azimuth must be in [0, 360) deg, got {args.azimuth:g}")
    geometry = ColumnGeometry.load(args.column_file)
    _, column = _scene(geometry, Contact(), Numerics())
    azimuth = weakest_azimuth(column) if args.azimuth is None else args.azimuth
    line = support_line(column, azimuth)
    alpha = line["critical_angle_rad"]
    if not alpha > 0:
        raise InputError(f"{geometry.name}: its centre of mass is not above its footprint "
                         f"toward {azimuth:g} deg")
    arm = line["com"] - line["pivot"]
    radius = float(np.linalg.norm(arm - (arm @ line["axis"]) * line["axis"]))
    return geometry, azimuth, alpha, 2 * radius * math.cos(alpha), 2 * radius * math.sin(alpha)


def run(args):
    from pipeline.rocking import fit_free_rocking
    if (args.block is None) == (args.column_file is None):
        raise InputError("give either --block HEIGHT,WIDTH or --column-file")
    if args.column_file is not None:
        given = [f"--{k}" for k in ("depth", "density") if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)} go(es) with --block: --column-file "
                             "describes the specimen")
        geometry, azimuth, alpha, height, width = _specimen(args)
    else:
        if args.azimuth is not None:
            raise InputError("--azimuth goes with --column-file (a block rocks in its "
                             "width's plane)")
        height, width = _numbers(args.block, "--block HEIGHT,WIDTH", 2)
        if not (0.01 <= height <= 30.0 and 0.005 <= width <= 30.0):
            raise InputError(f"--block: height in [0.01, 30] m and width in [0.005, 30] m "
                             f"needed, got {args.block!r}")
    depth = width if args.depth is None else args.depth
    density = paper.MARBLE_DENSITY_KG_M3 if args.density is None else args.density
    kn = args.kn if args.kn is not None else \
        paper.MARBLE_BLOCK_KN_N_M if args.block is not None else paper.COLUMN_KN_N_M
    if args.damping_map:
        from pipeline.scenario import Block, Contact
        if args.block is not None:
            Block(height=height, width=width, depth=depth, density=density)   # ranges
        Contact(kn=kn)
    else:
        alone = [f"--{k}" for k in ("depth", "density", "kn") if getattr(args, k) is not None]
        if alone:
            raise InputError(f"{', '.join(alone)} go(es) with --damping-map")
    if (args.free_rocking is None) == (args.frequency_hz is None):
        raise InputError("give either --free-rocking CSV or --frequency-hz with "
                         "--amplitude-ratio")
    if args.frequency_hz is not None:
        if not (math.isfinite(args.frequency_hz) and 0.01 <= args.frequency_hz <= 100.0):
            raise InputError(f"--frequency-hz must be in [0.01, 100] Hz, got "
                             f"{args.frequency_hz:g}")
        if args.amplitude_ratio is None:
            raise InputError("--frequency-hz needs --amplitude-ratio")
        ratios = _numbers(args.amplitude_ratio, "--amplitude-ratio")
        if not all(0.0 < r < 1.0 for r in ratios):
            raise InputError(f"--amplitude-ratio: ratios in (0, 1) needed (a free-rocking "
                             f"amplitude decays), got {args.amplitude_ratio!r}")
        fit = fit_free_rocking(height, width, frequency_hz=args.frequency_hz,
                               amplitude_ratios=ratios)
        source = {"frequency_hz": args.frequency_hz, "amplitude_ratios": ratios}
    else:
        if args.amplitude_ratio is not None:
            raise InputError("--amplitude-ratio goes with --frequency-hz, not --free-rocking")
        t, theta = load_free_rocking(args.free_rocking)
        fit = fit_free_rocking(height, width, t=t, theta=theta)
        source = {"free_rocking": str(args.free_rocking)}
    if not 0.0 < fit["restitution"] <= 1.0:
        raise InputError(f"the decay gives a restitution of {fit['restitution']:.3f}, outside "
                         "(0, 1]: amplitudes that grow are not a free-rocking decay")
    result = {"restitution": fit["restitution"], "restitution_sd": fit["restitution_sd"],
              "restitution_se": fit["restitution_se"], "impacts": fit["impacts"],
              "restitution_per_impact": [float(e) for e in fit["restitution_per_impact"]],
              "housner_restitution": fit["housner_restitution"], "source": source}
    if args.block is not None:
        result["block"] = {"height_m": height, "width_m": width}
        what = "this block"
    else:
        result["specimen"] = {"description": str(args.column_file), "name": geometry.name,
                              "azimuth_deg": azimuth, "critical_angle_deg": math.degrees(alpha),
                              "equivalent_block": {"height_m": height, "width_m": width}}
        what = f"{geometry.name} toward {azimuth:g} deg"
    if args.damping_map:
        from pipeline.verification import contact_map
        if args.block is not None:
            measured_at, runs = contact_map.block_measure(height, width, depth, kn, density)
            extra = {"depth_m": depth, "density_kg_m3": density}
        else:
            measured_at, measures = contact_map.specimen_measure(geometry, kn, azimuth)
            runs = lambda: measures() * len(contact_map.SPECIMEN_RELEASES)   # noqa: E731
            extra = {"azimuth_deg": azimuth,
                     "release_ratios": list(contact_map.SPECIMEN_RELEASES)}
        reach = f"{what} (kn {kn:g} N/m)"
        damping, measured = contact_map.bisect_damping(fit["restitution"], measured_at, reach)
        interval = contact_map.damping_interval(fit["restitution"], fit["restitution_se"],
                                                measured_at, reach)
        result.update(kn=kn, damping=damping, damping_interval=interval, damping_map={
            "measured_restitution": measured, "tolerance": contact_map.RESTITUTION_TOLERANCE,
            "yade_runs": runs(), **extra})
        print(f"damping {damping:.3f} per contact at kn {kn:g} N/m gives {what} a "
              f"restitution of {measured:.4f} in YADE ({runs()} free-rocking run(s) made; "
              "measured ones are kept in results/contact/restitution_map.json)")
        if interval is None:
            print("damping interval: none (one impact: no standard error of the restitution)")
        else:
            beyond = f" ({', '.join(interval['clipped'])} end at the reachable range's end)" \
                if interval["clipped"] else ""
            print(f"damping interval {interval['low']:.3f}-{interval['high']:.3f}: the "
                  f"restitution {interval['restitution_high']:.4f}-"
                  f"{interval['restitution_low']:.4f} (+- its standard error){beyond}")
    write_json(args.out, result)
    spread = "" if fit["restitution_sd"] is None else \
        f" +- {fit['restitution_se']:.3f} (standard error; single impacts scatter " \
        f"{fit['restitution_sd']:.3f})"
    print(f"restitution {fit['restitution']:.3f}{spread} from {fit['impacts']} impact(s); "
          f"a rigid block of this {'shape' if args.block else 'critical angle'}: "
          f"{fit['housner_restitution']:.3f} (Housner)")
    print(f"wrote {args.out}")
    return 0
