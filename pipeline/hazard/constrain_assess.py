"""What ``constrain`` says for a logic tree and the specimens standing at its site:
``constrain.json``'s content, the tables and the arrays of its figure
(:func:`constrain_tree`)."""
from enum import Enum

import numpy as np
from threadpoolctl import threadpool_limits

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.branch_ratio import rates_by_ratio, ratio_described
from pipeline.hazard.constrain import (FRACTILES, TARGET_RATES, bayes, cell_matrix,
                                       change_percent, draw_chunk, eliminate,
                                       log_survival_fixed, log_survival_sampled,
                                       motion_at_rate, weighted_mean,
                                       weighted_quantile)
from pipeline.hazard.constrain_parts import (BranchRow, ConstrainSpecimen, CurveStatistics,
                                             MemberMotion, Members, Mixture, MonteCarlo,
                                             MotionAtRate, SiteRow)
from pipeline.hazard.constrain_sites import (SITE_ASSUMPTION, SiteGroup, branch_test,
                                             check_same_branches, combined)
from pipeline.hazard.hazard_described import TreeHazard
from pipeline.hazard.logictree import LogicTree
from pipeline.hazard.record import ABSENT
from pipeline.hazard.survival_parts import age_keys
from pipeline.hazard.results import ConstrainResult
from pipeline.hazard.set_probability import set_probabilities, subset_probabilities
from pipeline.provenance import software_versions

AGE_SAMPLES = 2000           # Monte Carlo samples of differing, uncertain ages
INTERVAL = (2.5, 97.5)       # percentiles of the intervals over fragility draws
END_SHARE_WARNING = 0.1

WHY_BAYES = ("Bayes is the headline: each branch's weight is multiplied by the probability "
             "that the specimens survived under it (the likelihood), so all of what the "
             "survival says is used, and no threshold is chosen; elimination keeps or drops a "
             "branch by an arbitrary floor and forgets how far above it a branch lies.")

ASSUMPTIONS = [
    "Earthquakes are a Poisson process in time; a specimen's age is the time it has stood "
    "exposed in its present state.",
    "Specimens at one site share every earthquake and overturn independently given its "
    "shaking (P(any overturns) = 1 - prod(1 - P_j), averaged over PGV/PGA).  With differing "
    "ages the joint survival is the product over the age intervals (youngest first) of the "
    "survival of the specimens standing through each interval: exact for a Poisson process.",
    "An age is taken as dated (each specimen's age): known; normal (mean, sd) truncated "
    "at 0, uniform on an interval or samples from a file, integrated over; a lower bound "
    "taken as the age (the specimen's survival an upper bound, the constraint the weakest "
    "the bound allows).  One age for all specimens: integrated exactly.  Differing ages, "
    "some uncertain: Monte Carlo over "
    f"independent ages ({AGE_SAMPLES} samples; the standard error is reported), and for the "
    "fragility draws the ages at their means.",
    "Each branch's curve is interpolated linearly in (ln PGA, ln rate), nothing counted "
    "below its first level and every exceedance of its last level counted at it (a lower "
    "bound on the rate), as in survival.",
    "The mean hazard curve is the weighted mean of the branches' annual rates (OpenQuake "
    "averages probabilities of exceedance unless use_rates is set: at small probabilities "
    "the two agree); fractiles are OpenQuake's weighted quantile (values sorted, cumulative "
    "weights interpolated linearly), branches of weight 0 left out.",
    "Ground motion at an annual rate: the curve interpolated linearly in (ln rate, ln PGA), "
    "never extrapolated (null outside the curve's rates).",
    "The fragility's members (its parameter sets) are possible specimens: the weights under "
    "each member and under their mixture (the mean over members of P_s per branch) are "
    "reported apart from the Monte Carlo error of the fragility (its draws).  In a set, "
    "member m takes every specimen's m-th member (specimens without members their own "
    "fragility).",
]


@threadpool_limits.wrap(limits=1)      # BLAS threads only slow its many small products
def constrain_tree(tree, specimens, ratio_model, ages, rule, floor, draws, seed,
                   groups=None):
    """(constrain.json as a :class:`~pipeline.hazard.results.ConstrainResult`, branch
    rows, figure data) for the
    :class:`~pipeline.hazard.logictree.LogicTree` ``tree`` and ``specimens`` (fragility
    objects, one per specimen) of ages ``ages`` (:class:`~pipeline.hazard.ages.AgeModel`,
    years, one per specimen).  ``groups``: the specimens by site
    (:class:`~pipeline.hazard.constrain_sites.SiteGroup`; None: all at ``tree``'s site);
    ``tree`` gives the curves reported."""
    groups = groups or [SiteGroup(tree, tuple(range(len(specimens))))]
    rng = np.random.default_rng(seed)
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    sites, mode = _sites(tree, cells, groups, ages, rng, ratio_model)
    warnings = list(tree.notes)

    def survival_of(batch, sampled=True):
        return combined([_log_survival(t, c, [[chosen[j] for j in m] for chosen in batch],
                                       ratio, [ages[j] for j in m], how,
                                       samples if sampled else None)
                         for m, t, c, how, samples, ratio in sites])

    log_p, age_se = (None if v is None else v[0] for v in survival_of([specimens]))
    p = np.exp(log_p)
    posterior = {"bayes": bayes(tree.weights, log_p), "eliminate": eliminate(tree.weights, p,
                                                                           floor)}
    for name, w in posterior.items():
        if w is None:
            warnings.append(_none_left(name, floor, tree, p))
    members = _members(tree, specimens, survival_of, floor, warnings)
    carlo = _draws(tree, cells, specimens, survival_of, draws, rng, floor)
    for m, t, c, _, _, ratio in sites:
        warnings += _end_warnings(t, c, [specimens[j] for j in m], ratio, posterior[rule])
    test = branch_test(groups, _singles(sites, specimens, ages), p, tree, floor)
    prior_stats = _statistics(tree, tree.weights)
    post_stats = None if posterior[rule] is None else _statistics(tree, posterior[rule])
    other = "eliminate" if rule == "bayes" else "bayes"
    summary = ConstrainResult(
        rule=rule, headline=WHY_BAYES, floor=floor,
        branch_count=tree.size, specimen_count=len(specimens),
        specimens=[ConstrainSpecimen(fragility=f.describe(), **_age_keys(a))
                   for f, a in zip(specimens, ages)],
        age_model=mode.value,
        age_integration_se_max=None if age_se is None else float(np.nanmax(age_se)),
        branches=_branch_rows(tree, p, posterior, carlo, age_se),
        levels_m_s2=tree.levels_m_s2.tolist(),
        levels_g=(tree.levels_m_s2 / STANDARD_GRAVITY).tolist(),
        prior=prior_stats,
        posterior=post_stats,
        **{f"posterior_{other}": None if posterior[other] is None
           else _statistics(tree, posterior[other])},
        ground_motion_at_rates=_motions(tree, prior_stats, post_stats),
        members=members, monte_carlo=carlo,
        sites=_site_rows(groups),
        branch_test=test,
        hazard=TreeHazard(source=dict(tree.source), notes=list(tree.notes),
                          interpolation="linear in (ln PGA, ln rate)",
                          cells_per_interval=cells[2]),
        pgv_pga=ratio_described(ratio_model, {g.site: g.ratio_model for g in groups}),
        warnings=warnings,
        assumptions=ASSUMPTIONS + ([SITE_ASSUMPTION] if len(groups) > 1 else []),
        draws=draws, seed=seed, software=software_versions())
    figure = {"levels_m_s2": tree.levels_m_s2, "rates_per_yr": tree.rates_per_yr,
              "prior_weights": tree.weights, "posterior_weights": posterior[rule],
              "prior": prior_stats, "posterior": post_stats, "rule": rule,
              "ages": list(ages),
              "target_rates": TARGET_RATES, "branch_ids": tree.branch_ids,
              "branch_test": test}
    return summary, summary.branches, figure


def _site_rows(groups):
    """constrain.json's ``sites``: each site's specimens and, where it has its own, the
    PGV/PGA it took."""
    return [SiteRow(site=g.site, specimens=list(g.members),
                    pgv_pga=ABSENT if g.ratio_model is None else g.ratio_model.describe())
            for g in groups]


class AgeIntegration(Enum):
    """How the specimens' ages are integrated over (constrain.json's age_model)."""
    KNOWN = "known ages"
    ONE_FOR_ALL = "one uncertain age for all: integrated in closed form"
    MONTE_CARLO = f"differing uncertain ages: Monte Carlo over {AGE_SAMPLES} samples"


def _sites(tree, cells, groups, ages, rng, ratio_model):
    """(per site: members, its tree, its cells, its age integration and samples, its
    PGV/PGA model (its own or ``ratio_model``); the age integration reported: the most
    demanding of the sites')."""
    check_same_branches(groups)
    sites = [(g.members, g.tree, cells if g.tree is tree else
              cell_matrix(g.tree.levels_m_s2, g.tree.rates_per_yr),
              *_age_mode([ages[j] for j in g.members], rng),
              ratio_model if g.ratio_model is None else g.ratio_model) for g in groups]
    return sites, max((s[3] for s in sites), key=list(AgeIntegration).index)


def _singles(sites, specimens, ages):
    """ln P_s of each specimen alone at its site (n x B): one age each, no sampling."""
    out = np.empty((len(specimens), sites[0][1].size))
    for members, t, c, _, _, ratio_model in sites:
        for j in members:
            how, _ = _age_mode([ages[j]], None)
            out[j] = _log_survival(t, c, [[specimens[j]]], ratio_model, [ages[j]], how,
                                   None)[0][0]
    return out


def _age_mode(ages, rng):
    """(how ages are integrated, age samples (AGE_SAMPLES x n, years) or None)."""
    if all(a.fixed_yr is not None for a in ages):
        return AgeIntegration.KNOWN, None
    if all(a == ages[0] for a in ages):
        return AgeIntegration.ONE_FOR_ALL, None
    return (AgeIntegration.MONTE_CARLO,
            np.column_stack([a.draw(AGE_SAMPLES, rng) for a in ages]))


def _age_keys(age):
    """A specimen's age in constrain.json: survival.json's (:func:`~pipeline.hazard.
    survival_parts.age_keys`) but its age_distribution."""
    return {k: v for k, v in age_keys(age).items() if k != "age_distribution"}


def _log_survival(tree, cells, batch, ratio_model, ages, mode, samples):
    """(ln P_s, D x B, of each of the D fragility sets in ``batch`` (lists, one fragility
    per specimen), all integrated by one matrix product; its relative standard error
    (D x B) or None).  ``samples`` None: each age at its fixed or typical value (the
    fragility draws)."""
    def rates_of(subsets):
        return rates_by_ratio(cells, tree.levels_m_s2, tree.rates_per_yr, ratio_model,
                              lambda model: lambda x: subset_probabilities(batch, subsets,
                                                                           model, x))
    if mode is AgeIntegration.ONE_FOR_ALL:
        rate = rates_of([tuple(range(len(batch[0])))])[0]
        with np.errstate(divide="ignore"):
            return np.log(ages[0].survival(rate)), None
    if samples is None:
        return log_survival_fixed(rates_of, np.array(
            [a.typical_yr if a.fixed_yr is None else a.fixed_yr for a in ages])), None
    return log_survival_sampled(rates_of, samples)


def _none_left(rule: str, floor: float, tree: LogicTree, p: np.ndarray) -> str:
    """Why ``rule`` leaves no branch: every branch's survival probability ``p`` is 0
    (bayes) or below ``floor`` (eliminate), or only branches of weight 0 have more."""
    needed = p > 0 if rule == "bayes" else p >= floor
    spared = [b for b, ok, w in zip(tree.branch_ids, needed, tree.weights) if ok and w == 0]
    if spared:
        named = ", ".join(spared[:5]) + (f" and {len(spared) - 5} more" if len(spared) > 5
                                         else "")
        what = "above 0" if rule == "bayes" else f"of at least {floor:g}"
        return (f"only branches of weight 0 ({named}) give a survival probability {what}: "
                f"{'the Bayesian update' if rule == 'bayes' else 'elimination'} leaves no "
                "weight on any branch, no constrained curve under that rule")
    if rule == "bayes":
        return ("every branch gives the specimens a survival probability of 0: no Bayesian "
                "update (check the ages and the fragility)")
    return (f"every branch gives a survival probability below {floor:g}: elimination drops "
            "them all, no constrained curve under that rule")


BAND = (0.05, 0.95)            # the fractiles whose curves bound the band reported


def fractile_key(q):
    """The key of fractile ``q`` in a statistics' ``fractiles`` (constrain.json): ``%g``."""
    return f"{q:g}"


def fractile_curve(q):
    """The ``curve`` name of fractile ``q`` in ``ground_motion_at_rates``."""
    return f"fractile {fractile_key(q)}"


MEAN_CURVE = "mean"
BAND_CURVE = f"range {fractile_key(BAND[0])}-{fractile_key(BAND[1])}"


def _statistics(tree, weights):
    """Mean and fractile curves (annual rates) under ``weights``."""
    rates = tree.rates_per_yr
    return CurveStatistics(
        mean_rates_per_yr=weighted_mean(rates, weights).tolist(),
        fractiles={fractile_key(q): weighted_quantile(rates, weights, q).tolist()
                   for q in FRACTILES})


def _motions(tree, prior, posterior):
    """PGA at TARGET_RATES on the mean and each fractile curve, before and after."""
    rows = []
    curves = [(MEAN_CURVE, None)] + [(fractile_curve(q), fractile_key(q)) for q in FRACTILES]
    for rate in TARGET_RATES:
        for name, q in curves:
            before = _pga(tree, prior, q, rate)
            after = None if posterior is None else _pga(tree, posterior, q, rate)
            rows.append(_motion_row(rate, name, before, after))
        band = [fractile_key(q) for q in BAND]
        lo_b, hi_b = (_pga(tree, prior, q, rate) for q in band)
        lo_a, hi_a = (None, None) if posterior is None else \
            (_pga(tree, posterior, q, rate) for q in band)
        width_b = None if None in (lo_b, hi_b) else hi_b - lo_b
        width_a = None if None in (lo_a, hi_a) else hi_a - lo_a
        rows.append(_motion_row(rate, BAND_CURVE, width_b, width_a))
    return rows


def _motion_row(rate, curve, before, after):
    """PGA (m/s^2 or None) on ``curve`` at ``rate`` before and after, as a row."""
    return MotionAtRate(annual_rate_per_yr=rate, curve=curve, prior_m_s2=before,
                        posterior_m_s2=after, prior_g=_g(before), posterior_g=_g(after),
                        change_percent=change_percent(before, after))


def _pga(tree, stats, q, rate):
    """PGA (m/s^2) at ``rate`` on the mean (``q`` None) or the fractile ``q`` of ``stats``."""
    curve = stats.mean_rates_per_yr if q is None else stats.fractiles[q]
    return motion_at_rate(tree.levels_m_s2, np.asarray(curve), rate)


def _g(value):
    return None if value is None else value / STANDARD_GRAVITY


def _members(tree, specimens, survival_of, floor, warnings):
    """The weights under each member of the fragility and under their mixture, or None."""
    lists = [f.members() for f in specimens]
    counts = {len(m) for m in lists if m}
    if not counts:
        return None
    if len(counts) > 1:
        warnings.append(f"the specimens' fragilities have different numbers of members "
                        f"({sorted(counts)}): the members' spread not reported")
        return None
    count = counts.pop()
    log_ps = survival_of([[m[k] if m else f for m, f in zip(lists, specimens)]
                          for k in range(count)])[0]        # all members at once
    ps = np.exp(log_ps)
    mixture = ps.mean(axis=0)
    posteriors = [bayes(tree.weights, lp) for lp in log_ps]
    with np.errstate(divide="ignore"):
        mixed = bayes(tree.weights, np.log(mixture))
    at = {}
    for rate in TARGET_RATES:
        per = [None if w is None else motion_at_rate(tree.levels_m_s2,
                                                     weighted_mean(tree.rates_per_yr, w), rate)
               for w in posteriors]
        mix = None if mixed is None else motion_at_rate(
            tree.levels_m_s2, weighted_mean(tree.rates_per_yr, mixed), rate)
        known = [v for v in per if v is not None]
        at[f"{rate:g}"] = MemberMotion(
            mixture_g=_g(mix), per_member_g=[_g(v) for v in per],
            member_range_g=[_g(min(known)), _g(max(known))] if known else None)
    return Members(
        count=count, survival_per_member=ps.tolist(),
        posterior_bayes_per_member=[None if w is None else w.tolist() for w in posteriors],
        mixture=Mixture(survival_probability=mixture.tolist(),
                        posterior_bayes=None if mixed is None else mixed.tolist(),
                        posterior_eliminate=_list(eliminate(tree.weights, mixture, floor))),
        mean_ground_motion_at_rates=at)


def _draws(tree, cells, specimens, survival_of, draws, rng, floor):
    """The Monte Carlo error of the fragility: P_s, posterior weights and the posterior
    mean's PGA at TARGET_RATES over fragility draws (intervals), or None.  The draws are
    integrated in chunks of :func:`~pipeline.hazard.constrain.draw_chunk`, each chunk one
    matrix product (draws x cells times cells x branches)."""
    drawn = [f.draws(draws, rng) if draws else None for f in specimens]
    if all(d is None for d in drawn):
        return None
    sets = [[d[k] if d is not None else f for d, f in zip(drawn, specimens)]
            for k in range(draws)]
    chunk = draw_chunk(cells)
    log_ps = np.concatenate([survival_of(sets[i:i + chunk], sampled=False)[0]
                             for i in range(0, draws, chunk)])
    ps = np.exp(log_ps)
    posteriors = [bayes(tree.weights, lp) for lp in log_ps]
    usable = np.array([w for w in posteriors if w is not None])
    motion = {}
    for rate in TARGET_RATES:
        values = [motion_at_rate(tree.levels_m_s2, weighted_mean(tree.rates_per_yr, w), rate)
                  for w in usable]
        values = [v for v in values if v is not None]
        motion[f"{rate:g}"] = None if not values else \
            (np.percentile(values, INTERVAL) / STANDARD_GRAVITY).tolist()
    return MonteCarlo(
        draws=draws, survival_interval=np.percentile(ps, INTERVAL, axis=0).T.tolist(),
        posterior_bayes_interval=None if not len(usable) else
        np.percentile(usable, INTERVAL, axis=0).T.tolist(),
        posterior_mean_pga_g_interval_at_rates=motion,
        definition=f"{INTERVAL[0]:g}-{INTERVAL[1]:g} percentiles over {draws} draws of the "
                   "fragility's estimate (its Monte Carlo or fitting error)")


def _end_warnings(tree, cells, specimens, ratio_model, weights):
    """A warning when, for branches of weight, the last level holds much of the rate."""
    def probability_of(model):
        return lambda x: set_probabilities([specimens], model, x)[0]
    total = rates_by_ratio(cells, tree.levels_m_s2, tree.rates_per_yr, ratio_model,
                           probability_of)
    last = (tree.levels_m_s2[-1:], np.zeros((tree.size, 1)), 1)   # the last level's term
    top = rates_by_ratio(last, tree.levels_m_s2, tree.rates_per_yr, ratio_model,
                         probability_of)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(total > 0, top / total, 0.0)
    w = tree.weights if weights is None else weights
    held = float(w @ share)
    if held > END_SHARE_WARNING:
        return [f"{100 * held:.0f} % of the overturning rate (weighted over branches) lies at "
                "the curves' last level: extend the hazard curves (a lower bound on the rate)"]
    return []


def _list(array):
    return None if array is None else array.tolist()


def _branch_rows(tree, p, posterior, carlo, age_se):
    """Each branch's :class:`BranchRow`."""
    def weight(rule, k):
        return None if posterior[rule] is None else float(posterior[rule][k])
    return [BranchRow(
        branch=tree.branch_ids[k], path=tree.branch_paths[k],
        prior_weight=float(tree.weights[k]), survival_probability=float(p[k]),
        posterior_bayes=weight("bayes", k), posterior_eliminate=weight("eliminate", k),
        survival_age_se_relative=ABSENT if age_se is None else float(age_se[k]),
        survival_interval=ABSENT if carlo is None else carlo.survival_interval[k])
        for k in range(tree.size)]
