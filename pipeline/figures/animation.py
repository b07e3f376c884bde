"""Animations of runs (GIF, or MP4 when ffmpeg is present) and VTK export for ParaView.

Every body of the run is drawn, a colonnade's columns, epistyles and frieze blocks too;
bodies are drawn part by part (a drum, or a capital's echinus and abacus) from the
trajectory (centre of mass + quaternion, body z = long axis) in the absolute frame:
pedestal-frame position + pedestal displacement, so the pedestal is seen to move with
the ground.
"""
import math
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from pipeline.figures.style import COLUMN_COLOURS, figure
from pipeline.files import InputError, atomic_path, write_text
from pipeline.motion import Motion
from pipeline.outcome import Trajectory
from pipeline.outcome.columns import rotations
from pipeline.scenario import PEDESTAL

CIRCLE_SEGMENTS = 24
PEDESTAL_HALF = PEDESTAL["size"] / 2


def load(run):
    """:class:`Trajectory` from a run directory, a trajectory.npz path or a Trajectory."""
    if isinstance(run, Trajectory):
        return run
    path = Path(run)
    if path.is_dir():
        path = path / "trajectory.npz"
    if not path.is_file():
        raise InputError(f"no trajectory found: {path}")
    return Trajectory.load(path)


def start_in_file_s(run):
    """Record time (s) of the first sample of the motion a run's trajectory is on (its
    ``start_in_file_s``), from the ``motion.npz`` beside ``trajectory.npz``; None when
    there is none (a :class:`Trajectory` given as such): times stay on the motion's clock."""
    if isinstance(run, Trajectory):
        return None
    path = Path(run)
    motion = (path if path.is_dir() else path.parent) / "motion.npz"
    return Motion.load(motion).start_in_file_s if motion.is_file() else None


def clock_label(offset):
    """Which clock times shifted by ``offset`` (:func:`start_in_file_s`) are on."""
    return "motion's clock" if offset is None else "record's clock"


def body_parts(body):
    """The solid parts of a trajectory body (body frame about its centre of mass): dicts
    with shape frustum (bottom_diameter, top_diameter) or box (width, depth), height and
    bottom_centre.  Trajectories written before column files carry cylinders and boxes."""
    if "parts" in body:
        return body["parts"]
    h = body["height"]
    if body["shape"] == "cylinder":
        d = 2 * body["radius"]
        return [{"shape": "frustum", "height": h, "bottom_diameter": d, "top_diameter": d,
                 "bottom_centre": [0.0, 0.0, -h / 2]}]
    return [{"shape": "box", "height": h, "width": body["width"], "depth": body["depth"],
             "bottom_centre": [0.0, 0.0, -h / 2]}]


def part_rings(part):
    """Bottom and top outline (2 x k x 3) of one part in the body frame: circles of
    CIRCLE_SEGMENTS points, box faces by their 4 corners."""
    cx, cy, z0 = part["bottom_centre"]
    if part["shape"] == "frustum":
        ang = 2 * math.pi * np.arange(CIRCLE_SEGMENTS) / CIRCLE_SEGMENTS
        unit = np.column_stack([np.cos(ang), np.sin(ang)])
        rings = [unit * part["bottom_diameter"] / 2, unit * part["top_diameter"] / 2]
    else:
        w, d = part["width"] / 2, part["depth"] / 2
        rings = [np.array([[-w, -d], [w, -d], [w, d], [-w, d]])] * 2
    return np.stack([np.column_stack([ring + [cx, cy], np.full(len(ring), z)])
                     for ring, z in zip(rings, (z0, z0 + part["height"]))])


def body_surfaces(body, centre, quat_wxyz):
    """Per part of a body: its bottom and top outline (2 x k x 3), world frame (m)."""
    rot = rotations(quat_wxyz)
    out = []
    for part in body_parts(body):
        local = part_rings(part)
        out.append(rot.apply(local.reshape(-1, 3)).reshape(local.shape)
                   + np.asarray(centre, float))
    return out


def body_top_m(body):
    """Initial height (m) of a body's highest face (upright bodies)."""
    z = body["initial_pos"][2] if "initial_pos" in body else body["height"] / 2
    return max(z + p["bottom_centre"][2] + p["height"] for p in body_parts(body))


def view_box(bodies):
    """The animation's view: (East range, North range, height) m.  Square about the
    middle of the bodies as placed, reaching the pedestal's half width and 1 m beyond
    the outermost body (a column at the centre: the pedestal and 1 m around it; a
    colonnade: every column and beam), as high as the highest face (at least 1 m)."""
    xy = np.array([b["initial_pos"][:2] if "initial_pos" in b else (0.0, 0.0)
                   for b in bodies], float)
    low, high = xy.min(axis=0), xy.max(axis=0)
    middle = (low + high) / 2
    reach = float((high - low).max()) / 2 + PEDESTAL_HALF + 1.0
    return ((middle[0] - reach, middle[0] + reach), (middle[1] - reach, middle[1] + reach),
            max(max(body_top_m(b) for b in bodies), 1.0))


def body_colour(body):
    """A body's line colour: its column's (drums, monolithic, block), a colonnade's beams
    (epistyle and frieze blocks, which rest on others) brown, other columns black."""
    if body["column"] in COLUMN_COLOURS:
        return COLUMN_COLOURS[body["column"]]
    return "tab:brown" if body.get("rests_on") else "k"


def _frame_indices(t, fps, max_seconds):
    end = t[-1] if max_seconds is None else min(t[-1], max_seconds)
    times = np.arange(0.0, end + 1e-9, 1.0 / fps)
    return np.unique(np.clip(np.searchsorted(t, times), 0, len(t) - 1))


def animate_run(run, path, fps=20, max_seconds=None, max_frames=600):
    """Write a 3-D animation of a run to ``path`` (.gif, or .mp4 with ffmpeg)."""
    from matplotlib import animation  # lazy: matplotlib, not imported by a run or after Ctrl-C

    traj = load(run)
    offset = start_in_file_s(run)
    path = Path(path)
    if path.suffix not in (".gif", ".mp4"):
        raise InputError(f"animation must be .gif or .mp4, got {path.name}")
    if path.suffix == ".mp4" and not animation.writers.is_available("ffmpeg"):
        raise InputError("MP4 needs ffmpeg, which is not installed: write a .gif instead")
    t = traj.t
    fps = min(fps, max_frames / max(t[-1], 1e-9)) if max_seconds is None else fps
    frames = _frame_indices(t, fps, max_seconds)
    bodies = traj.bodies
    fig = figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    (x0, x1), (y0, y1), top = view_box(bodies)
    ax.set(xlim=(x0, x1), ylim=(y0, y1), zlim=(0, top),
           xlabel="East (m)", ylabel="North (m)", zlabel="Up (m)")
    ax.set_box_aspect((x1 - x0, y1 - y0, top))
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * PEDESTAL_HALF
    pedestal_line, = ax.plot([], [], [], color="grey")
    # one line per body part: bottom and top outline and every third side edge, apart
    # by NaN (one artist instead of ~10: a frame draws about 3x faster)
    body_lines = [[ax.plot([], [], [], color=body_colour(body), lw=0.8)[0]
                   for _ in body_parts(body)] for body in bodies]
    title = ax.set_title("")
    gap = np.full((1, 3), np.nan)

    def outline(rims):
        """Vertices (n x 3) of a part's line: closed bottom and top rims, side edges."""
        pieces = [np.vstack([rims[0], rims[0][:1]]), gap, np.vstack([rims[1], rims[1][:1]])]
        for a, b in zip(rims[0][::3], rims[1][::3]):
            pieces += [gap, a[None], b[None]]
        return np.vstack(pieces)

    def draw(k):
        disp = traj.pedestal_disp[k]
        pedestal_line.set_data_3d(square[:, 0] + disp[0], square[:, 1] + disp[1],
                                  np.full(5, disp[2]))
        for j, body in enumerate(bodies):
            for rims, line in zip(body_surfaces(body, traj.pos[k, j] + disp, traj.quat[k, j]),
                                  body_lines[j]):
                xyz = outline(rims)
                line.set_data_3d(xyz[:, 0], xyz[:, 1], xyz[:, 2])
        title.set_text(f"t = {t[k] + (offset or 0.0):5.2f} s ({clock_label(offset)})")

    if path.suffix == ".gif":
        # frames drawn here and quantised with Pillow's fast octree (its default
        # median cut took a third of the time of matplotlib's PillowWriter)
        from PIL import Image  # lazy: Pillow with matplotlib's animation, only when animating
        images = []
        for k in frames:
            draw(k)
            fig.canvas.draw()
            rgba = Image.frombuffer("RGBA", fig.canvas.get_width_height(),
                                    fig.canvas.buffer_rgba(), "raw", "RGBA", 0, 1)
            images.append(rgba.convert("RGB").quantize(method=Image.Quantize.FASTOCTREE))
        with atomic_path(path) as tmp:
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                           duration=round(1000 / fps), loop=0)
        return path
    anim = animation.FuncAnimation(fig, draw, frames=frames, interval=1000 / fps)
    with atomic_path(path) as tmp:
        anim.save(tmp.with_suffix(path.suffix), writer=animation.FFMpegWriter(fps=fps))
        tmp.with_suffix(path.suffix).replace(tmp)
    return path


def _vtp(points, polys):
    """XML PolyData (ASCII) with the given points (n x 3) and polygons (lists of indices)."""
    offsets = np.cumsum([len(p) for p in polys])
    return (
        '<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n'
        f'<PolyData><Piece NumberOfPoints="{len(points)}" NumberOfPolys="{len(polys)}">\n'
        '<Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">\n'
        + " ".join(f"{v:.5f}" for v in np.ravel(points)) +
        '\n</DataArray></Points>\n<Polys>\n'
        '<DataArray type="Int32" Name="connectivity" format="ascii">\n'
        + " ".join(str(i) for p in polys for i in p) +
        '\n</DataArray>\n<DataArray type="Int32" Name="offsets" format="ascii">\n'
        + " ".join(str(o) for o in offsets) +
        '\n</DataArray>\n</Polys>\n</Piece></PolyData>\n</VTKFile>\n')


def frame_polydata(traj, k):
    """Points and polygons of all body surfaces (and the pedestal top) at sample k."""
    points, polys = [], []
    disp = traj.pedestal_disp[k]
    sq = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float) * [PEDESTAL_HALF,
                                                                              PEDESTAL_HALF, 1]
    points.extend(sq + disp)
    polys.append([0, 1, 2, 3])
    for j, body in enumerate(traj.bodies):
        for bottom, top in body_surfaces(body, traj.pos[k, j] + disp, traj.quat[k, j]):
            n, base = len(bottom), len(points)
            points.extend(bottom)
            points.extend(top)
            polys.append(list(range(base + n - 1, base - 1, -1)))        # bottom, facing down
            polys.append(list(range(base + n, base + 2 * n)))            # top
            polys.extend([[base + i, base + (i + 1) % n, base + n + (i + 1) % n, base + n + i]
                          for i in range(n)])                            # sides
    return np.array(points), polys


def export_vtk(run, out_dir, every=5):
    """Write frame_XXXXX.vtp files and run.pvd (time series, s on the record's clock when
    the run's motion.npz is found) for ParaView; return the .pvd."""
    traj = load(run)
    offset = start_in_file_s(run) or 0.0
    if every < 1:
        raise InputError(f"every must be at least 1, got {every}")
    out_dir = Path(out_dir)
    entries = []
    for n, k in enumerate(range(0, len(traj.t), every)):
        name = f"frame_{n:05d}.vtp"
        write_text(out_dir / name, _vtp(*frame_polydata(traj, k)))
        entries.append(f'<DataSet timestep="{traj.t[k] + offset:.4f}" file={quoteattr(name)}/>')
    pvd = out_dir / "run.pvd"
    write_text(pvd, '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
               "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
    return pvd
