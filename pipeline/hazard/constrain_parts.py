"""The parts of ``constrain.json`` (:class:`~pipeline.hazard.results.ConstrainResult`) that
are records of their own, each written key for key in its field order and read back by
``from_json``: each specimen, each branch's row, the statistics of a set of curves, the
ground motion at a rate, the members' and the draws' spread and the sites (their PGV/PGA
in :mod:`pipeline.hazard.ratio_described`).  Rates in 1/yr, PGA in m/s^2 or g as named,
ages in ka or years as named."""
from dataclasses import dataclass

from pipeline.hazard.ages import AgeDescription
from pipeline.hazard.ratio_described import DensityRatio, GroupsRatio, read_ratio
from pipeline.hazard.record import (ABSENT, Record, check_leaves, check_probability,
                                    check_rate, each, optional)


@dataclass(frozen=True, kw_only=True)
class ConstrainSpecimen(Record):
    """One specimen: its fragility as described and its age (a normal's mean and sd in
    ka, null for other kinds; ``age`` as :meth:`~pipeline.hazard.ages.AgeModel.describe`
    gives it)."""
    fragility: dict
    age_ka: float | None
    age_sd_ka: float | None
    age: AgeDescription
    NAME = "specimens"
    PARTS = {"age": AgeDescription.from_json}


@dataclass(frozen=True, kw_only=True)
class BranchRow(Record):
    """One branch: its id and path, the prior weight, P that the specimens survived under
    it, the weights under Bayes and elimination (None where a rule leaves none), the age
    integration's relative error and the draws' interval where there are any."""
    branch: str
    path: str
    prior_weight: float
    survival_probability: float
    posterior_bayes: float | None
    posterior_eliminate: float | None
    survival_age_se_relative: float = ABSENT
    survival_interval: list = ABSENT
    NAME = "branches"

    def __post_init__(self):
        check_probability(self, "prior_weight", "survival_probability", "posterior_bayes",
                          "posterior_eliminate")


@dataclass(frozen=True, kw_only=True)
class CurveStatistics(Record):
    """The mean of the branches' curves and each fractile's (annual rates per level of
    ``levels_m_s2``; ``fractiles`` keyed by the fractile, ``%g``)."""
    mean_rates_per_yr: list
    fractiles: dict
    NAME = "statistics"

    def __post_init__(self):
        if not isinstance(self.fractiles, dict):
            raise ValueError("fractiles is not an object")


@dataclass(frozen=True, kw_only=True)
class MotionAtRate(Record):
    """PGA on one curve (``curve``: the mean, a fractile, or the band between two) at one
    annual rate, before and after, and the change in percent (None where a curve does not
    reach the rate)."""
    annual_rate_per_yr: float
    curve: str
    prior_m_s2: float | None
    posterior_m_s2: float | None
    prior_g: float | None
    posterior_g: float | None
    change_percent: float | None
    NAME = "ground_motion_at_rates"

    def __post_init__(self):
        check_rate(self, "annual_rate_per_yr")


@dataclass(frozen=True, kw_only=True)
class Mixture(Record):
    """The members' mixture: P_s per branch (the mean over members) and the weights under
    both rules (None where a rule leaves none)."""
    survival_probability: list
    posterior_bayes: list | None
    posterior_eliminate: list | None
    NAME = "members.mixture"


@dataclass(frozen=True, kw_only=True)
class MemberMotion(Record):
    """The posterior mean's PGA (g) at one rate under the mixture and under each member,
    and the members' range (None where none reaches the rate)."""
    mixture_g: float | None
    per_member_g: list
    member_range_g: list | None
    NAME = "members.mean_ground_motion_at_rates"


@dataclass(frozen=True, kw_only=True)
class Members(Record):
    """The fragility's members as possible specimens: P_s per member and branch, the Bayes
    weights per member, their mixture, and the posterior mean's PGA at each stated rate
    (keyed by the rate, ``%g``)."""
    count: int
    survival_per_member: list
    posterior_bayes_per_member: list
    mixture: Mixture
    mean_ground_motion_at_rates: dict
    NAME = "members"
    PARTS = {"mixture": Mixture.from_json,
             "mean_ground_motion_at_rates":
             lambda data: {k: MemberMotion.from_json(v) for k, v in data.items()}}

    def __post_init__(self):
        if len(self.survival_per_member) != self.count:
            raise ValueError(f"members: {len(self.survival_per_member)} rows, count "
                             f"{self.count}")


@dataclass(frozen=True, kw_only=True)
class MonteCarlo(Record):
    """The Monte Carlo error of the fragility: the percentiles of P_s and of the Bayes
    weights per branch over the draws, and of the posterior mean's PGA (g) at each stated
    rate (keyed by the rate, ``%g``; None where no draw reaches it)."""
    draws: int
    survival_interval: list
    posterior_bayes_interval: list | None
    posterior_mean_pga_g_interval_at_rates: dict
    definition: str
    NAME = "monte_carlo"


@dataclass(frozen=True, kw_only=True)
class SiteRow(Record):
    """A site of the tree (None: its only one), the specimens standing there (indices)
    and, where the site takes its own, its PGV/PGA (its rate density's, one or per group
    of branches)."""
    site: int | None
    specimens: list
    pgv_pga: DensityRatio | GroupsRatio = ABSENT
    NAME = "sites"
    PARTS = {"pgv_pga": read_ratio}

    def __post_init__(self):
        check_leaves(self, "pgv_pga")


CONSTRAIN_PARTS = {"specimens": each(ConstrainSpecimen.from_json),
                   "branches": each(BranchRow.from_json),
                   "prior": CurveStatistics.from_json,
                   "posterior": optional(CurveStatistics.from_json),
                   "posterior_bayes": optional(CurveStatistics.from_json),
                   "posterior_eliminate": optional(CurveStatistics.from_json),
                   "ground_motion_at_rates": each(MotionAtRate.from_json),
                   "members": optional(Members.from_json),
                   "monte_carlo": optional(MonteCarlo.from_json),
                   "sites": each(SiteRow.from_json),
                   "pgv_pga": optional(read_ratio)}
"""Readers of constrain.json's fields that are records (field name to reader)."""
