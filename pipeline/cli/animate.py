"""``animate``: a run as GIF (MP4 with ffmpeg) and a VTK time series for ParaView.

    python -m pipeline animate results/runs/GM20 --out gm20.gif --vtk gm20_vtk
"""
from pathlib import Path

NAME = "animate"
ORDER = 70
HELP = "animate a run (GIF/MP4) and export VTK"


def setup(p):
    p.add_argument("run_dir", type=Path, help="run directory holding trajectory.npz")
    p.add_argument("--out", type=Path, default=None,
                   help="animation file (default RUN/animation.gif)")
    p.add_argument("--fps", type=float, default=20.0, help="frames per second (20)")
    p.add_argument("--max-seconds", type=float, default=None, help="animate only the start")
    p.add_argument("--vtk", type=Path, default=None, metavar="DIR",
                   help="also write a VTK time series (run.pvd) for ParaView")


def run(args):
    from pipeline.figures.animation import animate_run, export_vtk  # lazy: the stage runs only with the command (light start-up and --help)
    out = animate_run(args.run_dir, args.out or args.run_dir / "animation.gif", fps=args.fps,
                      max_seconds=args.max_seconds)
    print(f"wrote {out}")
    if args.vtk:
        print(f"wrote {export_vtk(args.run_dir, args.vtk)}")
    return 0
