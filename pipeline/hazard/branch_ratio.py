"""PGV/PGA given PGA per branch of a logic tree (:class:`BranchRatios`), for ``constrain``:
each branch its own where the joint-hazard input holds the branch's realisation (a
disaggregation's ``rlzK`` columns, :func:`disaggregation_ratios`; an ``mrd`` per
realisation, :func:`mrd_ratios`), otherwise the mean's for every branch, and the summary
says which and why.  A branch of an OpenQuake export is realisation K when its id is K
(``realizations.csv``'s ``rlz_id``); a plain table's branches match where they are named
0, 1, ...  :func:`rates_by_ratio` integrates each group of branches sharing a model."""
from dataclasses import dataclass, replace

import numpy as np

from pipeline.files import InputError
from pipeline.hazard.constrain import branch_rates
from pipeline.hazard.disagg_ratio import ratio_mixture
from pipeline.hazard.mrd_ratio import ratio_from_mrd
from pipeline.hazard.ratio_described import DensityRatio, GroupsRatio, SitesRatio
from pipeline.hazard.same_place import check_same_place

MEAN = "mean"


@dataclass(frozen=True)
class BranchRatios:
    """PGV/PGA models of a tree's branches: ``models`` (one per group), ``rows`` (the
    branch indices of each group, together every branch once), ``per_branch`` (True: each
    branch its own realisation's; False: the mean's for all), ``why`` (in words) and
    ``route`` (what the models come from)."""
    models: tuple
    rows: tuple
    per_branch: bool
    why: str
    route: str

    def __post_init__(self):
        if len(self.models) != len(self.rows) or not self.models:
            raise InputError("PGV/PGA per branch: one model per group of branches")

    def describe(self):
        """constrain.json's pgv_pga: the one model's description
        (:class:`~pipeline.hazard.ratio_described.MixtureRatio` or
        :class:`~pipeline.hazard.ratio_described.DensityRatio`) with how the branches take
        it, or each group's (:class:`~pipeline.hazard.ratio_described.GroupsRatio`)."""
        if len(self.models) == 1:
            return replace(self.models[0].describe(), per_branch=self.per_branch,
                           branches=self.why)
        groups = [replace(m.describe(), branch_indices=[int(b) for b in rows])
                  for m, rows in zip(self.models, self.rows)]
        first = groups[0]
        where = {"file": first.file, "site_index": first.site_index} \
            if isinstance(first, DensityRatio) else {}
        return GroupsRatio(source=self.route, per_branch=self.per_branch, branches=self.why,
                           **where, groups=groups)


EACH_SITE = ("each site's specimens take PGV/PGA from the rate density at their own site "
             "(the file's site index), as sites[].pgv_pga describes it: no one site's "
             "rate density holds for every specimen")


def ratio_described(ratio_model, site_models):
    """constrain.json's ``pgv_pga``: ``ratio_model``'s description (None: null), or where
    the specimens stand at two sites or more each with its own model (``site_models``,
    {site: :class:`BranchRatios`, or None where a site takes ``ratio_model``}) the route
    and that each site takes its own (:func:`sites_ratio`)."""
    own = {s: m for s, m in site_models.items() if m is not None}
    if len(site_models) > 1 and own:
        return sites_ratio(own)
    return None if ratio_model is None else ratio_model.describe()


def sites_ratio(models):
    """constrain.json's ``pgv_pga`` (a :class:`~pipeline.hazard.ratio_described.
    SitesRatio`) for ``models`` ({site: :class:`BranchRatios`}, two sites or more, each
    the rate density at its own site)."""
    first = next(iter(models.values()))
    why = {m.why for m in models.values()}
    return SitesRatio(
        source="rate density of PGA and PGV (mrd) at each specimen's site",
        file=first.describe().given("file"), per_site=True, site_indices=list(models),
        sites=EACH_SITE, per_branch=all(m.per_branch for m in models.values()),
        branches=why.pop() if len(why) == 1 else "as each site's (sites[].pgv_pga)")


def realisation_ids(tree):
    """Each branch's realisation number (int), or None when a branch id is no number."""
    ids = [str(b) for b in tree.branch_ids]
    return [int(b) for b in ids] if all(b.isdigit() for b in ids) else None


def disaggregation_ratios(disaggregation, tree, column, vs30_m_s, mechanism, correlation):
    """The :class:`BranchRatios` of ``disaggregation`` (a
    :class:`~pipeline.hazard.disaggregation.MagDistDisaggregation`) for ``tree``:
    ``column`` None each branch K its column rlzK where the file holds every branch's,
    else the mean; a column named: that one for every branch.  Each column's bins are
    checked to add up to its curve: a branch's own curve, the mean over branches for
    "mean", realisation K's for rlzK."""
    check_same_place(str(disaggregation.source.get("file")), disaggregation.site,
                     tree.source, "the logic tree's curves")
    ids = realisation_ids(tree)
    own = None if ids is None else [f"rlz{k}" for k in ids]
    route = "magnitude-distance disaggregation " + str(disaggregation.source.get("file"))
    if column is None and own is not None and all(c in disaggregation.columns for c in own):
        for b, c in enumerate(own):
            disaggregation.check_rates(c, tree.levels_m_s2, tree.rates_per_yr[b],
                                       f"branch {tree.branch_ids[b]}'s curve")
        return BranchRatios(
            tuple(ratio_mixture(disaggregation, c, vs30_m_s, mechanism, correlation)
                  for c in own), tuple(np.array([b]) for b in range(tree.size)), True,
            "each branch K its own column rlzK", route)
    chosen = MEAN if column is None else column
    if chosen == MEAN:
        disaggregation.check_rates(MEAN, tree.levels_m_s2,
                                   tree.weights @ tree.rates_per_yr, "the mean curve")
        why = ("the column mean for every branch: the file holds "
               f"{', '.join(disaggregation.columns)}, not a column rlzK for each branch"
               + ("" if own is not None else " (the branches are not numbered realisations)")
               if column is None else "the column mean for every branch (as asked)")
    else:
        _check_named(disaggregation, tree, chosen, ids)
        why = f"the column {chosen} for every branch (as asked)"
    model = ratio_mixture(disaggregation, chosen, vs30_m_s, mechanism, correlation)
    return BranchRatios((model,), (np.arange(tree.size),), False, why, route)


def _check_named(disaggregation, tree, column, ids):
    """A column rlzK named for every branch: its bins against branch K's curve."""
    k = column[3:] if column.startswith("rlz") else ""
    if ids is None or not k.isdigit() or int(k) not in ids:
        raise InputError(f"--disaggregation-column {column}: no branch of the logic tree is "
                         "that realisation (give mean, or leave it out: each branch its own)")
    b = ids.index(int(k))
    disaggregation.check_rates(column, tree.levels_m_s2, tree.rates_per_yr[b],
                               f"branch {tree.branch_ids[b]}'s curve")


def mrd_ratios(joint, site, tree):
    """The :class:`BranchRatios` of ``joint`` (a
    :class:`~pipeline.hazard.joint_hazard.JointHazard`) at ``site`` for ``tree``: each
    branch K its realisation K's rate density where the file holds one per realisation
    and the branches are its realisations, else the mean's for every branch."""
    ids = realisation_ids(tree)
    count = joint.realisations
    route = "rate density of PGA and PGV (mrd) " + str(joint.source.get("file"))
    check_same_place(f"{joint.source.get('file')}: site {site}", joint.site(site).sites[0],
                     tree.source, "the logic tree's curves")
    if count and ids is not None and all(k < count for k in ids):
        return BranchRatios(tuple(ratio_from_mrd(joint, site, k) for k in ids),
                            tuple(np.array([b]) for b in range(tree.size)), True,
                            "each branch K the rate density of realisation K", route)
    if not count:
        why = ("the mean's rate density for every branch: the file holds no rate density "
               "per realisation (the engine writes the mean's only)")
    elif ids is None:
        why = ("the mean's rate density for every branch: the branches are not numbered "
               "realisations")
    else:
        why = (f"the mean's rate density for every branch: the file holds {count} "
               f"realisations' (0-{count - 1}), the tree's branches go to {max(ids)}")
    return BranchRatios((ratio_from_mrd(joint, site),), (np.arange(tree.size),), False,
                        why, route)


def rates_by_ratio(cells, levels_m_s2, rates_per_yr, ratio_model, probability_of):
    """:func:`~pipeline.hazard.constrain.branch_rates` with ``probability_of(model)`` (the
    probability function under a PGV/PGA model): a :class:`BranchRatios` per group of
    branches (each group's cells and curves), any other model for all branches."""
    if not isinstance(ratio_model, BranchRatios):
        return branch_rates(cells, levels_m_s2, rates_per_yr, probability_of(ratio_model))
    rates = np.atleast_2d(np.asarray(rates_per_yr, float))
    out = None
    for model, rows in zip(ratio_model.models, ratio_model.rows):
        part = branch_rates((cells[0], cells[1][rows], cells[2]), levels_m_s2, rates[rows],
                            probability_of(model))
        if out is None:
            out = np.empty(part.shape[:-1] + (rates.shape[0],))
        out[..., rows] = part
    return out
