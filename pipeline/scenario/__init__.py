"""Scenario stage: parameters (dataclasses), the scene writer and the YADE runner.

A scenario directory holds ``params.json`` (the scene file: every parameter,
:mod:`pipeline.scenario.scene_file`), ``motion.npz``
(the pedestal's ground motion in the processed-motion format of
:mod:`pipeline.motion`) and ``scene.py``, an unchanged copy of
``yade_scripts/column_scene.py``; running it writes ``trajectory.npz``.
"""
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.parameters import Block, Column, Contact, Drive, Numerics, RunParams
from pipeline.scenario.runner import YadeError, run_yade
from pipeline.scenario.scene_build import PEDESTAL, scene_params
from pipeline.scenario.scene_file import SceneFile
from pipeline.scenario.specimen import Specimen
from pipeline.scenario.writer import write_scenario

__all__ = ["PEDESTAL", "Block", "Column", "ColumnGeometry", "ColumnSpec", "Contact", "Drive",
           "Numerics", "RunParams", "SceneFile", "Specimen", "scene_params",
           "write_scenario", "run_yade", "YadeError"]
