"""Specimens at several sites of one logic tree: the survival of the whole set under each
branch, and the branch test (in the manner of Rood et al. 2023).

Sites are taken as far apart: one earthquake does not shake two of them hard, so the
overturnings at different sites are independent given the branch and the set's survival
is the product over sites of each site's survival (its specimens sharing its earthquakes,
as one site's set always does).  Units: rates in 1/yr, ages in years."""
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError

SITE_ASSUMPTION = (
    "Specimens at different sites: the sites are taken as far apart, one earthquake not "
    "shaking two of them hard, so under a branch the set's survival is the product over "
    "sites of each site's survival; specimens at one site share its earthquakes (near "
    "sites should be given as one site).")


@dataclass(frozen=True)
class SiteGroup:
    """The specimens ``members`` (indices into the specimens) at one site of the logic
    tree, and the tree's curves there (``tree``, a LogicTree; ``site``: its index or None
    for a tree of one site); ``ratio_model``: PGV/PGA at the site (the joint hazard's
    there), or None: the one given for every site."""
    tree: object
    members: tuple
    site: int | None = None
    ratio_model: object = None


def check_same_branches(groups):
    """InputError unless every site's tree has the same branches and weights."""
    first = groups[0].tree
    for g in groups[1:]:
        if g.tree.branch_ids != first.branch_ids or \
                not np.array_equal(g.tree.weights, first.weights):
            raise InputError(f"the logic tree's curves at site {g.site} hold other branches "
                             f"or weights than at site {groups[0].site}")


def combined(parts):
    """(ln P_s, relative se or None) of the whole set from each site's: ln P summed over
    the sites (their survival multiplied), the se's in quadrature."""
    if len(parts) == 1:
        return parts[0]
    log_p = sum(part[0] for part in parts)
    ses = [part[1] for part in parts if part[1] is not None]
    return log_p, np.sqrt(sum(se ** 2 for se in ses)) if ses else None


@dataclass(frozen=True)
class BranchTestRow:
    """One branch of the branch test: P(every specimen survived) ``survival_all``, the
    specimens whose own survival is below the level, the lowest specimen, its site and
    its survival."""
    branch: str
    prior_weight: float
    survival_all: float
    below_level: bool
    specimens_below_level: tuple
    lowest_specimen: int
    lowest_specimen_site: int | None
    lowest_specimen_survival: float

    def csv_line(self):
        site = "" if self.lowest_specimen_site is None else self.lowest_specimen_site
        return (f"{self.branch},{self.prior_weight:.9g},{self.survival_all:.9g},"
                f"{str(self.below_level).lower()},"
                f"{';'.join(str(j) for j in self.specimens_below_level)},"
                f"{self.lowest_specimen},{site},{self.lowest_specimen_survival:.9g}")


@dataclass(frozen=True)
class BranchTest:
    """The branch test at ``level`` (in the manner of Rood et al. 2023): its ``rows``, one
    per branch; the one writer of branch_test.csv and constrain.json's branch_test."""
    level: float
    rows: tuple

    def __post_init__(self):
        if not 0 < self.level < 1:
            raise ValueError(f"a branch test's level lies in (0, 1), got {self.level}")

    @property
    def branches_below_level(self):
        return [r.branch for r in self.rows if r.below_level]

    @property
    def prior_weight_below_level(self):
        return float(sum(r.prior_weight for r in self.rows if r.below_level))

    def as_json(self):
        """constrain.json's ``branch_test``."""
        return {"level": self.level, "branches_below_level": self.branches_below_level,
                "prior_weight_below_level": self.prior_weight_below_level,
                "definition": DEFINITION,
                "branches": [{**r.__dict__,
                              "specimens_below_level": list(r.specimens_below_level)}
                             for r in self.rows]}

    @classmethod
    def from_json(cls, data):
        """The branch test constrain.json's ``branch_test`` holds (:meth:`as_json`)."""
        return cls(data["level"], tuple(
            BranchTestRow(**{**r, "specimens_below_level": tuple(r["specimens_below_level"])})
            for r in data["branches"]))

    def csv(self):
        """branch_test.csv: one row per branch."""
        return "\n".join([",".join(BranchTestRow.__dataclass_fields__)]
                         + [r.csv_line() for r in self.rows]) + "\n"


DEFINITION = ("per branch the probability that every specimen survived (survival_all), "
              "each specimen's own survival, the specimens whose own survival is below the "
              "level (they carry the test) and the branches under which survival_all is "
              "below the level (--floor)")


def branch_test(groups, single_log_p, p_all, tree, level):
    """The :class:`BranchTest` of ``p_all`` (P(every specimen survived) per branch) and
    ``single_log_p`` (each specimen's own ln survival at its site, n x B) at ``level``."""
    single = np.exp(single_log_p)
    site_of = {j: g.site for g in groups for j in g.members}
    rows = []
    for k, branch in enumerate(tree.branch_ids):
        low = int(np.argmin(single[:, k]))
        rows.append(BranchTestRow(
            branch, float(tree.weights[k]), float(p_all[k]), bool(p_all[k] < level),
            tuple(j for j in range(single.shape[0]) if single[j, k] < level), low,
            site_of[low], float(single[low, k])))
    return BranchTest(level, tuple(rows))
