"""The parts of ``survival.json`` (:class:`~pipeline.hazard.results.SurvivalResult`) that
are records of their own, each written key for key in its field order and read back by
``from_json``: the route, each specimen's entry, the contribution by PGA interval, what
the curve's ends hold, what comes from outside a pulse grid, a hazard curve's row and a
set's survival under the three assumptions.  Rates in 1/yr, PGA in m/s^2 or g as named."""
from dataclasses import dataclass
from enum import Enum

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.ages import AgeKind
from pipeline.hazard.record import ABSENT, Record, check_probability, check_rate, each


class Route(Enum):
    """Which hazard survival is computed under (survival.json's ``hazard_route.route``)."""
    CURVE = "curve"
    JOINT = "joint"


@dataclass(frozen=True, kw_only=True)
class HazardRoute(Record):
    """The route and what it takes the hazard to be, in words."""
    route: Route
    what: str
    NAME = "hazard_route"
    PARTS = {"route": Route}

    def __post_init__(self):
        if not isinstance(self.route, Route):
            raise ValueError(f"route {self.route!r} is not one of "
                             f"{', '.join(r.value for r in Route)}")


@dataclass(frozen=True, kw_only=True)
class ContributionRow(Record):
    """The rate of overturning (1/yr) from one PGA interval of the curve (``hi`` None: the
    exceedances of its last level) and its share of the whole (None for a rate of 0)."""
    lo_m_s2: float
    hi_m_s2: float | None
    rate_per_yr: float
    share: float | None
    lo_g: float
    hi_g: float | None
    NAME = "contribution_by_intensity"

    def __post_init__(self):
        check_rate(self, "rate_per_yr")
        check_probability(self, "share")

    @classmethod
    def of(cls, row):
        """The row of :func:`pipeline.hazard.survival.contribution_by_intensity` ``row``,
        its PGA also in g."""
        hi = row["hi_m_s2"]
        return cls(**row, lo_g=row["lo_m_s2"] / STANDARD_GRAVITY,
                   hi_g=None if hi is None else hi / STANDARD_GRAVITY)


@dataclass(frozen=True, kw_only=True)
class CurveEnds(Record):
    """What the curve's ends hold of the rate (:func:`pipeline.hazard.survival.
    overturning_rate`): within the curve, at the last level, the shares of the first
    interval and the last level (None for a rate of 0), what the last level could add."""
    within_curve_per_yr: float
    at_last_level_per_yr: float
    share_first_interval: float | None
    share_at_last_level: float | None
    last_level_could_add_per_yr: float
    NAME = "curve_ends"

    def __post_init__(self):
        check_rate(self, "within_curve_per_yr", "at_last_level_per_yr",
                   "last_level_could_add_per_yr")
        check_probability(self, "share_first_interval", "share_at_last_level")


@dataclass(frozen=True, kw_only=True)
class OutsideGrid(Record):
    """A pulse grid's PGA range, the rate from below and above it and their shares, the
    rate with P = 0 below it and the edge's P held there, the hazard curve beyond the
    grid's top and the rate with P = 1 above it; ``p_above_grid`` the fragility's
    ``above_grid`` as it describes it."""
    pga_range_m_s2: list
    pga_range_g: list
    rate_below_grid_per_yr: float
    rate_above_grid_per_yr: float
    share_below_grid: float | None
    share_above_grid: float | None
    rate_per_yr_zero_below_grid: float
    rate_per_yr_edge_held_below_grid: float
    hazard_last_level_g: float
    hazard_reach_over_grid_top: float
    hazard_rate_above_grid_per_yr: float
    rate_per_yr_one_above_grid: float
    p_above_grid: dict | None
    NAME = "outside_grid"

    def __post_init__(self):
        check_rate(self, "rate_below_grid_per_yr", "rate_above_grid_per_yr",
                   "rate_per_yr_zero_below_grid", "rate_per_yr_edge_held_below_grid",
                   "hazard_rate_above_grid_per_yr", "rate_per_yr_one_above_grid")
        if len(self.pga_range_m_s2) != 2 or len(self.pga_range_g) != 2:
            raise ValueError("a PGA range is not two numbers")


@dataclass(frozen=True, kw_only=True)
class SpecimenResult(Record):
    """One specimen's entry of ``specimens``: its fragility as described, its rate and
    survival; on the curve route its interval, bounds, contribution, curve ends, parameter
    sets and what comes from outside its grid; on the joint route the shares in the top
    PGA row and PGV column."""
    fragility: dict
    annual_overturning_rate_per_yr: float
    survival_probability: float
    survival_interval: list | None = ABSENT
    rate_scale_bound_5pct: float | None = ABSENT
    intensity_scale_bound_5pct: float | None = ABSENT
    intensity_scale_bound_note: str = ABSENT
    contribution_by_intensity: list = ABSENT
    curve_ends: CurveEnds = ABSENT
    rate_per_parameter_set_per_yr: list = ABSENT
    survival_per_parameter_set: list = ABSENT
    survival_parameter_set_range: list = ABSENT
    outside_grid: OutsideGrid = ABSENT
    survival_interval_note: str = ABSENT
    share_top_pga: float | None = ABSENT
    share_top_pgv: float | None = ABSENT
    NAME = "specimens"
    PARTS = {"contribution_by_intensity": each(ContributionRow.from_json),
             "curve_ends": CurveEnds.from_json, "outside_grid": OutsideGrid.from_json}

    def __post_init__(self):
        check_rate(self, "annual_overturning_rate_per_yr")
        check_probability(self, "survival_probability", "share_top_pga", "share_top_pgv")


@dataclass(frozen=True, kw_only=True)
class CurveRow(Record):
    """One hazard curve's row of ``hazard_curves``: the curve (file, format, kind, site,
    investigation time) and the headline under it."""
    file: str | None
    format: str | None
    kind: str | None
    site_index: int | None
    investigation_time_yr: float | None
    annual_overturning_rate_per_yr: float
    survival_probability: float
    survival_interval: list | None
    rate_scale_bound_5pct: float | None
    intensity_scale_bound_5pct: float | None
    survival_parameter_set_range: list = ABSENT
    NAME = "hazard_curves"

    def __post_init__(self):
        check_rate(self, "annual_overturning_rate_per_yr")
        check_probability(self, "survival_probability")


@dataclass(frozen=True, kw_only=True)
class SetSurvival(Record):
    """A set's rate of any overturning (1/yr), its survival (all stand) and the bound on
    the hazard's rates, under one assumption."""
    annual_rate_any_overturns_per_yr: float
    survival_probability_all: float
    rate_scale_bound_5pct: float | None
    NAME = "site_set"

    def __post_init__(self):
        check_rate(self, "annual_rate_any_overturns_per_yr")
        check_probability(self, "survival_probability_all")


@dataclass(frozen=True, kw_only=True)
class SiteSet(Record):
    """A set's survival with independent earthquakes, under common shaking and fully
    correlated (the assumptions of :data:`pipeline.hazard.assess.ASSUMPTIONS`)."""
    independent: SetSurvival
    common_shaking: SetSurvival
    fully_correlated: SetSurvival
    NAME = "site_set"
    PARTS = {name: SetSurvival.from_json
             for name in ("independent", "common_shaking", "fully_correlated")}


SURVIVAL_PARTS = {"hazard_route": HazardRoute.from_json,
                  "specimens": each(SpecimenResult.from_json),
                  "contribution_by_intensity": each(ContributionRow.from_json),
                  "curve_ends": CurveEnds.from_json,
                  "outside_grid": OutsideGrid.from_json,
                  "hazard_curves": each(CurveRow.from_json),
                  "site_set": SiteSet.from_json}
"""Readers of survival.json's fields that are records (field name to reader)."""


def age_keys(age):
    """survival.json's age: age_ka and age_sd_ka (a normal's; null for other kinds),
    age_distribution in words and age (:meth:`~pipeline.hazard.ages.AgeModel.describe`)."""
    normal = age.kind is AgeKind.NORMAL
    words = {AgeKind.NORMAL: "fixed" if normal and age.sd_yr == 0 else "normal truncated at 0",
             AgeKind.LOWER_BOUND: "a lower bound (survival an upper bound)",
             AgeKind.INTERVAL: "uniform on an interval", AgeKind.SAMPLES: "samples"}
    return {"age_ka": age.mean_yr / 1000.0 if normal else None,
            "age_sd_ka": age.sd_yr / 1000.0 if normal else None,
            "age_distribution": words[age.kind], "age": age.describe()}
