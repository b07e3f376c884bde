"""Symmetry of a colonnade in YADE: turning the motion and the colonnade together by a
quarter turn turns the falls of the whole colonnade by it.

The two scenes are one scene turned: square box columns (their rims at the corners),
their positions and the stylobate turned by 90 deg clockwise about the origin, the beam
following its capitals, and the pedestal a square about the origin.  So every column
that falls in one falls in the other, a quarter turn further clockwise.  The pulse is
oblique to the row and far above the frame's overturning amplitude, so the falls are
decided by the motion, not by the last bits of a near-threshold run: the azimuths are
compared within a physical tolerance."""
import dataclasses
import math

import pytest

from pipeline.constants import MODEL_GRAVITY as G
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.scenario.colonnade import Colonnade, Stylobate
from pipeline.verification.frame import frame_colonnade, run_frame

pytestmark = [pytest.mark.yade, pytest.mark.libm]

AZIMUTH_DEG = 60.0          # the pulse, oblique to the row (which runs East)
TURN_DEG = 90.0             # clockwise: East goes South
AZIMUTH_TOLERANCE_DEG = 3.0
PGA_G, PERIOD_S = 2.0, 2.0  # a one-cosine pulse far above the frame's overturning one


def turned(colonnade):
    """``colonnade`` turned by 90 deg clockwise seen from above about the origin:
    (x, y) -> (y, -x)."""
    def turn(point):
        x, y = point
        return (y, -x)
    s = colonnade.stylobate
    columns = tuple(dataclasses.replace(c, x=turn((c.x, c.y))[0], y=turn((c.x, c.y))[1])
                    for c in colonnade.columns)
    return Colonnade(f"{colonnade.name}-turned", Stylobate(turn(s.start), turn(s.end),
                                                           s.width),
                     columns, colonnade.epistyles, colonnade.frieze)


def _difference_deg(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def test_turning_motion_and_colonnade_turns_every_fall(tmp_path):
    colonnade = frame_colonnade(2, 1.0)            # square 1 x 1 x 3 m columns, one beam
    assert colonnade.columns[0].column.blocks[0].solid.width == \
        colonnade.columns[0].column.blocks[0].solid.depth      # a quarter turn maps it
    outcomes = []
    for name, layout, azimuth in (("plain", colonnade, AZIMUTH_DEG),
                                  ("turned", turned(colonnade), AZIMUTH_DEG + TURN_DEG)):
        motion = one_cosine_pulse(PGA_G * G, PERIOD_S / (2 * math.pi), azimuth,
                                  dt=0.001, tail_s=3.0)
        outcomes.append({o["column"]: o for o in run_frame(tmp_path / name, layout, motion,
                                                           motion.duration)})
    plain, turn = outcomes
    assert sorted(plain) == sorted(turn) == ["B", "C1", "C2"]
    assert all(plain[c]["toppled"] for c in ("C1", "C2"))      # the pulse topples them
    for name in plain:
        assert plain[name]["toppled"] == turn[name]["toppled"], name
        if plain[name]["toppled"]:
            assert _difference_deg(turn[name]["downfall_azimuth_deg"],
                                   plain[name]["downfall_azimuth_deg"] + TURN_DEG) \
                < AZIMUTH_TOLERANCE_DEG, name
