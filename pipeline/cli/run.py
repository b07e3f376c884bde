"""``run``: one record through one YADE scenario to DIR/summary.json.

    python -m pipeline run --record GM20 --column both --hd 6 --out results/runs/GM20
"""
from dataclasses import fields
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.campaign.column_file import paper_rocking_hz
from pipeline.constants import COLUMN_TYPES
from pipeline.files import DirectoryLock, InputError
from pipeline.motion import RECORD_CLOCK
from pipeline.records import processed_motion, resolve
from pipeline.scenario import Column, Contact, Drive, Numerics, RunParams
from pipeline.cli._fields import add_arguments, add_column_file_argument, from_args
from pipeline.scenario.scene_build import scene_params
from pipeline.scenario.time_step import check_cost, check_time_step
from pipeline.scenario.runner import wall_limit_s
from pipeline.simulate import MAX_SCALE, back_azimuth_of, simulate

NAME = "run"
ORDER = 20
HELP = "simulate columns on a pedestal shaken by one record"
DESCRIPTION = ("Process the record, write the YADE scenario, run it and write DIR/summary.json "
               "(toppled, downfall azimuth, impact time and points per column).")
MAX_DURATION_S = 300.0   # longer motions need --window
SOFT_CONTACT_HZ = 8.0    # a described column rocking on its contact springs slower: a note


def setup(p):
    p.add_argument("--record", required=True, metavar="ID_OR_PATH",
                   help="catalogue id (records/catalog.csv), record file or processed .npz")
    add_arguments(p, Column)
    add_column_file_argument(p, "with --column both a monolith of the same outline stands "
                             "beside it; excludes --hd, --height, --drums, --density")
    add_arguments(p, Contact)
    p.add_argument("--contact-file", type=Path, default=None, metavar="JSON",
                   help="contact parameters (kn, damping; mu_s, mu_k) from a file `contact` "
                   "wrote (a free-rocking test)")
    add_arguments(p, Numerics)
    p.add_argument("--back-azimuth", type=float, default=None, metavar="DEG",
                   help="back azimuth to the epicentre when the record does not give it, [0, 360)")
    p.add_argument("--window", type=float, nargs=2, default=None, metavar=("START", "END"),
                   help="use only this excerpt of the record (s after the record's first "
                   f"sample, as the times printed); needed above {MAX_DURATION_S:g} s")
    p.add_argument("--rotate", type=float, default=0.0, metavar="DEG",
                   help="turn the horizontal motion clockwise by DEG")
    p.add_argument("--scale", type=float, default=1.0,
                   help=f"scale the motion (default 1; 0-{MAX_SCALE:g})")
    p.add_argument("--centred", action="store_true",
                   help="put a single column at the pedestal centre (default for one column)")
    p.add_argument("--processing", choices=("default", "none"), default="default",
                   help="default: cut, offset, taper, 0.1-25 Hz band-pass, baseline "
                   "(pipeline/records/processing.py); none: the file's acceleration as given "
                   "(an already processed motion: synthetic, shake table, analytic pulse); "
                   "recorded in summary.json")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="output directory (default results/runs/<record id>)")


def check_run_options(args):
    """Validate the options that are not parameter dataclasses (one line each)."""
    if args.back_azimuth is not None:
        back_azimuth_of(None, args.back_azimuth)
    Drive(args.window, args.rotate, args.scale)       # --window, --rotate, --scale
    if getattr(args, "column_file", None) is not None:
        given = [flag for flag, name in (("--hd", "hd"), ("--height", "height"),
                                         ("--drums", "n_drums"), ("--density", "density"))
                 if getattr(args, name, None) is not None]
        if given:
            raise InputError(f"--column-file describes the column: drop {', '.join(given)}")


def run(args):
    check_run_options(args)
    column = from_args(Column, args, centred=True if args.centred else None)
    if column.colonnade is not None:
        given = [flag for flag, name in (("--column", "kind"), ("--centred", "centred"))
                 if getattr(args, name, None)]
        if given:
            raise InputError(f"--column-file {column.colonnade.name} is a colonnade, which "
                             f"places its own columns: drop {', '.join(given)}")
    contact, numerics = _contact(args), from_args(Numerics, args)
    check_time_step(contact, numerics)
    out = args.out
    if out is None:
        out = RESULTS_DIR / "runs" / resolve(args.record).id
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} exists and is not a directory")
    motion, _ = processed_motion(args.record, back_azimuth=args.back_azimuth, cache_dir=None,
                                 mode=args.processing)
    length = _simulated_length(motion, args.window)
    check_cost(scene_params(columns=column.specs(), colonnade=column.colonnade,
                            contact=contact, numerics=numerics,
                            motion_duration=length), wall_limit_s(length + numerics.tail_s))
    with DirectoryLock(out, wait=False):
        summary = simulate(motion, out, RunParams(column, contact, numerics, Drive(
            args.window, args.rotate, args.scale)), back_azimuth=args.back_azimuth)
    if not summary.simulated:
        print(f"note: {summary.note}")
    elif not any(c.max_tilt_deg > 0.1 for c in summary.columns):
        print("note: the motion did not make any column rock (max tilt below 0.1 deg)")
    _print_column(column, contact, numerics)
    if summary.start_in_file_s != 0.0:
        print(f"times in {RECORD_CLOCK} (the simulated motion, and trajectory.npz's clock, "
              f"start at {summary.start_in_file_s:.2f} s)")
    for col in summary.columns:
        print(_outcome_line(col, column.geometry is not None))
    if summary.colonnade is not None:
        whole = summary.colonnade
        spread = ("" if whole.fall_azimuth_spread_deg is None else
                  f", fall azimuths spread {whole.fall_azimuth_spread_deg:.0f} deg")
        print(f"colonnade {whole.name}: {whole.columns_fallen} of {whole.columns} columns and "
              f"{whole.beams_fallen} of {whole.beams} beams fell{spread}")
    print(f"wrote {out / 'summary.json'} ({summary.simulated_s:.1f} s simulated in "
          f"{summary.wall_s:.1f} s)")
    return 0


def _contact(args):
    """The run's Contact: the flags, or a contact file's values beside them (a value
    given in both refused)."""
    if args.contact_file is None:
        return from_args(Contact, args)
    from pipeline.scenario.contact_file import checked_contact, load_contact_file  # lazy: the stage runs only with the command (light start-up and --help)
    from_file = load_contact_file(args.contact_file)
    both = [f"--{k.replace('_', '-')}" for k in from_file if getattr(args, k) is not None]
    if both:
        raise InputError(f"--contact-file sets {', '.join(both)}: give it there or on the "
                         "command line, not both")
    flags = {f.name: getattr(args, f.name) for f in fields(Contact)
             if getattr(args, f.name, None) is not None}
    return checked_contact(from_file, args.contact_file, **flags)


def _simulated_length(motion, window):
    """Seconds of ``motion`` simulated (``window``: START END in the record's clock, or
    None); InputError when the window misses the motion or it is too long."""
    if window:
        first, last = motion.start_in_file_s, motion.start_in_file_s + motion.duration
        if not first - 1e-9 <= window[0] < last:
            where = "before the motion starts" if window[0] < first else \
                "after the motion ends"
            raise InputError(f"--window starts at {window[0]:g} s, {where} (it spans "
                             f"{first:.2f} to {last:.2f} s after the record's first sample)")
        length = min(window[1], last) - window[0]
        if length > MAX_DURATION_S:
            raise InputError(f"--window spans {length:.0f} s: at most {MAX_DURATION_S:g} s "
                             "are simulated")
        return length
    if motion.duration > MAX_DURATION_S:
        raise InputError(f"the record lasts {motion.duration:.0f} s: give --window START "
                         f"END (at most {MAX_DURATION_S:g} s simulated)")
    return motion.duration


def _print_column(column, contact, numerics):
    """What was shaken: a mesh specimen's mass properties or a described column's types,
    and a note when it rocks on soft contact springs."""
    if getattr(column.geometry, "mesh_path", None):
        rock = column.geometry
        print(f"specimen {rock.name!r} from {Path(rock.mesh_path).name}: {rock.mass:.1f} kg, "
              f"centre of mass {rock.com[2]:.3f} m up, critical angle "
              f"{rock.critical_angle_deg():.1f} deg"
              + (f", settled {rock.settled_by_deg:.2f} deg onto its base"
                 if rock.settled_by_deg > 0.01 else ""))
    elif column.colonnade is not None:
        c = column.colonnade
        print(f"colonnade {c.name!r}: {len(c.columns)} columns, {len(c.epistyles)} epistyles, "
              f"{len(c.frieze)} frieze blocks")
    elif column.geometry is not None:
        roles = {"drums": "'drums' = as described",
                 "monolithic": "'monolithic' = one stone of its outline"}
        shown = list(COLUMN_TYPES) if column.kind == "both" else [column.kind]
        print(f"column {column.geometry.name!r}: " + ", ".join(roles[k] for k in shown))
    if column.geometry is not None:
        hz = column.geometry.contact_rocking_hz(contact.kn, numerics.rim_points)
        if hz < SOFT_CONTACT_HZ:
            print(f"note: with --kn {contact.kn:g} this column rocks on its contact springs "
                  f"at {hz:.1f} Hz (the paper's column at {paper_rocking_hz():.1f} Hz): raise --kn (campaign "
                  "columns does) for rigid-block behaviour")


def _outcome_line(col, described):
    """One column's outcome in one line (``described``: a column file's, whose bodies
    have names)."""
    if not col.toppled:
        return f"{col.column:>10}: standing (max tilt {col.max_tilt_deg:.1f} deg)"
    if col.toppled_by == "rests past its critical angle":
        return (f"{col.column:>10}: overturned toward {col.downfall_azimuth_deg:.0f} deg "
                f"(past its critical angle from {col.impact_time_s:.2f} s on)")
    first = min((b for b in col.bodies if b["struck"]), default=None,
                key=lambda b: b["impact_time_s"])
    more = ""
    if described and first is not None:
        more = f" (first to strike: {first.get('name') or 'body %d' % first['index']})"
    how = "" if col.toppled_by in (None, "impact") else f" ({col.toppled_by})"
    return (f"{col.column:>10}: toppled toward {col.downfall_azimuth_deg:.0f} deg "
            f"at {col.impact_time_s:.2f} s{more}{how}")
