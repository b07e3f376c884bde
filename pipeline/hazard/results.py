"""What ``survival`` and ``constrain`` say, ``survival.json`` and ``constrain.json``, each as
one type (:class:`SurvivalResult`, :class:`ConstrainResult`) with one writer (``text()``:
the JSON written key for key in the field order) and one reader
(:func:`read_survival_result`, :func:`read_constrain_result`).  The routes fill different
fields (survival's curve route, :func:`pipeline.hazard.assess.assess`, and joint route,
:func:`pipeline.hazard.joint_assess.assess_joint`; constrain's other rule): a field left
:data:`ABSENT` is not written.  Their inner parts are as docs/survival.md and
docs/constrained-hazard.md describe them."""
from dataclasses import dataclass, fields
from pathlib import Path

from pipeline.files import InputError, result_json_text
from pipeline.hazard.constrain_sites import BranchTest
from pipeline.userfiles import DATA_FILE_BYTES, read_json

RULES = ("bayes", "eliminate")              # constrain's rules (constrain.json's rule)


class _Absent:
    """A field the route does not fill (not written to the file)."""

    def __repr__(self):
        return "ABSENT"


ABSENT = _Absent()


class _ResultFile:
    """What both results share: the file's ``NAME``, its ``REQUIRED`` fields, the writer
    and the reader."""
    NAME = ""
    REQUIRED = ()

    def _check_required(self):
        missing = [k for k in self.REQUIRED if getattr(self, k) is ABSENT]
        if missing:
            raise InputError(f"{self.NAME}: no {', '.join(missing)}")

    def given(self, name):
        """The field ``name``, or None where the route leaves it absent."""
        value = getattr(self, name)
        return None if value is ABSENT else value

    def as_json(self) -> dict:
        """The file's content: the fields given, in their order."""
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not ABSENT:
                out[f.name] = value.as_json() if hasattr(value, "as_json") else value
        return out

    def text(self) -> str:
        """The file's text (a NaN or an infinity a one-line error, before any file)."""
        return result_json_text(self.as_json(), self.NAME)

    @classmethod
    def _read(cls, path, **convert):
        data = read_json(path, cls.NAME, DATA_FILE_BYTES)
        if not isinstance(data, dict):
            raise InputError(f"{path}: not a {cls.NAME} (no JSON object)")
        unknown = sorted(set(data) - {f.name for f in fields(cls)})
        if unknown:
            raise InputError(f"{path}: unknown keys {', '.join(unknown)}")
        try:
            return cls(**{k: convert[k](v) if k in convert else v for k, v in data.items()})
        except (InputError, ValueError, TypeError) as e:
            raise InputError(f"{path}: {e}") from None


@dataclass(frozen=True)
class SurvivalResult(_ResultFile):
    """survival.json: the headline (annual overturning rate, 1/yr; survival probability
    over the age; its interval or null; the bounds on the hazard's rates and PGA levels
    that leave survival at 5 %), the age, each specimen's entry, the hazard and the
    PGV/PGA model as described, assumptions, warnings, draws and seed, software."""
    hazard_route: dict = ABSENT
    annual_overturning_rate_per_yr: float = ABSENT
    survival_probability: float = ABSENT
    survival_interval: list | None = ABSENT
    survival_interval_note: str = ABSENT
    survival_per_parameter_set: list = ABSENT
    survival_parameter_set_range: list = ABSENT
    outside_grid: dict = ABSENT
    rate_scale_bound_5pct: float | None = ABSENT
    intensity_scale_bound_5pct: float | None = ABSENT
    intensity_scale_bound_note: str = ABSENT
    contribution_by_intensity: list = ABSENT
    curve_ends: dict = ABSENT
    share_top_pga: float = ABSENT
    share_top_pgv: float = ABSENT
    headline: str = ABSENT
    age_ka: float | None = ABSENT
    age_sd_ka: float | None = ABSENT
    age_distribution: str = ABSENT
    age: dict = ABSENT
    definitions: dict = ABSENT
    specimens: list = ABSENT
    hazard: dict = ABSENT
    pgv_pga: dict | None = ABSENT
    pgv_pga_used: bool = ABSENT
    assumptions: list = ABSENT
    warnings: list = ABSENT
    draws: int = ABSENT
    seed: int = ABSENT
    software: dict = ABSENT
    hazard_curves: list = ABSENT
    survival_range_over_curves: list = ABSENT
    site_set: dict = ABSENT
    hazard_component: str = ABSENT
    figure: str = ABSENT
    site_motion: dict = ABSENT

    NAME = "survival.json"
    REQUIRED = ("hazard_route", "annual_overturning_rate_per_yr", "survival_probability",
                "survival_interval", "rate_scale_bound_5pct", "intensity_scale_bound_5pct",
                "headline", "age_ka", "age_sd_ka", "age_distribution", "age", "specimens",
                "hazard", "pgv_pga", "pgv_pga_used", "assumptions", "warnings", "draws",
                "seed", "software")

    def __post_init__(self):
        self._check_required()
        p, rate = self.survival_probability, self.annual_overturning_rate_per_yr
        if p < 0.0 or p > 1.0:      # a NaN is the writer's one-line error
            raise InputError(f"{self.NAME}: survival_probability {p!r} is not in [0, 1]")
        if rate < 0.0:
            raise InputError(f"{self.NAME}: annual_overturning_rate_per_yr {rate!r} < 0")
        if not self.specimens:
            raise InputError(f"{self.NAME}: no specimens")


@dataclass(frozen=True)
class ConstrainResult(_ResultFile):
    """constrain.json: the rule and its floor, the branches' survival and weights before
    and after, the prior and constrained curves' statistics (``posterior`` under the
    rule, ``posterior_bayes`` or ``posterior_eliminate`` under the other), the ground
    motion at the stated rates, the members' and draws' spread, the branch test
    (:class:`~pipeline.hazard.constrain_sites.BranchTest`), the hazard and the PGV/PGA
    model as described, warnings, assumptions, draws and seed, software, and the files
    of the set."""
    rule: str = ABSENT
    headline: str = ABSENT
    floor: float = ABSENT
    branch_count: int = ABSENT
    specimen_count: int = ABSENT
    specimens: list = ABSENT
    age_model: str = ABSENT
    age_integration_se_max: float | None = ABSENT
    branches: list = ABSENT
    levels_m_s2: list = ABSENT
    levels_g: list = ABSENT
    prior: dict = ABSENT
    posterior: dict | None = ABSENT
    posterior_bayes: dict | None = ABSENT
    posterior_eliminate: dict | None = ABSENT
    ground_motion_at_rates: list = ABSENT
    members: dict | None = ABSENT
    monte_carlo: dict | None = ABSENT
    sites: list = ABSENT
    branch_test: BranchTest = ABSENT
    hazard: dict = ABSENT
    pgv_pga: dict | None = ABSENT
    warnings: list = ABSENT
    assumptions: list = ABSENT
    draws: int = ABSENT
    seed: int = ABSENT
    software: dict = ABSENT
    hazard_component: str = ABSENT
    files: list = ABSENT

    NAME = "constrain.json"
    REQUIRED = ("rule", "headline", "floor", "branch_count", "specimen_count", "specimens",
                "age_model", "age_integration_se_max", "branches", "levels_m_s2",
                "levels_g", "prior", "posterior", "ground_motion_at_rates", "members",
                "monte_carlo", "sites", "branch_test", "hazard", "pgv_pga", "warnings",
                "assumptions", "draws", "seed", "software")

    def __post_init__(self):
        self._check_required()
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


def read_survival_result(path: Path) -> SurvivalResult:
    """survival.json at ``path`` (a key it does not know, or a missing one, is a one-line
    error naming the file)."""
    return SurvivalResult._read(path)


def read_constrain_result(path: Path) -> ConstrainResult:
    """constrain.json at ``path`` (as :func:`read_survival_result`)."""
    return ConstrainResult._read(path, branch_test=BranchTest.from_json)
