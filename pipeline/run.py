"""The ``run`` command: one record through one YADE scenario to ``summary.json``.

    python -m pipeline run --record GM20 --column both --hd 6 --out results/runs/GM20
"""
import math
from pathlib import Path

import numpy as np

from pipeline import RESULTS_DIR, outcome, records, scenario
from pipeline.files import InputError, write_json


def rotate_horizontal(vectors, degrees):
    """Turn horizontal motion clockwise (seen from above) by ``degrees``: a motion
    along azimuth phi becomes one along phi + degrees.  vectors: (n, 3) E/N/U."""
    b = math.radians(degrees)
    out = np.array(vectors, float)
    e, n = out[:, 0].copy(), out[:, 1].copy()
    out[:, 0] = e * math.cos(b) + n * math.sin(b)
    out[:, 1] = -e * math.sin(b) + n * math.cos(b)
    return out


def drive_motion(motion, window=None, rotate_deg=0.0, scale=1.0):
    """Pedestal motion dict (dt, acc, disp) from a processed motion, optionally cut to
    ``window`` = (start_s, end_s), turned by ``rotate_deg`` and scaled by ``scale``."""
    dt = motion["dt"]
    acc, disp = np.asarray(motion["acc"]), np.asarray(motion["disp"])
    if window is not None:
        start, end = window
        if not (0 <= start < end):
            raise InputError(f"window must satisfy 0 <= start < end, got {start}, {end}")
        i0, i1 = int(round(start / dt)), int(round(end / dt)) + 1
        if i0 >= len(acc) - 1:
            raise InputError(f"window starts at {start} s, after the record ends "
                             f"({(len(acc) - 1) * dt:.1f} s)")
        acc, disp = acc[i0:i1], disp[i0:i1] - disp[i0]
    if not math.isfinite(scale) or scale < 0:
        raise InputError(f"scale must be a non-negative number, got {scale}")
    return {"dt": dt, "acc": rotate_horizontal(acc, rotate_deg) * scale,
            "disp": rotate_horizontal(disp, rotate_deg) * scale}


def back_azimuth_of(meta, override=None, rotate_deg=0.0):
    """Back azimuth (deg) from the command line or the record metadata, turned with the
    motion; None if unknown."""
    value = override if override is not None else meta.get("back_azimuth_deg")
    if value is None or not math.isfinite(value):
        return None
    return float((value + rotate_deg) % 360.0)


def simulate(record, out_dir, column="both", hd=6.0, height=3.5, n_drums=7, density=2960.0,
             centred=None, back_azimuth=None, window=None, rotate_deg=0.0, scale=1.0,
             timeout_s=None, **scene_options):
    """Run one scenario and write ``out_dir/summary.json``; return the summary dict.

    record: catalogue id, record file or processed .npz.  scene_options: contact
    (kn, damping, mu_s, mu_k) and numerics keys of pipeline.scenario.
    """
    motion_path = records.processed_motion_path(record, back_azimuth=back_azimuth)
    motion = records.load_motion(motion_path)
    drive = drive_motion(motion, window, rotate_deg, scale)
    columns = scenario.column_specs(column, hd, height, n_drums, density, centred)
    duration = (len(drive["acc"]) - 1) * drive["dt"]
    params = scenario.scene_params(columns=columns, motion_duration=duration, **scene_options)
    out_dir = Path(out_dir)
    scenario.write_scenario(out_dir, params, drive)
    trajectory = scenario.run_yade(out_dir, timeout_s=timeout_s)
    parameters = {"column": column, "hd": hd, "height_m": height, "n_drums": n_drums,
                  "density_kg_m3": density, **params["contact"], "window_s": window,
                  "rotate_deg": rotate_deg, "scale": scale, "motion_file": str(motion_path)}
    summary = outcome.summarise(trajectory, record=motion["meta"].get("record_id", str(record)),
                                back_azimuth_deg=back_azimuth_of(motion["meta"], back_azimuth,
                                                                 rotate_deg),
                                parameters=parameters)
    write_json(out_dir / "summary.json", summary)
    return summary


def add_command(subparsers):
    p = subparsers.add_parser(
        "run", help="simulate columns on a pedestal shaken by one record",
        description="Process the record if needed, write the YADE scenario, run it and write "
        "DIR/summary.json (toppled, downfall azimuth, impact time and points per column).")
    p.add_argument("--record", required=True, metavar="ID_OR_PATH",
                   help="catalogue id (records/catalog.csv), record file or processed .npz")
    p.add_argument("--column", default="both", choices=["both", "monolithic", "drums"],
                   help="both = the paper's twin model (default)")
    p.add_argument("--hd", type=float, default=6.0, help="slenderness h/d (default 6)")
    p.add_argument("--height", type=float, default=3.5, help="column height in m (default 3.5)")
    p.add_argument("--drums", type=int, default=7, help="number of drums (default 7)")
    p.add_argument("--density", type=float, default=2960.0, help="kg/m^3 (default 2960)")
    p.add_argument("--mu-s", type=float, default=0.7, help="static friction (default 0.7)")
    p.add_argument("--mu-k", type=float, default=0.6, help="kinetic friction (default 0.6)")
    p.add_argument("--kn", type=float, default=1.2e8,
                   help="normal stiffness per rim contact point, N/m (default 1.2e8)")
    p.add_argument("--damping", type=float, default=0.36, help="contact damping ratio (0.36)")
    p.add_argument("--back-azimuth", type=float, default=None, metavar="DEG",
                   help="back azimuth to the epicentre when the record does not give it")
    p.add_argument("--window", type=float, nargs=2, default=None, metavar=("START", "END"),
                   help="use only this excerpt of the record (s)")
    p.add_argument("--rotate", type=float, default=0.0, metavar="DEG",
                   help="turn the horizontal motion clockwise by DEG")
    p.add_argument("--scale", type=float, default=1.0, help="scale the motion (default 1)")
    p.add_argument("--centred", action="store_true",
                   help="put a single column at the pedestal centre (default for one column)")
    p.add_argument("--dt-factor", type=float, default=scenario.NUMERICS_DEFAULTS["dt_factor"],
                   help="time step as a fraction of sqrt(m/kn)")
    p.add_argument("--rim-points", type=int, default=scenario.NUMERICS_DEFAULTS["rim_points"],
                   help="contact spheres per rim")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="output directory (default results/runs/<record>)")
    p.set_defaults(func=run_command)


def run_command(args):
    out = args.out or RESULTS_DIR / "runs" / Path(str(args.record)).stem
    summary = simulate(args.record, out, column=args.column, hd=args.hd, height=args.height,
                       n_drums=args.drums, density=args.density, back_azimuth=args.back_azimuth,
                       centred=True if args.centred else None, window=args.window,
                       rotate_deg=args.rotate, scale=args.scale, mu_s=args.mu_s, mu_k=args.mu_k,
                       kn=args.kn, damping=args.damping, dt_factor=args.dt_factor,
                       rim_points=args.rim_points)
    for col in summary["columns"]:
        if col["toppled"]:
            print(f"{col['column']:>10}: toppled toward {col['downfall_azimuth_deg']:.0f} deg "
                  f"at {col['impact_time_s']:.2f} s")
        else:
            print(f"{col['column']:>10}: standing (max tilt {col['max_tilt_deg']:.1f} deg)")
    print(f"wrote {out / 'summary.json'} ({summary['simulated_s']:.1f} s simulated in "
          f"{summary['wall_s']:.1f} s)")
    return 0
