"""The correlation of ln PGA and ln PGV residuals, named by where each value comes from.

- :data:`BAKER_BRADLEY_2017` (0.654): observed in the NGA-West2 residuals, Baker &
  Bradley (2017), Earthquake Spectra 33(1), 145-156, with the data corrected in 2021-2022
  (Z1.0 and region values; corrigendum, Earthquake Spectra 41(2), 2025; the analysis at
  GitHub ``bakerjw/NGAW2_correlations``); the value OpenQuake's ``BakerBradley2017``
  correlation model (its table of the corrected data) gives for PGA and PGV.
- :data:`BRADLEY_2012` (0.733): Bradley (2012), "Empirical correlations between peak
  ground velocity and spectrum-based intensity measures", Earthquake Spectra 28(1),
  17-35: his model's prediction for PGV and SA at periods below 0.01 s (PGA); OpenQuake's
  ``Bradley2012`` returns it.

With 0.654 the spread of ln PGV given ln PGA, sigma_v sqrt(1 - rho^2), is
sqrt(1 - 0.654^2) / sqrt(1 - 0.733^2) = 1.11 times that with 0.733.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class NamedCorrelation:
    """A correlation ``value`` (-1 to 1) with its ``name`` and ``source``."""
    value: float
    name: str
    source: str

    def __post_init__(self):
        if not -1.0 <= self.value <= 1.0:
            raise ValueError(f"a correlation lies in [-1, 1], got {self.value}")

    def describe(self):
        return {"pga_pgv_correlation": self.value, "name": self.name, "source": self.source}


BAKER_BRADLEY_2017 = NamedCorrelation(
    0.654, "baker-bradley-2017",
    "observed: NGA-West2 residuals, Baker & Bradley (2017), Earthq. Spectra 33(1), data "
    "corrected 2021-2022 (bakerjw/NGAW2_correlations); OpenQuake BakerBradley2017")
BRADLEY_2012 = NamedCorrelation(
    0.733, "bradley-2012",
    "predicted: Bradley (2012), Earthq. Spectra 28(1) 17-35, PGV with SA(T < 0.01 s); "
    "OpenQuake Bradley2012")
BY_NAME = {c.name: c for c in (BAKER_BRADLEY_2017, BRADLEY_2012)}


def correlation_source(value):
    """Where the correlation ``value`` comes from, in words: a named correlation's source,
    or that neither gives it (the user's own)."""
    named = [c for c in BY_NAME.values() if c.value == value]
    if named:
        return named[0].source
    return (f"given: neither {BAKER_BRADLEY_2017.value:g} (observed, Baker & Bradley 2017) "
            f"nor {BRADLEY_2012.value:g} (predicted, Bradley 2012)")
