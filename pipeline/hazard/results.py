"""What ``survival`` and ``constrain`` say, ``survival.json`` and ``constrain.json``, each as
one type (:class:`SurvivalResult`, :class:`ConstrainResult`) with one writer (``text()``:
the JSON written key for key in the field order) and one reader
(:func:`read_survival_result`, :func:`read_constrain_result`).  The routes fill different
fields (survival's curve route, :func:`pipeline.hazard.assess.assess`, and joint route,
:func:`pipeline.hazard.joint_assess.assess_joint`; constrain's other rule): a field left
:data:`ABSENT` is not written.  Their inner parts are as docs/survival.md and
docs/constrained-hazard.md describe them."""
from dataclasses import dataclass
from pathlib import Path

from pipeline.files import InputError, result_json_text
from pipeline.hazard.constrain_parts import (CONSTRAIN_PARTS, CurveStatistics, Members,
                                             MonteCarlo)
from pipeline.hazard.ages import AgeDescription
from pipeline.hazard.constrain_sites import BranchTest
from pipeline.hazard.hazard_described import (CurveHazard, JointHazardDescribed, TreeHazard,
                                              read_survival_hazard)
from pipeline.hazard.ratio_described import (MixtureRatio, RatioDescribed, ScenarioRatio,
                                              StatedRatio, read_ratio)
from pipeline.hazard.record import (ABSENT, Record, check_leaves, check_probability,
                                    check_rate, optional)
from pipeline.hazard.survival_parts import (SURVIVAL_PARTS, CurveEnds, HazardRoute,
                                            OutsideGrid, Route, SiteSet)
from pipeline.userfiles import DATA_FILE_BYTES, read_json

RULES = ("bayes", "eliminate")              # constrain's rules (constrain.json's rule)
__all__ = ["ABSENT", "ConstrainResult", "SurvivalResult", "read_constrain_result",
           "read_survival_result"]


class _ResultFile(Record):
    """What both results share: the file's ``NAME``, its writer and its reader."""

    def text(self) -> str:
        """The file's text (a NaN or an infinity a one-line error, before any file)."""
        return result_json_text(self.as_json(), self.NAME)

    @classmethod
    def _read(cls, path):
        data = read_json(path, cls.NAME, DATA_FILE_BYTES)
        if not isinstance(data, dict):
            raise InputError(f"{path}: not a {cls.NAME} (no JSON object)")
        try:
            return cls.from_json(data)
        except InputError as e:
            raise InputError(f"{path}: {str(e).removeprefix(cls.NAME + ': ')}") from None


@dataclass(frozen=True, kw_only=True)
class SurvivalResult(_ResultFile):
    """survival.json: the headline (annual overturning rate, 1/yr; survival probability
    over the age; its interval or null; the bounds on the hazard's rates and PGA levels
    that leave survival at 5 %), the age, each specimen's entry
    (:class:`~pipeline.hazard.survival_parts.SpecimenResult`), the hazard and the PGV/PGA
    model as described, assumptions, warnings, draws and seed, software.  A field without
    a default is required on every route."""
    hazard_route: HazardRoute
    annual_overturning_rate_per_yr: float
    survival_probability: float
    survival_interval: list | None
    survival_interval_note: str = ABSENT
    survival_per_parameter_set: list = ABSENT
    survival_parameter_set_range: list = ABSENT
    outside_grid: OutsideGrid = ABSENT
    rate_scale_bound_5pct: float | None
    intensity_scale_bound_5pct: float | None
    intensity_scale_bound_note: str = ABSENT
    contribution_by_intensity: list = ABSENT
    curve_ends: CurveEnds = ABSENT
    share_top_pga: float | None = ABSENT
    share_top_pgv: float | None = ABSENT
    headline: str
    age_ka: float | None
    age_sd_ka: float | None
    age_distribution: str
    age: AgeDescription
    definitions: dict = ABSENT
    specimens: list
    hazard: CurveHazard | JointHazardDescribed
    pgv_pga: StatedRatio | ScenarioRatio | MixtureRatio | None
    pgv_pga_used: bool
    assumptions: list
    warnings: list
    draws: int
    seed: int
    software: dict
    hazard_curves: list = ABSENT
    survival_range_over_curves: list = ABSENT
    site_set: SiteSet = ABSENT
    hazard_component: str = ABSENT
    figure: str = ABSENT
    site_motion: dict = ABSENT

    NAME = "survival.json"
    PARTS = {**SURVIVAL_PARTS, "age": AgeDescription.from_json,
             "hazard": read_survival_hazard, "pgv_pga": optional(read_ratio)}

    def __post_init__(self):
        check_leaves(self, "pgv_pga")
        joint = isinstance(self.hazard, JointHazardDescribed)
        if joint != (self.hazard_route.route is Route.JOINT):
            raise InputError(f"{self.NAME}: the hazard is not of the route "
                             f"{self.hazard_route.route.value}")
        check_probability(self, "survival_probability")
        check_rate(self, "annual_overturning_rate_per_yr")
        if not self.specimens:
            raise InputError(f"{self.NAME}: no specimens")


@dataclass(frozen=True, kw_only=True)
class ConstrainResult(_ResultFile):
    """constrain.json: the rule and its floor, the branches' survival and weights before
    and after, the prior and constrained curves' statistics (``posterior`` under the
    rule, ``posterior_bayes`` or ``posterior_eliminate`` under the other), the ground
    motion at the stated rates, the members' and draws' spread, the branch test
    (:class:`~pipeline.hazard.constrain_sites.BranchTest`), the hazard and the PGV/PGA
    model as described (by its route, :mod:`pipeline.hazard.ratio_described`), warnings, assumptions, draws and seed, software, and the files
    of the set (the parts' types in :mod:`pipeline.hazard.constrain_parts`)."""
    rule: str
    headline: str
    floor: float
    branch_count: int
    specimen_count: int
    specimens: list
    age_model: str
    age_integration_se_max: float | None
    branches: list
    levels_m_s2: list
    levels_g: list
    prior: CurveStatistics
    posterior: CurveStatistics | None
    posterior_bayes: CurveStatistics | None = ABSENT
    posterior_eliminate: CurveStatistics | None = ABSENT
    ground_motion_at_rates: list
    members: Members | None
    monte_carlo: MonteCarlo | None
    sites: list
    branch_test: BranchTest
    hazard: TreeHazard
    pgv_pga: RatioDescribed | None
    warnings: list
    assumptions: list
    draws: int
    seed: int
    software: dict
    hazard_component: str = ABSENT
    files: list = ABSENT

    NAME = "constrain.json"
    PARTS = {**CONSTRAIN_PARTS, "branch_test": BranchTest.from_json,
             "hazard": TreeHazard.from_json}

    def __post_init__(self):
        if self.rule not in RULES:
            raise InputError(f"{self.NAME}: rule {self.rule!r} is not one of "
                             f"{', '.join(RULES)}")
        other = f"posterior_{RULES[1 - RULES.index(self.rule)]}"
        if getattr(self, other) is ABSENT or getattr(self, f"posterior_{self.rule}") \
                is not ABSENT:
            raise InputError(f"{self.NAME}: the other rule's weights are {other} "
                             f"(rule {self.rule})")
        if len(self.branches) != self.branch_count:
            raise InputError(f"{self.NAME}: {len(self.branches)} branches, branch_count "
                             f"{self.branch_count}")
        if not isinstance(self.branch_test, BranchTest):
            raise InputError(f"{self.NAME}: branch_test is not a BranchTest")
        check_leaves(self, "pgv_pga")


def read_survival_result(path: Path) -> SurvivalResult:
    """survival.json at ``path`` (a key it does not know, or a missing one, is a one-line
    error naming the file)."""
    return SurvivalResult._read(path)


def read_constrain_result(path: Path) -> ConstrainResult:
    """constrain.json at ``path`` (as :func:`read_survival_result`)."""
    return ConstrainResult._read(path)
