"""The members' ranges: what a rock's members draw because no scan fixes it, declared once.

``campaign fragility`` (a mesh specimen's default ``--ranges``) and the members mode of
``campaign shake-table`` (its ``default`` candidate) both read :data:`MEMBER_RANGES`;
nothing else spells these numbers.  Each range says where it comes from
(docs/rock-fragility.md quotes the sources).  :data:`CHOSEN_BY` names the scoring that
chose the seating and stiffness ranges; a later scoring that chooses others changes
them here, and with them both campaigns' defaults.
"""
from dataclasses import dataclass
import math


@dataclass(frozen=True)
class MemberRange:
    """One drawn parameter: ``low``-``high`` in ``unit``, and where the range comes from."""
    name: str
    low: float
    high: float
    unit: str
    source: str

    def __post_init__(self):
        if not (math.isfinite(self.low) and math.isfinite(self.high)
                and self.low <= self.high):
            raise ValueError(f"member range {self.name}: need finite low <= high")
        if not self.source.strip():
            raise ValueError(f"member range {self.name}: its source must be stated")


CHOSEN_BY = ("make shake-table-scores, before the yaw was drawn: among four candidates "
             "(the earlier defaults footprint 1-3 mm and kn 4e7-1.2e8, kn 4e7-1.2e9, "
             "footprint 1-1.5 mm, both) by log-likelihood per test on SP1's June-July "
             "tests; on the August tests: accuracy 0.900, Brier 0.088")

MEMBER_RANGES = (
    MemberRange("kn", 4e7, 1.2e9, "N/m",
                "the contact stiffness of the asperities is not measured: chosen by the "
                "shake-table scoring (make shake-table-scores) over 4e7-1.2e8; the "
                "stiffness check (make contact-convergence) changes a few predictions up "
                "to 1.2e9"),
    MemberRange("damping", 0.05, 0.1, "",
                "the shake-table calibration grid's two values, which scored alike"),
    MemberRange("mu_s", 0.6, 0.8, "",
                "dry rock on rock 0.6-0.85 (Byerlee 1978, PAGEOPH 116); the calibration "
                "chose 0.7 over the providers' PyBullet 0.3 at every footprint"),
    MemberRange("footprint_tolerance_m", 0.001, 0.0015, "m",
                "the seating, which asperities of the scanned base touch: chosen by the "
                "shake-table scoring (make shake-table-scores) over 1-3 mm"),
    MemberRange("yaw_deg", -10.0, 10.0, "deg",
                "the rock's turn about the vertical from its stated orientation: the "
                "providers give SP1's orientation on the table only through their "
                "simulation (scan x = table axis: records/shake_table/README.md, 'Table "
                "axis'; 'only known through this simulation setup': "
                "records/tools/derive_shake_table.py), with no tolerance, and the rock "
                "was put back on the table after each overturn "
                "(145 of the 259 June-July tests with a motion); +-10 deg is an "
                "assumption for that placement, not a measurement"),
)
ORDER = tuple(r.name for r in MEMBER_RANGES)


def number_text(value):
    """A value as the ranges' text spells it: 0.001, 4e7, 1.2e8, -10."""
    return f"{value:g}".replace("e+0", "e").replace("e+", "e")


def ranges_text(ranges=MEMBER_RANGES):
    """The ranges as ``--ranges`` spells them (``name=LO:HI;...``)."""
    return ";".join(f"{r.name}={number_text(r.low)}:{number_text(r.high)}" for r in ranges)


def by_name(ranges=MEMBER_RANGES):
    """{name: (low, high)} of the declared ranges."""
    return {r.name: (r.low, r.high) for r in ranges}
