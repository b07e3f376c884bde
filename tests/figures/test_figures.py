"""Campaign figures, animation geometry and VTK export."""
import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pandas as pd
import pytest

from pipeline.figures import animation
from pipeline.figures import campaign as campaign_figures
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.outcome import Trajectory
from tests.refusal import refused


def test_figures_write_pngs(tmp_path, runs_table):
    runs = runs_table()
    for func, name in ((campaign_figures.plot_rose, "rose.png"),
                       (campaign_figures.plot_toppling_vs_parameters, "params.png"),
                       (campaign_figures.plot_downfall_vs_directions, "dirs.png")):
        func(runs, tmp_path / name)
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    one = runs[runs["record_id"] == "R0"]
    impacts = pd.DataFrame({"run_id": one["run_id"], "column": one["column"], "body_index": 0,
                            "impact_time_s": 5.0, "x_m": one["impact_x_m"].fillna(0),
                            "y_m": one["impact_y_m"].fillna(0), "hd": one["hd"], "mu_s": 0.7,
                            "record_id": "R0"})
    t = np.linspace(0, 10, 1001)
    disp = np.column_stack([0.1 * np.sin(t), 0.05 * np.cos(t), 0 * t])
    motion = Motion(0.01, disp, disp, disp, meta={"back_azimuth_deg": 240.0})
    campaign_figures.plot_impact_map(one, impacts, motion, tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 10_000


def test_empty_runs_raise_and_write_nothing(tmp_path):
    with pytest.raises(InputError):
        campaign_figures.plot_rose(pd.DataFrame(), tmp_path / "rose.png")
    assert not list(tmp_path.iterdir())


def lying_east_trajectory():
    """One monolith standing, then rotated 90 deg about the North axis (lying East)."""
    q = [math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0]      # w, x, y, z
    body = {"name": "m", "column": "monolithic", "index": 0, "shape": "cylinder",
            "height": 3.5, "radius": 0.3, "mass": 2772.0}
    return Trajectory(t=np.array([0.0, 1.0]), pedestal_disp=np.zeros((2, 3)),
                      pos=np.array([[[0, 0, 1.75]], [[1.75, 0, 0.3]]]),
                      quat=np.array([[[1.0, 0, 0, 0]], [q]]), bodies=[body])


def test_body_rotated_about_north_lies_along_east():
    traj = lying_east_trajectory()
    bottom, top = animation.body_surfaces(traj.bodies[0], traj.pos[1, 0], traj.quat[1, 0])[0]
    axis = top.mean(axis=0) - bottom.mean(axis=0)
    assert axis == pytest.approx([3.5, 0, 0], abs=1e-9)
    assert bottom[:, 2].min() == pytest.approx(0.0, abs=1e-9)   # lies on the pedestal


def test_vtk_export_is_valid_xml_with_all_frames(tmp_path):
    pvd = animation.export_vtk(lying_east_trajectory(), tmp_path, every=1)
    entries = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [float(e.get("timestep")) for e in entries] == [0.0, 1.0]
    piece = ET.parse(tmp_path / entries[1].get("file")).getroot().find("PolyData/Piece")
    n = animation.CIRCLE_SEGMENTS
    assert int(piece.get("NumberOfPoints")) == 4 + 2 * n          # pedestal + two rims
    assert int(piece.get("NumberOfPolys")) == 1 + 2 + n


def test_a_run_directory_animates_on_the_record_clock(tmp_path):
    """A run directory whose motion starts 30 s before the record's first sample: the
    VTK series' time steps are the trajectory's times on the record's clock."""
    traj = lying_east_trajectory()
    np.savez(tmp_path / "trajectory.npz", t=traj.t, pos=traj.pos, quat=traj.quat,
             bodies=np.array(json.dumps(traj.bodies)), vel=traj.vel, angvel=traj.angvel,
             pedestal_disp=traj.pedestal_disp, dt=1e-4, motion_end=1.0, stopped_early=False)
    zeros = np.zeros((3, 3))
    Motion(0.5, zeros, zeros, zeros, meta={"start_in_file_s": -30.0}).save(
        tmp_path / "motion.npz")
    assert animation.start_in_file_s(tmp_path) == -30.0
    assert animation.start_in_file_s(traj) is None          # no run directory: its own clock
    pvd = animation.export_vtk(tmp_path, tmp_path / "vtk", every=1)
    entries = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [float(e.get("timestep")) for e in entries] == [-30.0, -29.0]


def _run_dir(path):
    """A run directory of the lying column's trajectory (no motion.npz: its own clock)."""
    traj = lying_east_trajectory()
    path.mkdir()
    np.savez(path / "trajectory.npz", t=traj.t, pos=traj.pos, quat=traj.quat,
             bodies=np.array(json.dumps(traj.bodies)), vel=traj.vel, angvel=traj.angvel,
             pedestal_disp=traj.pedestal_disp, dt=1e-4, motion_end=1.0, stopped_early=False)
    return path


@pytest.mark.parametrize("option, words", [
    (["--fps", "0"], "--fps 0 outside the allowed range (0, inf]"),
    (["--fps", "-5"], "--fps -5 outside the allowed range (0, inf]"),
    (["--fps", "nan"], "--fps must be a finite number"),
    (["--max-seconds", "-1"], "--max-seconds -1 outside the allowed range (0, inf] s"),
])
def test_animate_refuses_a_frame_rate_or_length_it_cannot_draw(tmp_path, capsys, option, words):
    """No frames at 0 or fewer per second, nor before the run starts: one line, no file."""
    run = _run_dir(tmp_path / "run")
    out = tmp_path / "a.gif"
    refused(capsys, ["animate", run, "--out", out, *option], words, out)


def test_animation_gif(tmp_path):
    from PIL import Image
    traj = lying_east_trajectory()
    out = animation.animate_run(traj, tmp_path / "a.gif", fps=2)
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    with Image.open(out) as gif:    # frames every 0.5 s: both samples (t 0 and 1 s), 500 ms
        assert gif.n_frames == len(traj.t) == 2
        assert gif.info["duration"] == 500
    with pytest.raises(InputError):
        animation.animate_run(lying_east_trajectory(), tmp_path / "a.avi")


def colonnade_trajectory():
    """The shipped colonnade's bodies as placed (no YADE): standing, then every body
    moved 0.5 m East."""
    from scipy.spatial.transform import Rotation

    from pipeline.scenario import scene_params
    from pipeline.scenario.colonnade_file import load
    scene = scene_params(colonnade=load("parthenon-north-flank"), t_max=1.0)
    bodies = [dict(b, initial_pos=b["centre"], initial_rotation=b["rotation"])
              for column in scene.columns for b in column["bodies"]]
    pos = np.array([b["centre"] for b in bodies], float)
    quat = Rotation.from_matrix([b["rotation"] for b in bodies]).as_quat()[:, [3, 0, 1, 2]]
    return Trajectory(t=np.array([0.0, 1.0]), pos=np.stack([pos, pos + [0.5, 0.0, 0.0]]),
                      quat=np.stack([quat, quat]), bodies=bodies)


def test_a_colonnade_animates_with_every_body_in_view(tmp_path):
    from PIL import Image
    traj = colonnade_trajectory()
    kinds = {b["column"][0] for b in traj.bodies}
    assert kinds == {"N", "E", "F"}                # columns, epistyles, frieze blocks
    (x0, x1), (y0, y1), top = animation.view_box(traj.bodies)
    for body in traj.bodies:                        # every body as placed, 1 m inside
        x, y, _ = body["initial_pos"]
        assert x0 + 1.0 < x < x1 - 1.0 and y0 + 1.0 < y < y1 - 1.0
    assert top == pytest.approx(max(b["centre"][2] + b["parts"][0]["height"] / 2
                                    for b in traj.bodies if b["column"].startswith("F")))
    assert {animation.body_colour(b) for b in traj.bodies if b.get("rests_on")} == \
        {"tab:brown"}
    # every body part in the frame: a box 2 + 4 polygons, a frustum 2 + CIRCLE_SEGMENTS
    points, polys = animation.frame_polydata(traj, 1)
    parts = [p for b in traj.bodies for p in animation.body_parts(b)]
    n = animation.CIRCLE_SEGMENTS
    assert len(polys) == 1 + sum(6 if p["shape"] == "box" else 2 + n for p in parts)
    out = animation.animate_run(traj, tmp_path / "colonnade.gif", fps=1)
    with Image.open(out) as gif:
        assert gif.n_frames == 2
