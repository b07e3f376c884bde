"""A colonnade (:class:`~pipeline.scenario.colonnade.Colonnade`) as entries of the scene
file: each column as a column alone would be, its capital's top body carrying a top plate
when beams rest on it; each epistyle and frieze block one box body (its own scene
column, ``rests_on`` its supports) with base rims on the areas where it meets its
supports' top faces, edge rims on its bottom and top outlines (to strike the pedestal
when it falls) and a top plate when frieze blocks rest on it.

Sizes m, mass kg; a beam's body frame: x along its axis, y across, z up, about its centre
of mass.
"""
import dataclasses
import math

import numpy as np

from pipeline.files import InputError
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.outline import clip_convex, perimeter_points
from pipeline.scenario.scene_file import SceneBody, SceneColumn

MAX_SCENE_UNITS = 14     # columns and beams: YADE's collision masks give each two bits


def scene_columns(colonnade, rim_points):
    """The colonnade's :class:`SceneColumn` entries: its columns, then its epistyles and
    frieze blocks."""
    units = len(colonnade.columns) + len(colonnade.epistyles) + len(colonnade.frieze)
    if units > MAX_SCENE_UNITS:
        raise InputError(f"colonnade {colonnade.name}: {units} columns and beams; the YADE "
                         f"scene holds at most {MAX_SCENE_UNITS}")
    faces = colonnade.faces()
    beams = colonnade.epistyles + colonnade.frieze
    loaded = {name for beam in beams for name in beam.on}
    out = []
    for column in colonnade.columns:
        spec = ColumnSpec(column.name, "column", column.x, column.y, column.column)
        scene = spec.geometry.scene_column(spec, rim_points)
        if column.name in loaded:
            scene = _with_top_plate(scene, column)
        out.append(scene)
    uplift = min(c.uplift_ratio for c in out)
    for beam in beams:
        out.append(beam_scene(beam, faces, beam.name in loaded, uplift, rim_points))
    return out


def _with_top_plate(scene, column):
    """``scene`` with its top body's plate: the capital's top face, which beams stand on."""
    body = column.bodies()[-1]
    top, outline = body.top
    hx, hy = outline.half_extents()
    plate = {"centre": (top - body.com).tolist(), "half_size": [hx, hy]}
    bodies = list(scene.bodies)
    bodies[-1] = dataclasses.replace(bodies[-1], plate=plate)
    return dataclasses.replace(scene, bodies=bodies)


def beam_scene(beam, faces, loaded, uplift_ratio, rim_points):
    """The :class:`SceneColumn` of one beam resting on its supports' top ``faces``
    (:meth:`Colonnade.faces`); ``loaded``: frieze blocks rest on it (a top plate);
    ``uplift_ratio``: the colonnade's (a beam lifts only with its columns)."""
    face = faces[beam.name]
    cx, cy = face.centre
    ax, ay = face.axis
    z0 = face.z - beam.height                     # its bottom, on its supports
    rotation = np.array([[ax, -ay, 0.0], [ay, ax, 0.0], [0.0, 0.0, 1.0]])
    centre = np.array([cx, cy, z0 + beam.height / 2])
    L, W, H = beam.length, beam.width, beam.height
    m = beam.mass
    inertia = np.diag([m * (W * W + H * H) / 12, m * (L * L + H * H) / 12,
                       m * (L * L + W * W) / 12])
    box = np.array([[-L / 2, -W / 2], [L / 2, -W / 2], [L / 2, W / 2], [-L / 2, W / 2]])
    rims = []
    for name in beam.on:
        support = faces[name].outline.polygon()
        local = (support - [cx, cy]) @ rotation[:2, :2]      # into the beam's frame
        area = clip_convex(box, local)
        if len(area) < 3:
            raise InputError(f"{beam.what} does not reach {name}, which it is said to rest on")
        rims.append(_polygon_rim("base", area, -H / 2, (0.0, 0.0, 1.0), rim_points))
    rims.append(_polygon_rim("edge", box, -H / 2, (0.0, 0.0, 1.0), rim_points))
    rims.append(_polygon_rim("edge", box, H / 2, (0.0, 0.0, -1.0), rim_points))
    body = SceneBody(
        name=f"{beam.name}[0]", column=beam.name, index=0, block_name=beam.name, blocks=[0],
        shape="box", height=float(face.z), mass=m, inertia=inertia.tolist(),
        principal_axes=np.eye(3).tolist(), centre=centre.tolist(),
        rotation=rotation.tolist(), column_position=[cx, cy],
        parts=[{"shape": "box", "height": H, "width": L, "depth": W, "block": 0,
                "name": beam.name, "bottom_centre": [0.0, 0.0, -H / 2]}],
        rims=rims, plate={"centre": [0.0, 0.0, H / 2], "half_size": [L / 2, W / 2]}
        if loaded else None, rests_on=list(beam.on))
    return SceneColumn(
        name=beam.name, kind=beam.course.value, x=cx, y=cy, description=beam.what,
        height=float(face.z), n_bodies=1, uplift_ratio=uplift_ratio,
        rocking_lever_m=W / 2, overturning_barrier_j=None, settles=False, bodies=[body],
        rests_on=list(beam.on))


def _polygon_rim(role, vertices, z, normal, rim_points):
    v = np.asarray(vertices, float)
    if _signed_area(v) < 0:
        v = v[::-1]
    return {"role": role, "z": z, "normal": list(normal), "kind": "polygon",
            "vertices": v.tolist(), "points": perimeter_points(v, rim_points).tolist()}


def _signed_area(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def reach_m(scene_column):
    """How far (m) from the scene's origin a scene column may land when it falls."""
    return math.hypot(scene_column.x, scene_column.y) + 1.1 * scene_column.height + 2.0
