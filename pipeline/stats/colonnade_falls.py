"""Where a colonnade's columns fell: the fall azimuths of its columns (beams left out)
over a campaign's runs, per group of runs (a record, or a direction of shaking), with
their circular mean and spread (:func:`pipeline.stats.circular.circular_summary`).
An ensemble's nominal run (member -1) is not a sample and is left out, as in
``colonnade_statistics.json``.  Azimuths in degrees clockwise from North, in [0, 360)."""
import math
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError, csv_true
from pipeline.stats.circular import circular_summary

NEEDED = ("run_id", "column", "toppled", "downfall_azimuth_deg")


@dataclass(frozen=True)
class FallDirections:
    """The columns of one ``group`` of ``runs`` runs: ``shaken`` columns shaken (columns
    times runs), ``azimuths_deg`` those of the columns that fell (deg, [0, 360)); the
    circular mean (deg, [0, 360)), Mardia's circular standard deviation (deg) and the mean
    resultant length of those, None without a fall (the mean also when R is 0)."""
    group: str
    runs: int
    shaken: int
    azimuths_deg: tuple

    def __post_init__(self):
        object.__setattr__(self, "azimuths_deg",
                           tuple(float(a) for a in self.azimuths_deg))
        if not all(0.0 <= a < 360.0 for a in self.azimuths_deg):
            raise InputError(f"{self.group}: fall azimuths must lie in [0, 360) deg")
        if not 0 <= len(self.azimuths_deg) <= self.shaken:
            raise InputError(f"{self.group}: {len(self.azimuths_deg)} falls of "
                             f"{self.shaken} columns shaken")

    @property
    def fallen(self):
        return len(self.azimuths_deg)

    def _summary(self):
        return circular_summary(self.azimuths_deg)

    @property
    def mean_deg(self):
        mean = self._summary()["mean_deg"]
        return None if not self.fallen or not math.isfinite(mean) else float(mean)

    @property
    def spread_deg(self):
        return None if not self.fallen else float(self._summary()["circular_std_deg"])

    @property
    def resultant_length(self):
        return None if not self.fallen else float(self._summary()["resultant_length"])


def wrapped_azimuths(azimuths_deg):
    """Azimuths (deg) wrapped into [0, 360) (numpy's mod gives 360 for a hair below 0)."""
    wrapped = np.mod(np.asarray(azimuths_deg, float), 360.0)
    return np.where(wrapped >= 360.0, 0.0, wrapped)


def fall_directions(runs, groups, columns):
    """A :class:`FallDirections` per group of ``groups`` ({run_id: group}, in the order
    of first appearance): the rows of ``runs`` (runs.csv's: run_id, column, toppled,
    downfall_azimuth_deg; an ensemble's with member) of the colonnade's ``columns``
    (names; beams are left out).  A fallen column without an azimuth is an InputError."""
    missing = [c for c in NEEDED if c not in runs.columns]
    if missing:
        raise InputError(f"runs table lacks column(s): {', '.join(missing)}")
    rows = runs[runs["column"].isin(list(columns)) & runs["run_id"].isin(list(groups))]
    if "member" in rows:
        rows = rows[rows["member"] >= 0]
    out = []
    for group in dict.fromkeys(groups[r] for r in dict.fromkeys(rows["run_id"])):
        sub = rows[rows["run_id"].map(groups) == group]
        fell = sub[[csv_true(v) for v in sub["toppled"]]]
        azimuths = fell["downfall_azimuth_deg"].to_numpy(float)
        if not np.isfinite(azimuths).all():
            raise InputError(f"{group}: a fallen column without a fall azimuth")
        out.append(FallDirections(str(group), int(sub["run_id"].nunique()), len(sub),
                                  tuple(wrapped_azimuths(azimuths))))
    return out
