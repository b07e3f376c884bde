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
    for a tree of one site)."""
    tree: object
    members: tuple
    site: int | None = None


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


def branch_test(groups, specimens, single_log_p, p_all, tree, level):
    """Per branch: P(every specimen survived) ``p_all``, each specimen's own survival
    (``single_log_p``: n x B), the specimens below ``level`` under it (that carry the
    test) and the lowest; and the branches whose ``p_all`` falls below ``level``."""
    single = np.exp(single_log_p)
    site_of = {j: g.site for g in groups for j in g.members}
    rows = []
    for k, branch in enumerate(tree.branch_ids):
        low = int(np.argmin(single[:, k]))
        rows.append({"branch": branch, "prior_weight": float(tree.weights[k]),
                     "survival_all": float(p_all[k]),
                     "below_level": bool(p_all[k] < level),
                     "specimens_below_level": [j for j in range(len(specimens))
                                               if single[j, k] < level],
                     "lowest_specimen": low, "lowest_specimen_site": site_of[low],
                     "lowest_specimen_survival": float(single[low, k])})
    below = [r["branch"] for r in rows if r["below_level"]]
    return rows, {"level": level, "branches_below_level": below,
                  "prior_weight_below_level": float(sum(r["prior_weight"] for r in rows
                                                        if r["below_level"])),
                  "definition": "per branch the probability that every specimen survived "
                  "(survival_all), each specimen's own survival, the specimens whose own "
                  "survival is below the level (they carry the test) and the branches "
                  "under which survival_all is below the level (--floor)"}


def branch_test_csv(rows):
    """branch_test.csv: one row per branch."""
    lines = ["branch,prior_weight,survival_all,below_level,specimens_below_level,"
             "lowest_specimen,lowest_specimen_site,lowest_specimen_survival"]
    for r in rows:
        site = "" if r["lowest_specimen_site"] is None else r["lowest_specimen_site"]
        lines.append(f"{r['branch']},{r['prior_weight']:.9g},{r['survival_all']:.9g},"
                     f"{str(r['below_level']).lower()},"
                     f"{';'.join(str(j) for j in r['specimens_below_level'])},"
                     f"{r['lowest_specimen']},{site},{r['lowest_specimen_survival']:.9g}")
    return "\n".join(lines) + "\n"
