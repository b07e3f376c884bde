"""The scene file of a scene (:class:`~pipeline.scenario.scene_file.SceneFile`): its
columns and test block placed on the pedestal (sizes in m, mass in kg), the parameters
as dicts and the time step (s) the scene takes.
"""
import dataclasses
import math

from pipeline import paper
from pipeline.files import InputError
from pipeline.scenario import colonnade_scene
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.parameters import Contact, Numerics
from pipeline.scenario.scene_file import SceneFile
from pipeline.scenario.time_step import check_time_step, dt_factor_for, time_step_s

PEDESTAL = {"size": paper.PEDESTAL_SIZE_M, "thickness": paper.PEDESTAL_THICKNESS_M,
            "mass": paper.PEDESTAL_MASS_KG,
            # the top face extends beyond the 5 m block so that a column falling over
            # the edge still lands at pedestal level (impact points up to ~4 m away)
            "contact_half_size": 12.0}

def scene_params(columns=(), block=None, contact=None, numerics=None, motion_duration=0.0,
                 t_max=None, colonnade=None):
    """The scene file (:class:`~pipeline.scenario.scene_file.SceneFile`) of a scene.

    columns: list of :class:`~pipeline.scenario.geometry.ColumnSpec` (from
    :meth:`~pipeline.scenario.parameters.Column.specs`); block: a
    :class:`~pipeline.scenario.parameters.Block` (placed as a column named "block" at the
    centre) or None; contact, numerics: :class:`~pipeline.scenario.parameters.Contact`,
    :class:`~pipeline.scenario.parameters.Numerics` (defaults when None); colonnade: a
    :class:`~pipeline.scenario.colonnade.Colonnade` whose columns and beams join the
    scene (:mod:`pipeline.scenario.colonnade_scene`).
    """
    contact = contact or Contact()
    numerics = numerics or Numerics()
    check_time_step(contact, numerics)
    if not columns and block is None and colonnade is None:
        raise InputError("a scene needs at least one column or a block")
    if t_max is None:
        t_max = motion_duration + numerics.tail_s
    if not (math.isfinite(t_max) and t_max > 0):
        raise InputError(f"simulated duration must be positive, got {t_max!r}")
    specs = list(columns)
    if block is not None:
        specs.append(ColumnSpec("block", "block", 0.0, 0.0, ColumnGeometry.block(
            block.height, block.width, block.depth, block.density, block.theta0_rad)))
    pedestal = dict(PEDESTAL)
    for spec in specs:
        spec.geometry.check_rims(numerics.rim_sphere_radius)
        # a tall column falling over must still land at pedestal level
        reach = math.hypot(spec.x, spec.y) + 1.1 * spec.geometry.height + 2.0
        if reach > pedestal["contact_half_size"]:
            pedestal["contact_half_size"] = float(math.ceil(reach))
    scene_columns = [spec.scene(numerics.rim_points) for spec in specs]
    if colonnade is not None:
        placed = colonnade_scene.scene_columns(colonnade, numerics.rim_points)
        for column in colonnade.columns:
            column.column.check_rims(numerics.rim_sphere_radius)
        for entry in placed:
            reach = colonnade_scene.reach_m(entry)
            if reach > pedestal["contact_half_size"]:
                pedestal["contact_half_size"] = float(math.ceil(reach))
        scene_columns += [entry.to_dict() for entry in placed]
    dt_factor = dt_factor_for(contact, numerics)
    return SceneFile(
        columns=scene_columns, block=None if block is None else dataclasses.asdict(block),
        contact=dataclasses.asdict(contact), numerics=dataclasses.asdict(numerics),
        pedestal=pedestal, dt_factor=dt_factor,
        time_step_s=time_step_s(scene_columns, contact, numerics.rim_points, dt_factor),
        t_max=float(t_max))
