"""What a run says of a colonnade as a whole (:class:`ColonnadeOutcome`, ``summary.json``
``colonnade``): how many of its columns and beams fell, and whether the columns fell
parallel (the circular spread of their downfall azimuths)."""
import math
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError
from pipeline.stats.circular import circular_summary

PARALLEL_SPREAD_DEG = 15.0    # columns whose azimuths spread less than this fell parallel


@dataclass(frozen=True, kw_only=True)
class ColonnadeOutcome:
    """A colonnade's run: its ``name``, the numbers of its columns and beams and of those
    that fell, the circular mean (deg clockwise from North) and circular standard
    deviation (deg, Mardia's sqrt(-2 ln R)) of the fallen columns' downfall azimuths
    (None for fewer than two), whether they fell ``parallel`` (spread below
    PARALLEL_SPREAD_DEG; None for fewer than two), the fallen columns by first impact
    (``fall_order``) and whether they fell ``in_sequence``, one after the other along the
    row like dominoes (their places along the row in the order of their impacts only
    rising or only falling; None for fewer than three)."""
    name: str
    columns: int
    columns_fallen: int
    beams: int
    beams_fallen: int
    fall_azimuth_mean_deg: float = None
    fall_azimuth_spread_deg: float = None
    parallel: bool = None
    fall_order: tuple = ()
    in_sequence: bool = None

    def __post_init__(self):
        object.__setattr__(self, "fall_order", tuple(self.fall_order))
        for key in ("columns", "columns_fallen", "beams", "beams_fallen"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InputError(f"colonnade outcome: {key} must be a count, got {value!r}")
        if self.columns_fallen > self.columns or self.beams_fallen > self.beams:
            raise InputError("colonnade outcome: more fallen than there are")

    @classmethod
    def of(cls, name, columns, beams):
        """The outcome of colonnade ``name`` from its columns' and beams'
        :class:`~pipeline.outcome.summary.ColumnOutcome`."""
        fallen = [c for c in columns if c.toppled]
        azimuths = [c.downfall_azimuth_deg for c in fallen
                    if c.downfall_azimuth_deg is not None]
        mean = spread = parallel = None
        if len(azimuths) >= 2:
            stats = circular_summary(azimuths)
            spread = float(stats["circular_std_deg"])
            mean = None if math.isnan(stats["mean_deg"]) else float(stats["mean_deg"])
            parallel = bool(spread < PARALLEL_SPREAD_DEG)
        timed = sorted((c for c in fallen if c.impact_time_s is not None),
                       key=lambda c: c.impact_time_s)
        in_sequence = None
        if len(timed) >= 3:
            along = _along_row([c.position_m for c in columns], [c.position_m for c in timed])
            steps = [b - a for a, b in zip(along, along[1:])]
            in_sequence = all(d > 0 for d in steps) or all(d < 0 for d in steps)
        return cls(name=name, columns=len(columns), columns_fallen=len(fallen),
                   beams=len(beams), beams_fallen=sum(b.toppled for b in beams),
                   fall_azimuth_mean_deg=mean, fall_azimuth_spread_deg=spread,
                   parallel=parallel, fall_order=tuple(c.column for c in timed),
                   in_sequence=in_sequence)


def _along_row(row, points):
    """Places (m) of ``points`` (x, y) along the row through ``row``'s positions (its
    principal direction)."""
    row = np.asarray(row, float)
    centre = row.mean(axis=0)
    _, _, axes = np.linalg.svd(row - centre)
    return list((np.asarray(points, float) - centre) @ axes[0])
