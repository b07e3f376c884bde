"""Shared fixtures: the Agg backend, analytic pulse motions, hand-built trajectories."""
import math
import os
import signal
import tempfile
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")
# Hypothesis keeps its example database and caches out of the source tree.
os.environ.setdefault("HYPOTHESIS_STORAGE_DIRECTORY",
                      str(Path(tempfile.gettempdir()) / "toppling-columns-hypothesis"))

from pipeline.motion import Motion  # noqa: E402
from pipeline.motion.pulses import one_sine_pulse  # noqa: E402
from pipeline.outcome import Trajectory  # noqa: E402


def pytest_addoption(parser):
    parser.addoption("--second-libm", action="store_true",
                     help="YADE processes use glibc's other libm routines "
                     "(pipeline.scenario.runner.SECOND_LIBM_TUNABLES): a second CPU's last bits")


def pytest_configure(config):
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        # started in the background (nohup, `make test &`): the Ctrl-C tests' commands
        # would inherit the ignored SIGINT and never see it
        signal.signal(signal.SIGINT, signal.default_int_handler)
    # the stages' messages printed as the command line prints them (tests of a library
    # function read them with capsys)
    from pipeline.cli import setup_logging
    setup_logging()
    if config.getoption("--second-libm"):
        from pipeline.scenario.runner import SECOND_LIBM_TUNABLES
        os.environ["GLIBC_TUNABLES"] = SECOND_LIBM_TUNABLES


def lying_trajectory(azimuth_deg, n_drums=1, radius=0.29, height=3.5, fall_at=1.0):
    """Hand-built trajectory: a column standing at (1.5, 0) that lies flat toward
    azimuth_deg from fall_at on (bodies along the fall line, centres at height r)."""
    t = np.linspace(0, 2, 201)
    h = height / n_drums
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0])
    tilt_axis = np.cross([0, 0, 1], u)
    down = Rotation.from_rotvec(tilt_axis * math.pi / 2)
    pos = np.zeros((len(t), n_drums, 3))
    quat = np.zeros((len(t), n_drums, 4))
    origin = np.array([1.5, 0.0, 0.0])
    for k in range(n_drums):
        standing = origin + [0, 0, (k + 0.5) * h]
        lying = origin + u * (k + 0.5) * h + [0, 0, radius]
        fallen = t >= fall_at
        pos[:, k] = np.where(fallen[:, None], lying, standing)
        q = down.as_quat()  # x, y, z, w
        quat[:, k] = np.where(fallen[:, None], [q[3], q[0], q[1], q[2]], [1, 0, 0, 0])
    bodies = [{"shape": "cylinder", "column": "drums" if n_drums > 1 else "monolithic",
               "index": k, "height": h, "radius": radius, "mass": 100.0,
               "initial_pos": list(origin + [0, 0, (k + 0.5) * h])} for k in range(n_drums)]
    return Trajectory(t=t, pos=pos, quat=quat, bodies=bodies, dt=1e-4, motion_end=1.0,
                      stopped_early=True)


@pytest.fixture
def make_lying_trajectory():
    return lying_trajectory


@pytest.fixture
def pulse():
    """one_sine_pulse(azimuth_deg, amplitude, period, duration, dt) -> Motion."""
    return one_sine_pulse


def still_motion(n=101, dt=0.01):
    """A motion at rest (zeros), n samples."""
    zeros = np.zeros((n, 3))
    return Motion(dt, zeros, zeros, zeros, meta={"record_id": "still"})


@pytest.fixture
def make_still_motion():
    return still_motion


def make_runs_table(n=8):
    """A hand-made runs table: falls scattered around 60 deg, back azimuth 240 deg."""
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


@pytest.fixture
def runs_table():
    return make_runs_table
