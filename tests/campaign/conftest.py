"""Fixtures shared by the campaign tests."""
import pytest

from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse


@pytest.fixture(scope="module")
def pulse_file(tmp_path_factory):
    """A processed-motion file (str path): a one-sine pulse toward N30E, 3 m/s^2, 4 s,
    back azimuth 120 deg."""
    path = tmp_path_factory.mktemp("motion") / "pulse.npz"
    m = one_sine_pulse(30.0, 3.0, duration=4.0)
    Motion(m.dt, m.acc, m.vel, m.disp,
           meta={"record_id": "pulse", "back_azimuth_deg": 120.0}).save(path)
    return str(path)
