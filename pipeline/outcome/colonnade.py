"""What a run says of a colonnade as a whole (:class:`ColonnadeOutcome`, ``summary.json``
``colonnade``): how many of its columns and beams fell, and whether the columns fell
parallel (the circular spread of their downfall azimuths)."""
import math
from dataclasses import dataclass

from pipeline.files import InputError
from pipeline.stats.circular import circular_summary

PARALLEL_SPREAD_DEG = 15.0    # columns whose azimuths spread less than this fell parallel


@dataclass(frozen=True, kw_only=True)
class ColonnadeOutcome:
    """A colonnade's run: its ``name``, the numbers of its columns and beams and of those
    that fell, the circular mean (deg clockwise from North) and circular standard
    deviation (deg, Mardia's sqrt(-2 ln R)) of the fallen columns' downfall azimuths
    (None for fewer than two), and whether they fell ``parallel`` (spread below
    PARALLEL_SPREAD_DEG; None for fewer than two)."""
    name: str
    columns: int
    columns_fallen: int
    beams: int
    beams_fallen: int
    fall_azimuth_mean_deg: float = None
    fall_azimuth_spread_deg: float = None
    parallel: bool = None

    def __post_init__(self):
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
        return cls(name=name, columns=len(columns), columns_fallen=len(fallen),
                   beams=len(beams), beams_fallen=sum(b.toppled for b in beams),
                   fall_azimuth_mean_deg=mean, fall_azimuth_spread_deg=spread,
                   parallel=parallel)
