"""Circular statistics, campaign figures, animation geometry and VTK export."""
import math
import xml.etree.ElementTree as ET

import numpy as np
import pandas as pd
import pytest

from pipeline import analysis, animate
from pipeline.files import InputError


def test_circular_mean_wraps_through_north():
    s = analysis.circular_summary([350.0, 10.0])
    assert min(s["mean_deg"], 360 - s["mean_deg"]) == pytest.approx(0.0, abs=1e-9)
    assert s["resultant_length"] == pytest.approx(math.cos(math.radians(10)))


def test_axial_mean_ignores_sense():
    s = analysis.circular_summary([10.0, 190.0], axial=True)
    assert s["mean_deg"] == pytest.approx(10.0)
    assert s["resultant_length"] == pytest.approx(1.0)
    # the same two directions as vectors cancel
    assert analysis.circular_summary([10.0, 190.0])["resultant_length"] == pytest.approx(0, abs=1e-12)


def test_rayleigh_separates_concentrated_from_uniform():
    rng = np.random.default_rng(3)
    assert analysis.circular_summary(rng.normal(40, 10, 30))["rayleigh_p"] < 1e-6
    assert analysis.circular_summary(np.arange(0, 360, 12.0))["rayleigh_p"] > 0.5


def test_angle_difference_wraps():
    assert analysis.angle_difference_deg(10, 350) == pytest.approx(20)
    assert analysis.angle_difference_deg(350, 10) == pytest.approx(-20)
    assert analysis.angle_difference_deg(0, 180) == pytest.approx(180)


def test_correlation_of_rotated_copy_is_one():
    rng = np.random.default_rng(1)
    a = rng.uniform(0, 360, 40)
    assert analysis.circular_correlation(a, (a + 75) % 360) == pytest.approx(1.0)


def runs_table(n=8):
    rng = np.random.default_rng(0)
    rows = []
    for k in range(n):
        for column in ("drums", "monolithic"):
            toppled = k % 3 != 0
            az = (60 + 20 * rng.standard_normal()) % 360 if toppled else np.nan
            rows.append({"campaign": "test", "run_id": f"r{k}", "record_id": f"R{k % 2}",
                         "column": column, "hd": 3 + 0.5 * k, "mu_s": 0.7, "toppled": toppled,
                         "downfall_azimuth_deg": az, "impact_time_s": 5.0 if toppled else np.nan,
                         "impact_x_m": 2 * math.sin(math.radians(az)) if toppled else np.nan,
                         "impact_y_m": 2 * math.cos(math.radians(az)) if toppled else np.nan,
                         "back_azimuth_deg": 240.0, "az_max_acc_deg": 70.0,
                         "az_max_vel_deg": 65.0, "az_max_disp_deg": 62.0, "pga_h": 2 + k,
                         "pgv_h": 0.2 * (k + 1), "pgd_h": 0.05 * (k + 1), "pgv_pga_h": 0.1})
    return pd.DataFrame(rows)


def test_direction_statistics_sees_the_imposed_alignment():
    stats = analysis.direction_statistics(runs_table(30))
    row = stats[(stats["column"] == "drums") & (stats["record_id"] == "all")
                & (stats["reference"] == "back_azimuth")].iloc[0]
    # falls scattered around 60 deg, back azimuth 240: directionally opposite, axially aligned
    assert abs(row["mean_difference_deg"]) == pytest.approx(180, abs=15)
    assert abs(row["axial_mean_difference_deg"]) < 15


def test_figures_write_pngs(tmp_path):
    runs = runs_table()
    for func, name in ((analysis.plot_rose, "rose.png"),
                       (analysis.plot_toppling_vs_parameters, "params.png"),
                       (analysis.plot_downfall_vs_directions, "dirs.png")):
        func(runs, tmp_path / name)
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    one = runs[runs["record_id"] == "R0"]
    impacts = pd.DataFrame({"run_id": one["run_id"], "column": one["column"], "body_index": 0,
                            "impact_time_s": 5.0, "x_m": one["impact_x_m"].fillna(0),
                            "y_m": one["impact_y_m"].fillna(0), "hd": one["hd"], "mu_s": 0.7,
                            "record_id": "R0"})
    t = np.linspace(0, 10, 1001)
    motion = {"disp": np.column_stack([0.1 * np.sin(t), 0.05 * np.cos(t), 0 * t]),
              "meta": {"back_azimuth_deg": 240.0}}
    analysis.plot_impact_map(one, impacts, motion, tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 10_000


def test_empty_runs_raise_and_write_nothing(tmp_path):
    with pytest.raises(InputError):
        analysis.plot_rose(pd.DataFrame(), tmp_path / "rose.png")
    assert not list(tmp_path.iterdir())


def lying_east_trajectory():
    """One monolith standing, then rotated 90 deg about the North axis (lying East)."""
    q = [math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0]      # w, x, y, z
    body = {"name": "m", "column": "monolithic", "index": 0, "shape": "cylinder",
            "height": 3.5, "radius": 0.3, "mass": 2772.0}
    return {"t": np.array([0.0, 1.0]), "pedestal_disp": np.zeros((2, 3)),
            "pos": np.array([[[0, 0, 1.75]], [[1.75, 0, 0.3]]]),
            "quat": np.array([[[1.0, 0, 0, 0]], [q]]), "bodies": [body]}


def test_body_rotated_about_north_lies_along_east():
    traj = lying_east_trajectory()
    bottom, top = animate.body_surface(traj["bodies"][0], traj["pos"][1, 0], traj["quat"][1, 0])
    axis = top.mean(axis=0) - bottom.mean(axis=0)
    assert axis == pytest.approx([3.5, 0, 0], abs=1e-9)
    assert bottom[:, 2].min() == pytest.approx(0.0, abs=1e-9)   # lies on the pedestal


def test_vtk_export_is_valid_xml_with_all_frames(tmp_path):
    pvd = animate.export_vtk(lying_east_trajectory(), tmp_path, every=1)
    entries = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [float(e.get("timestep")) for e in entries] == [0.0, 1.0]
    piece = ET.parse(tmp_path / entries[1].get("file")).getroot().find("PolyData/Piece")
    n = animate.CIRCLE_SEGMENTS
    assert int(piece.get("NumberOfPoints")) == 4 + 2 * n          # pedestal + two rims
    assert int(piece.get("NumberOfPolys")) == 1 + 2 + n


def test_animation_gif(tmp_path):
    out = animate.animate_run(lying_east_trajectory(), tmp_path / "a.gif", fps=2)
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    with pytest.raises(InputError):
        animate.animate_run(lying_east_trajectory(), tmp_path / "a.avi")
