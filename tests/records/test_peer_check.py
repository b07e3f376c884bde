"""Processed peaks against PEER's own values (pipeline.records.peer_check)."""
import math

import numpy as np
import pytest

from pipeline.records import peer_check, processed_motion


def test_rotd50_of_analytic_motions():
    t = np.linspace(0.0, 10.0, 10001)
    circle = np.column_stack([np.cos(t), np.sin(t), 0 * t])       # every direction peaks at 1
    assert peer_check.rotd50(circle) == pytest.approx(1.0, abs=1e-4)
    a = math.radians(30.0)
    line = np.column_stack([np.sin(a) * np.sin(t), np.cos(a) * np.sin(t), 0 * t])
    # peak along angle b is |cos(b - 60 deg)|: the median over [0, 180) is cos(45 deg)
    assert peer_check.rotd50(line) == pytest.approx(math.cos(math.radians(45.0)), abs=0.01)


@pytest.mark.parametrize("record_id", ["NF04", "GM20"])
def test_processing_keeps_the_peaks_of_peer_pulse_records(record_id):
    """PEER's records are processed already: on FEMA P695's pulse-like records ours keeps
    their RotD50 PGA within 3 % and PGV within 10 %."""
    motion, _ = processed_motion(record_id, cache_dir=None)
    given, _ = processed_motion(record_id, cache_dir=None, mode="none")
    row = peer_check.peer_row(record_id, motion, given)
    assert row["pulse_like"] is True
    assert row["pga_ratio_given"] == pytest.approx(1.0, abs=0.03)
    assert row["pgv_ratio_given"] == pytest.approx(1.0, abs=0.10)


def test_nga_west2_records_carry_the_flatfile_values():
    motion, _ = processed_motion("RSN126-GAZLI", cache_dir=None)
    ref = motion.meta["peer_reference"]
    assert ref["measure"] == "RotD50" and ref["rsn"] == 126
    assert ref["pga_ms2"] == pytest.approx(0.70178 * 9.80665, rel=1e-3)   # flatfile PGA(g)
