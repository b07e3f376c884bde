"""``animate``: a run as GIF (MP4 with ffmpeg) and a VTK time series for ParaView.

    python -m pipeline animate results/runs/GM20 --out gm20.gif --vtk gm20_vtk
"""
from pathlib import Path

from pipeline.cli._fields import add_arguments, from_args
from pipeline.figures.animation_options import AnimationOptions

NAME = "animate"
ORDER = 70
HELP = "animate a run (GIF/MP4) and export VTK"


def setup(p):
    p.add_argument("run_dir", type=Path, help="run directory holding trajectory.npz")
    p.add_argument("--out", type=Path, default=None,
                   help="animation file (default RUN/animation.gif)")
    add_arguments(p, AnimationOptions)
    p.add_argument("--vtk", type=Path, default=None, metavar="DIR",
                   help="also write a VTK time series (run.pvd) for ParaView")


def run(args):
    options = from_args(AnimationOptions, args)
    from pipeline.figures.animation import animate_run, export_vtk  # lazy: the stage runs only with the command (light start-up and --help)
    out = animate_run(args.run_dir, args.out or args.run_dir / "animation.gif",
                      fps=options.fps, max_seconds=options.max_seconds)
    print(f"wrote {out}")
    if args.vtk:
        print(f"wrote {export_vtk(args.run_dir, args.vtk)}")
    return 0
