"""A specimen's age as it is dated (:class:`AgeModel`), and survival over it.

Overturnings at an annual rate r are a Poisson process: a specimen of age t survives with
exp(-r t); of an uncertain age T, with E[exp(-r T)] over T's distribution.  Four kinds
(:class:`AgeKind`), each with that expectation in closed form where one exists (ages in
years, rates in 1/yr):

- :class:`LowerBound` (">10.5 ka"): only T >= a is known; exp(-r a), the most the
  specimen can have survived (an upper bound on survival, a lower bound on nothing else);
- :class:`UniformInterval` (13-22 ka from deglaciation): T uniform on [a, b];
  (exp(-r a) - exp(-r b)) / (r (b - a));
- :class:`AgeSamples` (samples of an exposure age's distribution, a column of a file):
  the mean of exp(-r t_k) over the samples;
- :class:`TruncatedNormal` (mean, sd): normal truncated at 0;
  exp(-r mu + r^2 s^2 / 2) Phi((mu - r s^2) / s) / Phi(mu / s).
"""
import csv
import io
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, fields
from enum import Enum

import numpy as np
from scipy import stats

from pipeline.files import InputError
from pipeline.hazard.record import ABSENT, Record
from pipeline.hazard.survival import survival_probability
from pipeline.userfiles import DATA_FILE_BYTES, read_user_text, show

MAX_AGE_YR = 1e8               # older than any rock at the surface is a typo
MAX_SAMPLES = 10_000_000


class AgeKind(Enum):
    """How an age is dated."""
    LOWER_BOUND = "lower_bound"
    INTERVAL = "interval"
    SAMPLES = "samples"
    NORMAL = "normal"


def _check_age(value, what):
    if not (isinstance(value, int | float) and not isinstance(value, bool)
            and math.isfinite(value)
            and 0 <= value <= MAX_AGE_YR):
        raise InputError(f"{what} must be 0 to {MAX_AGE_YR:g} years, got {show(value)}")


@dataclass(frozen=True, kw_only=True)
class AgeDescription(Record):
    """An age as results describe it (survival.json's and constrain.json's ``age``): its
    kind, the values of that kind (years; samples: their count, where they come from and
    their mean, least and greatest) and what survival over it means."""
    kind: AgeKind
    samples: int = ABSENT
    source: str | None = ABSENT
    mean_yr: float = ABSENT
    sd_yr: float = ABSENT
    min_yr: float = ABSENT
    max_yr: float = ABSENT
    lo_yr: float = ABSENT
    hi_yr: float = ABSENT
    survival: str
    NAME = "age"
    PARTS = {"kind": AgeKind}
    VALUES = {AgeKind.LOWER_BOUND: ("min_yr",), AgeKind.INTERVAL: ("lo_yr", "hi_yr"),
              AgeKind.SAMPLES: ("samples", "source", "mean_yr", "min_yr", "max_yr"),
              AgeKind.NORMAL: ("mean_yr", "sd_yr")}

    def __post_init__(self):
        if not isinstance(self.kind, AgeKind):
            raise ValueError(f"kind {self.kind!r} is not one of "
                             f"{', '.join(k.value for k in AgeKind)}")
        given = tuple(f.name for f in fields(self)[1:-1] if getattr(self, f.name) is not ABSENT)
        if given != self.VALUES[self.kind]:
            raise ValueError(f"an age of kind {self.kind.value} holds "
                             f"{', '.join(self.VALUES[self.kind])}, not {', '.join(given)}")


class AgeModel(ABC):
    """A specimen's age (years) as dated; ``kind`` says which."""
    kind: AgeKind

    @abstractmethod
    def survival(self, rate_per_yr):
        """E[exp(-rate T)] over the age T; ``rate_per_yr`` (1/yr) may be an array."""

    @abstractmethod
    def describe(self):
        """The age as results describe it (:class:`AgeDescription`)."""

    @property
    def fixed_yr(self):
        """The age (years) when survival is exp(-rate age) exactly, else None."""
        return None

    @property
    @abstractmethod
    def typical_yr(self):
        """A representative age (years, above 0 unless the age is 0): the mean, the bound."""

    @property
    def band_yr(self):
        """(low, high, what it is) of the age to shade in a figure, or None."""
        return None

    @abstractmethod
    def draw(self, n, rng):
        """``n`` ages (years) drawn from the age's distribution (``rng`` a numpy
        Generator), for a Monte Carlo over several specimens' ages."""


@dataclass(frozen=True)
class LowerBound(AgeModel):
    """Only ``min_yr`` <= T is known: survival exp(-r min_yr), an upper bound."""
    min_yr: float
    kind = AgeKind.LOWER_BOUND

    def __post_init__(self):
        _check_age(self.min_yr, "a lower bound on the age")

    def survival(self, rate_per_yr):
        return np.exp(-np.asarray(rate_per_yr, float) * self.min_yr)

    @property
    def fixed_yr(self):
        return self.min_yr

    @property
    def typical_yr(self):
        return self.min_yr

    def draw(self, n, rng):
        """The bound itself: survival's upper bound, as :meth:`survival` gives it."""
        return np.full(n, float(self.min_yr))

    def describe(self):
        return AgeDescription(kind=self.kind, min_yr=self.min_yr, survival="exp(-rate min): "
                              "an upper bound (the age is at least min)")


@dataclass(frozen=True)
class UniformInterval(AgeModel):
    """T uniform on [``lo_yr``, ``hi_yr``] (equal ends: a known age)."""
    lo_yr: float
    hi_yr: float
    kind = AgeKind.INTERVAL

    def __post_init__(self):
        _check_age(self.lo_yr, "the age interval's lower end")
        _check_age(self.hi_yr, "the age interval's upper end")
        if self.hi_yr < self.lo_yr:
            raise InputError(f"age interval upside down: {self.lo_yr:g} to {self.hi_yr:g} "
                             "years (the lower end first)")

    def survival(self, rate_per_yr):
        rate = np.asarray(rate_per_yr, float)
        x = rate * (self.hi_yr - self.lo_yr)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(x > 0, -np.expm1(-x) / np.where(x > 0, x, 1.0), 1.0)
        return np.exp(-rate * self.lo_yr) * mean

    @property
    def fixed_yr(self):
        return self.lo_yr if self.lo_yr == self.hi_yr else None

    @property
    def typical_yr(self):
        return 0.5 * (self.lo_yr + self.hi_yr)

    @property
    def band_yr(self):
        return None if self.lo_yr == self.hi_yr else (self.lo_yr, self.hi_yr, "age interval")

    def draw(self, n, rng):
        return rng.uniform(self.lo_yr, self.hi_yr, n)

    def describe(self):
        return AgeDescription(kind=self.kind, lo_yr=self.lo_yr, hi_yr=self.hi_yr,
                              survival="(exp(-rate lo) - exp(-rate hi)) / (rate (hi - lo)): "
                              "the age uniform on [lo, hi]")


@dataclass(frozen=True)
class AgeSamples(AgeModel):
    """Samples of the age's distribution (``ages_yr``, years): survival is their mean
    of exp(-r t); ``source`` names where they come from."""
    ages_yr: tuple
    source: str = ""
    kind = AgeKind.SAMPLES

    def __post_init__(self):
        if not self.ages_yr:
            raise InputError(f"no age samples{' in ' + self.source if self.source else ''}")
        for k, age in enumerate(self.ages_yr):
            _check_age(age, f"age sample {k + 1}{' of ' + self.source if self.source else ''}")

    def survival(self, rate_per_yr):
        rate = np.asarray(rate_per_yr, float)
        ages = np.asarray(self.ages_yr, float)
        return np.exp(-rate[..., None] * ages).mean(axis=-1)

    @property
    def typical_yr(self):
        return float(np.mean(self.ages_yr))

    @property
    def band_yr(self):
        lo, hi = np.percentile(np.asarray(self.ages_yr, float), [2.5, 97.5])
        return None if lo == hi else (float(lo), float(hi), "age samples, 95 %")

    def draw(self, n, rng):
        """The samples drawn with replacement."""
        return rng.choice(np.asarray(self.ages_yr, float), n, replace=True)

    def describe(self):
        ages = np.asarray(self.ages_yr, float)
        return AgeDescription(kind=self.kind, samples=len(ages), source=self.source,
                              mean_yr=float(ages.mean()), min_yr=float(ages.min()),
                              max_yr=float(ages.max()),
                              survival="the mean of exp(-rate t) over the samples")


@dataclass(frozen=True)
class TruncatedNormal(AgeModel):
    """T normal (``mean_yr``, ``sd_yr``) truncated at 0 (sd 0: a known age)."""
    mean_yr: float
    sd_yr: float = 0.0
    kind = AgeKind.NORMAL

    def __post_init__(self):
        _check_age(self.mean_yr, "the age's mean")
        _check_age(self.sd_yr, "the age's sd")
        if self.sd_yr > 0 and self.mean_yr == 0:
            raise InputError("an age of mean 0 with a spread: give a positive mean")

    def survival(self, rate_per_yr):
        """In closed form, without a difference of huge numbers
        (:func:`pipeline.hazard.survival.survival_probability`)."""
        return survival_probability(rate_per_yr, self.mean_yr, self.sd_yr)

    @property
    def fixed_yr(self):
        return self.mean_yr if self.sd_yr == 0 else None

    @property
    def typical_yr(self):
        return self.mean_yr

    @property
    def band_yr(self):
        if self.sd_yr == 0:
            return None
        return (self.mean_yr - self.sd_yr, self.mean_yr + self.sd_yr, "age $\\pm$ 1 sd")

    def draw(self, n, rng):
        if self.sd_yr == 0:
            return np.full(n, float(self.mean_yr))
        return stats.truncnorm.rvs(-self.mean_yr / self.sd_yr, np.inf, loc=self.mean_yr,
                                   scale=self.sd_yr, size=n, random_state=rng)

    def describe(self):
        return AgeDescription(kind=self.kind, mean_yr=self.mean_yr, sd_yr=self.sd_yr,
                              survival="E[exp(-rate T)], T normal truncated at 0 (closed "
                              "form)")


def load_age_samples(path, column=None, scale_to_yr=1.0):
    """:class:`AgeSamples` from the column named ``column`` of the CSV file ``path`` (a
    header line, comment lines starting with ``#``; ``column`` None: the file's only
    column); ``scale_to_yr`` converts the column's unit to years (1000 for ka).  Every
    row must hold a number there."""
    text = read_user_text(path, "age samples file", DATA_FILE_BYTES)
    lines = [line for line in text.splitlines() if line.strip()
             and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"age samples file {path} is empty")
    rows = csv.reader(io.StringIO("\n".join(lines)))
    header = [h.strip() for h in next(rows)]
    if column is None and len(header) != 1:
        raise InputError(f"{path}: {len(header)} columns ({', '.join(map(show, header))}): "
                         "name the one holding the ages (--age-column)")
    column = header[0] if column is None else column
    if column not in header:
        raise InputError(f"{path}: no column {show(column)} (has "
                         f"{', '.join(map(show, header))})")
    k = header.index(column)
    ages = []
    for n, row in enumerate(rows, start=2):
        if len(ages) >= MAX_SAMPLES:
            raise InputError(f"{path}: more than {MAX_SAMPLES} samples")
        cell = row[k].strip() if k < len(row) else ""
        try:
            ages.append(float(cell) * scale_to_yr)
        except ValueError:
            raise InputError(f"{path}: data row {n - 1}, column {column}: not a number: "
                             f"{show(cell)}") from None
    return AgeSamples(tuple(ages), f"{path}, column {column}")
