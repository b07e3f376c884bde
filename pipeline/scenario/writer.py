"""Write a scenario directory: params.json, motion.npz and scene.py (values never in code)."""
import dataclasses
import shutil
from pathlib import Path

from pipeline import YADE_SCRIPTS_DIR

SCENE_TEMPLATE = YADE_SCRIPTS_DIR / "column_scene.py"


def write_scenario(run_dir, params, motion=None):
    """Write params.json (``params``, a :class:`~pipeline.scenario.scene_file.SceneFile`),
    motion.npz (if ``motion``, a :class:`~pipeline.motion.Motion`) and scene.py into
    ``run_dir``; return the scene path."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    if motion is not None:
        motion.save(run_dir / "motion.npz")
        params = dataclasses.replace(params, motion_file="motion.npz")
    params.write(run_dir)
    shutil.copyfile(SCENE_TEMPLATE, run_dir / "scene.py")
    return run_dir / "scene.py"
