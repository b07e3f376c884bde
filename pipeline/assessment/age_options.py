"""The checks of the age options of ``survival`` and ``constrain`` (declared in
:mod:`pipeline.assessment.options`): one kind of age, its companions, an interval the
right way up; and ``constrain --age KIND:VALUES``, each specimen's age of its own kind
(:class:`StatedAge`)."""
import math
from dataclasses import dataclass
from pathlib import Path

from pipeline.files import InputError
from pipeline.hazard.ages import (AgeKind, LowerBound, TruncatedNormal, UniformInterval,
                                  load_age_samples)
from pipeline.userfiles import show

AGE_VALUES = {"--age-ka": lambda o: ("--age-ka", o.age_ka),
               "--age-min-ka": lambda o: ("--age-min-ka", o.age_min_ka),
               "--age-range-ka": lambda o: ("--age-range-ka", o.age_range_ka),
               "--age-samples": lambda o: ("--age-samples", o.age_samples)}
KA = 1000.0                 # years in a thousand years
AGE_FORMS = {AgeKind.LOWER_BOUND: "lower_bound:MIN", AgeKind.INTERVAL: "interval:LO,HI",
             AgeKind.NORMAL: "normal:MEAN[,SD]", AgeKind.SAMPLES: "samples:FILE"}


def age_kinds(options):
    """The age flags given (one kind of age is asked for)."""
    return [flag for flag, value in (("--age-ka", options.age_ka),
                                     ("--age-min-ka", options.age_min_ka),
                                     ("--age-range-ka", options.age_range_ka),
                                     ("--age-samples", options.age_samples))
            if value is not None and value != ()]


def check_age_kinds(options, given, several=""):
    """One kind of age (``several``: how to give ages of several kinds, if any);
    --age-sd-ka with --age-ka only, --age-column with --age-samples; an interval the right
    way up."""
    if len(given) > 1:
        raise InputError(f"give one kind of age: {' or '.join(given)}, not both{several}")
    sd = options.age_sd_ka
    if "--age-ka" not in given and sd not in (0.0, (0.0,)):
        raise InputError("--age-sd-ka applies with --age-ka")
    if given != ["--age-samples"] and options.age_column is not None:
        raise InputError("--age-column applies with --age-samples")
    ranges = options.age_range_ka
    for lo, hi in ([ranges] if ranges and not isinstance(ranges[0], tuple) else ranges or ()):
        if hi < lo:
            raise InputError(f"--age-range-ka {lo:g} {hi:g}: the interval is upside down "
                             "(the lower end first)")
        if hi == 0:
            raise InputError("--age-range-ka 0 0: an age of 0 (the upper end above 0)")


@dataclass(frozen=True)
class StatedAge:
    """One specimen's age as ``--age`` states it: its kind and its values (ka), or the
    file of its samples; every value checked on construction (largest ``max_ka``)."""
    kind: AgeKind
    values_ka: tuple[float, ...] = ()
    file: Path | None = None
    max_ka: float = math.inf

    def __post_init__(self):
        text = f"--age {self.text()}"
        counts = {AgeKind.LOWER_BOUND: (1,), AgeKind.INTERVAL: (2,), AgeKind.NORMAL: (1, 2),
                  AgeKind.SAMPLES: (0,)}[self.kind]
        if len(self.values_ka) not in counts:
            raise InputError(f"{text}: expected {AGE_FORMS[self.kind]} (ka)")
        for k, value in enumerate(self.values_ka):
            least_open = not ((self.kind is AgeKind.INTERVAL and k == 0)
                              or (self.kind is AgeKind.NORMAL and k == 1))
            if not (math.isfinite(value) and (value > 0 if least_open else value >= 0)
                    and value <= self.max_ka):
                raise InputError(f"{text}: {value:g} ka outside "
                                 f"{'(' if least_open else '['}0, {self.max_ka:g}] ka")
        if self.kind is AgeKind.INTERVAL and self.values_ka[1] < self.values_ka[0]:
            raise InputError(f"{text}: the interval is upside down (the lower end first)")

    @classmethod
    def parse(cls, text, max_ka):
        """``KIND:VALUES`` (``lower_bound:10.5``, ``interval:13,22``, ``normal:15,3``,
        ``samples:FILE``; ka) as a StatedAge; InputError in one line."""
        kind, sep, rest = text.partition(":")
        known = {k.value: k for k in AgeKind}
        if not sep or kind.strip() not in known:
            raise InputError(f"--age {show(text)}: expected KIND:VALUES, the kind one of "
                             f"{', '.join(AGE_FORMS.values())} (ka)")
        kind = known[kind.strip()]
        if kind is AgeKind.SAMPLES:
            if not rest.strip():
                raise InputError(f"--age {show(text)}: expected {AGE_FORMS[kind]}")
            return cls(kind, file=Path(rest.strip()), max_ka=max_ka)
        try:
            values = tuple(float(v) for v in rest.split(","))
        except ValueError:
            raise InputError(f"--age {show(text)}: expected {AGE_FORMS[kind]}, numbers in "
                             "ka") from None
        return cls(kind, values, max_ka=max_ka)

    def text(self):
        """The age as ``--age`` gives it."""
        if self.file is not None:
            return f"{self.kind.value}:{self.file}"
        return f"{self.kind.value}:{','.join(f'{v:g}' for v in self.values_ka)}"

    def model(self, column=None):
        """The :class:`~pipeline.hazard.ages.AgeModel` (years); a samples file read here
        (its ``column``, or its only one)."""
        years = [v * KA for v in self.values_ka]
        if self.kind is AgeKind.LOWER_BOUND:
            return LowerBound(years[0])
        if self.kind is AgeKind.INTERVAL:
            return UniformInterval(*years)
        if self.kind is AgeKind.NORMAL:
            return TruncatedNormal(*years)
        return load_age_samples(self.file, column, KA)
