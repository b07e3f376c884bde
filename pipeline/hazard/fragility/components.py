"""PGA on the hazard curve's horizontal component: RotD50 against the campaigns' vector peak.

Hazard curves built on NGA-West2 ground-motion models (the USGS 2014 model; most
OpenQuake models) are in RotD50 PGA (Boore 2010: the median over rotation angles of
the peak of the rotated component).  ``campaign fragility`` states PGA as the peak of
the horizontal acceleration vector, which is RotD100 (the largest rotated peak).  A
fragility read against a hazard curve is put on the curve's measure:
P_hazard(x) = P_fragility(x / f), f = RotD50 / (vector peak) of the campaign's motions:

- a pulse grid: a one-cosine pulse along one line stands for the field motion along its
  strongest direction (the rock's heading is sampled, the motion's peak is not), so its
  PGA is the field motion's RotD100 and f = 1 / (RotD100 / RotD50) of Boore & Kishida
  (below).  A field motion that is itself along one line would have f = cos 45 deg
  (0.7071: the median over theta in [0, 180) of |cos theta|), the lowest any motion has;
  it is kept beside as ``polarised_fraction`` (the survival it gives is the lower bound);
- a campaign of scaled records: f of each record computed from its motion
  (:func:`pipeline.motion.measures.rotd_peak`), their geometric mean (scaling leaves f
  unchanged);
- where a record's motion cannot be read: the ratio RotD100 / RotD50 of PGA of Boore &
  Kishida (2017, BSSA 107(1)) for NGA-West2 records, ln ratio = c0 + r1 ln(R / 50 km)
  + m1 (M - 5.5) + m2 (M - 5.5)^2 (the smoothed PGA coefficients, as the USGS ShakeMap
  ships them), at the stated magnitude and distance, else at M 5.5, 50 km.

PGV/PGA is taken as the same on both measures (exact for a motion along one line; the
RotD100 / RotD50 ratios of PGA and PGV of Boore & Kishida differ by about 2 %).
"""
import math
from dataclasses import dataclass, replace

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.fragility.kinds import Fragility

COMPONENTS = ("rotd50", "rotd100")          # the hazard curve's PGA: RotD50 or vector peak
LINE_ROTD50_FRACTION = math.cos(math.pi / 4)
# Boore & Kishida (2017) RotD100 / RotD50 of PGA (NGA-West2, Rrup 0-400 km, M 2-9):
# the smoothed coefficients of USGS ShakeMap's
# nga-w2.lmR1M2_D100D50.4paper.RrupMin_0000.RrupMax_0400.Mmin_2.00.Mmax_9.00.csv, row PGA
BK17_PGA = {"c0": 0.185774509051029, "r1": -0.0111551267212533, "m1": -0.00435147917276275,
            "m2": -0.00145851835598356, "sigma": 0.083688638942042}


def bk17_rotd100_over_rotd50(magnitude=None, distance_km=None):
    """RotD100 / RotD50 of PGA after Boore & Kishida (2017) at M and Rrup (km); M 5.5 and
    50 km where not given (their reference), clipped to M 2-9, R 0.01-400 km."""
    m = 5.5 if magnitude is None else min(max(magnitude, 2.0), 9.0)
    r = 50.0 if distance_km is None else min(max(distance_km, 0.01), 400.0)
    c = BK17_PGA
    return math.exp(c["c0"] + c["r1"] * math.log(r / 50.0) + c["m1"] * (m - 5.5)
                    + c["m2"] * (m - 5.5) ** 2)


def records_fraction(records, fraction_of=None, magnitude=None, distance_km=None):
    """f = RotD50 / vector peak of PGA over ``records`` (ids of the project's records):
    ``fraction_of(record)`` computes a record's from its motion (e.g.
    :func:`pipeline.records.rotd50_fraction`); a record it cannot read (or without
    ``fraction_of``) takes the Boore & Kishida (2017) ratio.  Dict fraction (geometric
    mean over the records), per_record {id: f}, source."""
    per_record, missing = {}, []
    for record in records:
        try:
            if fraction_of is None:
                raise InputError("no motions")
            per_record[record] = float(fraction_of(record))
        except (InputError, OSError, KeyError, ValueError):
            missing.append(record)
    bk = 1.0 / bk17_rotd100_over_rotd50(magnitude, distance_km)
    values = list(per_record.values()) + [bk] * len(missing)
    if not values:
        values, missing = [bk], ["(none listed)"]
    parts = []
    if per_record:
        parts.append(f"RotD50 / RotD100 computed from the motion of {len(per_record)} "
                     "record(s) (0.5 deg steps)")
    if missing:
        parts.append(f"the Boore & Kishida (2017) ratio, f = {bk:.4f} (at M "
                     f"{5.5 if magnitude is None else magnitude:g}, "
                     f"{50 if distance_km is None else distance_km:g} km), for record(s) "
                     f"whose motion was not read: {', '.join(map(str, missing))}")
    return {"fraction": float(np.exp(np.mean(np.log(values)))), "per_record": per_record,
            "source": "; ".join(parts)}


@dataclass(frozen=True)
class OnHazardMeasure(Fragility):
    """A fragility (``inner``, a :class:`~pipeline.hazard.fragility.kinds.Fragility` over its
    own PGA) read on the hazard curve's PGA:
    P(x) = inner P(x / ``fraction``); ``measure``: what each PGA is and where the fraction
    comes from (said in the output)."""
    inner: Fragility
    fraction: float
    measure: dict

    @property
    def uses_ratio(self):
        return self.inner.uses_ratio

    @property
    def label(self):
        return self.inner.label

    def probability(self, pga_m_s2, pgv_pga_s=None):
        pga = np.asarray(pga_m_s2, float) / self.fraction
        if pgv_pga_s is None:
            return self.inner.probability(pga)
        return self.inner.probability(pga, pgv_pga_s)

    def stacks_with(self, other):
        return isinstance(other, OnHazardMeasure) and other.fraction == self.fraction and \
            self.inner.stacks_with(other.inner)

    def probability_stack(self, fragilities, pga_m_s2, pgv_pga_s=None):
        pga = np.asarray(pga_m_s2, float) / self.fraction
        return self.inner.probability_stack([f.inner for f in fragilities], pga, pgv_pga_s)

    def draws(self, n, rng):
        drawn = self.inner.draws(n, rng)
        return None if drawn is None else [replace(self, inner=d) for d in drawn]

    def members(self):
        inner = self.inner.members()
        return None if inner is None else [replace(self, inner=m) for m in inner]

    def variants(self):
        inner = self.inner.variants()
        return None if inner is None else {k: replace(self, inner=v) for k, v in inner.items()}

    def grid_range(self):
        inner = self.inner.grid_range()
        return None if inner is None else tuple(v * self.fraction for v in inner)

    def describe(self):
        return {**self.inner.describe(), "pga_measure": self.measure}


def on_hazard_measure(fragility, kind, component, records=(), fraction_of=None,
                      magnitude=None, distance_km=None):
    """``fragility`` (its PGA the horizontal vector peak) put on a hazard curve of
    ``component`` (rotd50 or rotd100): ``kind`` "line" (motions along one line: the pulse
    grid) or "records" (the campaign's ``records``, :func:`records_fraction`)."""
    if component not in COMPONENTS:
        raise InputError(f"--hazard-component must be one of {', '.join(COMPONENTS)}, got "
                         f"{component!r}")
    described = {"fragility": "peak of the horizontal acceleration vector (= RotD100)",
                 "hazard": "RotD50" if component == "rotd50" else "RotD100 (vector peak)"}
    if component == "rotd100":
        return OnHazardMeasure(fragility, 1.0, {**described, "fraction": 1.0,
                                                "source": "the same measure: no conversion"})
    if kind == "line":
        fraction = 1.0 / bk17_rotd100_over_rotd50(magnitude, distance_km)
        source = (f"a pulse is the field motion's strongest direction (RotD100): f = 1 / "
                  f"(RotD100 / RotD50 of PGA, Boore & Kishida 2017, at M "
                  f"{5.5 if magnitude is None else magnitude:g}, "
                  f"{50 if distance_km is None else distance_km:g} km) = {fraction:.4f}; a "
                  "field motion along one line would have cos 45 deg")
        extra = {"polarised_fraction": LINE_ROTD50_FRACTION}
    else:
        found = records_fraction(records, fraction_of, magnitude, distance_km)
        fraction, source = found["fraction"], found["source"]
        extra = {"per_record": found["per_record"]}
    return OnHazardMeasure(fragility, fraction, {
        **described, "fraction": fraction, "source": source, **extra,
        "definition": "P on the hazard's PGA x = P of the fragility at x / fraction, "
                      "fraction = RotD50 / vector peak of the campaign's motions; PGV/PGA "
                      "taken as the same on both measures"})
