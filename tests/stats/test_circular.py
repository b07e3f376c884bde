"""Circular statistics against hand-computed values and imposed alignments."""
import math

import numpy as np
import pytest

from pipeline.stats import circular


def test_circular_mean_wraps_through_north():
    s = circular.circular_summary([350.0, 10.0])
    assert min(s["mean_deg"], 360 - s["mean_deg"]) == pytest.approx(0.0, abs=1e-9)
    assert s["resultant_length"] == pytest.approx(math.cos(math.radians(10)))


def test_a_mean_a_hair_west_of_north_is_0_not_360():
    # symmetric about North: the mean comes out a rounding error below 0 deg
    mean = circular.circular_summary([355.0, 5.0, 340.0, 20.0])["mean_deg"]
    assert 0.0 <= mean < 360.0 and min(mean, 360.0 - mean) < 1e-9
    axial = circular.circular_summary([175.0, 5.0], axial=True)["mean_deg"]
    assert 0.0 <= axial < 180.0 and min(axial, 180.0 - axial) < 1e-9


def test_axial_mean_ignores_sense():
    s = circular.circular_summary([10.0, 190.0], axial=True)
    assert s["mean_deg"] == pytest.approx(10.0)
    assert s["resultant_length"] == pytest.approx(1.0)
    # the same two directions as vectors cancel
    assert circular.circular_summary([10.0, 190.0])["resultant_length"] == pytest.approx(0, abs=1e-12)


def test_rayleigh_separates_concentrated_from_uniform():
    rng = np.random.default_rng(3)
    assert circular.circular_summary(rng.normal(40, 10, 30))["rayleigh_p"] < 1e-6
    assert circular.circular_summary(np.arange(0, 360, 12.0))["rayleigh_p"] > 0.5


def test_angle_difference_wraps():
    assert circular.angle_difference_deg(10, 350) == pytest.approx(20)
    assert circular.angle_difference_deg(350, 10) == pytest.approx(-20)
    assert circular.angle_difference_deg(0, 180) == pytest.approx(180)


def test_correlation_of_rotated_copy_is_one():
    rng = np.random.default_rng(1)
    a = rng.uniform(0, 360, 40)
    assert circular.circular_correlation(a, (a + 75) % 360) == pytest.approx(1.0)


def test_direction_statistics_sees_the_imposed_alignment(runs_table):
    stats = circular.direction_statistics(runs_table(30))
    row = stats[(stats["column"] == "drums") & (stats["record_id"] == "all")
                & (stats["reference"] == "back_azimuth")].iloc[0]
    # falls scattered around 60 deg, back azimuth 240: directionally opposite, axially aligned
    assert abs(row["mean_difference_deg"]) == pytest.approx(180, abs=15)
    assert abs(row["axial_mean_difference_deg"]) < 15




def test_azimuth_of_a_vector_clockwise_from_north():
    from pipeline.stats.circular import azimuth_deg
    assert azimuth_deg(0.0, 1.0) == 0.0 and azimuth_deg(1.0, 0.0) == 90.0
    assert azimuth_deg(0.0, -2.0) == 180.0 and azimuth_deg(-1.0, 0.0) == 270.0
    assert np.allclose(azimuth_deg(np.array([1.0, -1.0]), np.array([1.0, 1.0])), [45.0, 315.0])
