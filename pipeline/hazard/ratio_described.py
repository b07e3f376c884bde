"""PGV/PGA given PGA as the results describe it (survival.json's and constrain.json's
``pgv_pga``, constrain.json's ``sites[].pgv_pga``): one record per route by which it was
obtained, made by the PGV/PGA model that takes the route (its ``describe()``) and read
back by :func:`read_ratio`:

- :class:`StatedRatio`: a lognormal the user states, the same at every PGA;
- :class:`ScenarioRatio`: one scenario's ground-motion model at a magnitude and distance,
  ln PGV given ln PGA by their correlation;
- :class:`MixtureRatio`: a mixture over a magnitude-distance disaggregation's bins;
- :class:`DensityRatio`: a site's rate density of PGA and PGV (OpenQuake's ``mrd``);
- :class:`GroupsRatio`: a logic tree's branches in groups, each group its own mixture or
  rate density (``groups``: each of those with its ``branch_indices``);
- :class:`SitesRatio`: specimens at several sites, each site its own rate density.

Where ``constrain`` gives every branch one mixture or rate density, its record also says
how the branches take it (``per_branch``, ``branches``).  PGA in m/s^2, PGV in m/s,
PGV/PGA in s, distances in km, Vs30 in m/s."""
from dataclasses import dataclass

from pipeline.files import InputError
from pipeline.hazard.record import ABSENT, Record, check_leaves, each

STATED = "user"
SCENARIO = "ground-motion model"
MIXTURE = "magnitude-distance disaggregation"


def _at_least(record, low, *names):
    """ValueError unless each field ``names`` of ``record`` is >= ``low``."""
    for name in names:
        if getattr(record, name) < low:
            raise ValueError(f"{name} {getattr(record, name)!r} < {low:g}")


def _fixed(record, source):
    if record.source != source:
        raise ValueError(f"source {record.source!r} is not {source!r}")


@dataclass(frozen=True, kw_only=True)
class StatedRatio(Record):
    """PGV/PGA lognormal with the median (s) and sigma of ln the user states."""
    source: str = STATED
    distribution: str
    median_s: float
    sigma_ln: float
    NAME = "pgv_pga"

    def __post_init__(self):
        check_leaves(self)
        _fixed(self, STATED)
        if not self.median_s > 0:
            raise ValueError(f"median_s {self.median_s!r} is not above 0")
        _at_least(self, 0.0, "sigma_ln")


@dataclass(frozen=True, kw_only=True)
class ScenarioRatio(Record):
    """The ground-motion model at one magnitude and Joyner-Boore distance (km), Vs30 (m/s)
    and mechanism, the correlation of ln PGA and ln PGV and where it comes from, the
    model's medians (m/s^2, m/s) and sigmas of ln, pygmm's version."""
    source: str = SCENARIO
    model: str
    magnitude: float
    distance_jb_km: float
    vs30_m_s: float
    mechanism: str
    pga_pgv_correlation: float
    pga_pgv_correlation_source: str
    median_pga_m_s2: float
    median_pgv_m_s: float
    ln_std_pga: float
    ln_std_pgv: float
    pygmm: str
    distribution: str
    NAME = "pgv_pga"

    def __post_init__(self):
        check_leaves(self)
        _fixed(self, SCENARIO)
        _at_least(self, 0.0, "distance_jb_km", "vs30_m_s", "median_pga_m_s2",
                  "median_pgv_m_s", "ln_std_pga", "ln_std_pgv")
        _correlation(self)


def _correlation(record):
    if not -1.0 <= record.pga_pgv_correlation <= 1.0:
        raise ValueError(f"pga_pgv_correlation {record.pga_pgv_correlation!r} is not in "
                         "[-1, 1]")


class _OfBranches(Record):
    """What a mixture and a rate density say of a tree's branches: in a group of
    :class:`GroupsRatio` its ``branch_indices``; given to every branch, ``per_branch``
    (each its own realisation's) and ``branches`` (why, in words)."""

    def _check_branches(self):
        if (self.per_branch is ABSENT) != (self.branches is ABSENT):
            raise ValueError("per_branch and branches go together")
        if self.branch_indices is not ABSENT and (
                self.per_branch is not ABSENT or not self.branch_indices
                or not all(isinstance(b, int) and b >= 0 for b in self.branch_indices)):
            raise ValueError("a group's branch_indices: branch numbers, no per_branch")

    @property
    def in_group(self) -> bool:
        """True for a group of :class:`GroupsRatio`."""
        return self.branch_indices is not ABSENT


@dataclass(frozen=True, kw_only=True)
class MixtureRatio(_OfBranches):
    """A mixture over the disaggregation's bins with events (``bins``: each its magnitude
    and distance, km), their shares at each anchor (m/s^2, the disaggregated levels) as
    ``shares`` says, and the bins' ground-motion model (Vs30, mechanism, correlation)."""
    branch_indices: list = ABSENT
    source: str = MIXTURE
    bins_used: int
    bins: list
    anchors_m_s2: list
    shares: str
    model: str
    vs30_m_s: float
    mechanism: str
    pga_pgv_correlation: float
    pga_pgv_correlation_source: str
    per_branch: bool = ABSENT
    branches: str = ABSENT
    NAME = "pgv_pga"

    def __post_init__(self):
        check_leaves(self)
        _fixed(self, MIXTURE)
        self._check_branches()
        _correlation(self)
        if self.bins_used < 1 or len(self.bins) != self.bins_used or not all(
                isinstance(b, list | tuple) and len(b) == 2 for b in self.bins):
            raise ValueError(f"bins_used {self.bins_used!r}: not as many [magnitude, "
                             "distance] bins")


@dataclass(frozen=True, kw_only=True)
class DensityRatio(_OfBranches):
    """A site's rate density of PGA and PGV (the mean's, or a realisation's as ``source``
    says; ``file`` and ``site_index`` where the density was read from one), the PGA cells
    with events and the distribution taken."""
    branch_indices: list = ABSENT
    source: str
    file: str = ABSENT
    site_index: int = ABSENT
    pga_cells_with_events: int
    distribution: str
    per_branch: bool = ABSENT
    branches: str = ABSENT
    NAME = "pgv_pga"

    def __post_init__(self):
        check_leaves(self)
        self._check_branches()
        _at_least(self, 1, "pga_cells_with_events")


def _read_group(data):
    return read_ratio(data)


@dataclass(frozen=True, kw_only=True)
class GroupsRatio(Record):
    """A logic tree's branches in groups, each group its own mixture or rate density:
    the route (``source``, with the file), ``per_branch`` and why (``branches``), the
    file and site of the first group's rate density, and the groups."""
    source: str
    per_branch: bool
    branches: str
    file: str = ABSENT
    site_index: int = ABSENT
    groups: list
    NAME = "pgv_pga"
    PARTS = {"groups": each(_read_group)}

    def __post_init__(self):
        check_leaves(self)
        if len(self.groups) < 2 or not all(
                isinstance(g, MixtureRatio | DensityRatio) and g.in_group for g in self.groups):
            raise ValueError("groups: two or more, each a mixture or a rate density with its "
                             "branch_indices")

    def group_of(self, branch):
        """The group that branch ``branch`` (its index) is in."""
        return next(g for g in self.groups if branch in g.branch_indices)


@dataclass(frozen=True, kw_only=True)
class SitesRatio(Record):
    """constrain.json's ``pgv_pga`` when the specimens stand at several sites and each
    site's take PGV/PGA from the rate density at their own site (``--joint-hazard`` with
    ``--specimen-site``): the route (``source``) and its file, the sites (``site_indices``,
    the file's), in words that each takes its own (described under ``sites[].pgv_pga``),
    and how the branches take it (``per_branch``, ``branches``: the same at every site,
    one file and one tree's branches)."""
    source: str
    file: str | None
    per_site: bool
    site_indices: list
    sites: str
    per_branch: bool
    branches: str
    NAME = "pgv_pga"

    def __post_init__(self):
        check_leaves(self)
        if self.per_site is not True or len(self.site_indices) < 2:
            raise ValueError("per site: per_site true, two sites or more")


RatioDescribed = (StatedRatio | ScenarioRatio | MixtureRatio | DensityRatio | GroupsRatio
                  | SitesRatio)
"""The PGV/PGA of a result, by any route."""

ROUTES = (("per_site", SitesRatio), ("groups", GroupsRatio), ("bins_used", MixtureRatio),
          ("pga_cells_with_events", DensityRatio), ("magnitude", ScenarioRatio),
          ("median_s", StatedRatio))
"""The key that only each route's record holds, and the record."""


def read_ratio(data) -> RatioDescribed:
    """The record of the JSON object ``data`` (InputError in one line where it is no
    route's or a route's record refuses it)."""
    if not isinstance(data, dict):
        raise InputError(f"pgv_pga: not a JSON object: {type(data).__name__}")
    kind = next((cls for key, cls in ROUTES if key in data), None)
    if kind is None:
        raise InputError("pgv_pga: no route of PGV/PGA (it holds none of "
                         f"{', '.join(key for key, _ in ROUTES)})")
    return kind.from_json(data)
