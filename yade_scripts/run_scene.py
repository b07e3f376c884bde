# Run a generated YADE scene with YADE imported as a Python module.
#
#     /usr/bin/python3 run_scene.py DIR/scene.py
#
# Unlike the `yade` launcher this opens no network port (the launcher serves a
# Python prompt on 0.0.0.0:9000 and an info server on 0.0.0.0:21000) and saves
# the launcher's start-up.  YADE's compiled module is built for Debian's python3
# and its numpy, so this runs under /usr/bin/python3, not the project's venv.
# `yade -n -x scene.py` still runs the same scene on its own.
import os
import runpy
import sys

YADE_PY = os.environ.get("YADE_PY_PATH", "/usr/lib/x86_64-linux-gnu/yade-double/py")
sys.path.insert(1, YADE_PY)
import yade  # noqa: E402,F401  (boots YADE: plugins, O)

scene = os.path.abspath(sys.argv[1])
sys.argv = [scene]
runpy.run_path(scene, run_name="__main__")
