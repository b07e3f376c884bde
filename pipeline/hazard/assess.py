"""What survival says for one specimen or a set at one site: ``survival.json`` as a
:class:`~pipeline.hazard.results.SurvivalResult` and the arrays its figure draws
(:func:`assess`)."""
from dataclasses import replace

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.disagg_ratio import RatioMixture
from pipeline.hazard.survival import (contribution_by_intensity, intensity_scale_bound,
                                      overturning_rate, rate_density, rate_outside,
                                      rate_exceeding, rate_scale_bound,
                                      survival_probability)
from pipeline.hazard.hazard_described import CurveHazard
from pipeline.hazard.record import ABSENT
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.results import SurvivalResult
from pipeline.hazard.survival_parts import (ContributionRow, CurveEnds, CurveRow, HazardRoute,
                                            OutsideGrid, Route, SetSurvival, SiteSet,
                                            SpecimenResult, age_keys)
from pipeline.provenance import software_versions

BOUND_SURVIVAL = 0.05         # survival probability the bounds keep (the keys' 5pct)
INTERVAL = (2.5, 97.5)        # percentiles of the survival interval
END_SHARE_WARNING = 0.1       # warn when a curve's end holds more of the rate than this
REACH_WARNING = 2.0           # and beyond this x a grid's top PGA, when P above the grid
REACH_SHARE = 0.01            # could add more than this share of the rate

ASSUMPTIONS = [
    "Overturnings are a Poisson process in time: survival of age t is exp(-rate t).",
    "The hazard curve is interpolated linearly in (ln PGA, ln rate); no extrapolation: "
    "nothing below its first level, and every exceedance of its last level counted at the "
    "last level (a lower bound on the rate; what it could add is reported).",
    "An age is taken as dated (survival.json age): known; normal (mean, sd) truncated at "
    "0, uniform on an interval or samples from a file, integrated over: the survival "
    "probability is its mean over the age, not an interval; a lower bound taken as the "
    "age, so that the survival is an upper bound.",
    "PGV/PGA at each PGA level is lognormal (from the user, or from the ground-motion "
    "model at the stated magnitude and distance); the fragility is averaged over it.",
    "survival_interval: 95 % of the survival probabilities of fragility parameters drawn "
    "from the uncertainty of their estimate (parametric bootstrap); the PGV/PGA model is "
    "taken as exact, and each hazard curve too: the hazard's own uncertainty is the spread "
    "over the curves given (hazard_curves: e.g. an engine's mean and quantile curves).",
    "A pulse grid (campaign fragility --pulses) is read as its cells: P bilinear in (ln "
    "PGA, ln PGV/PGA) inside the grid, the logistic surface fitted to the same runs above "
    "and beside it, and below its first PGA the choice of --below-grid (fragility."
    "below_grid; default: P rising linearly in ln PGA from 0 at the uplift acceleration g "
    "tan(alpha) to the edge's P); its survival_interval is the cells' Monte Carlo error and "
    "survival_per_parameter_set the members' spread, reported apart.",
    "A fragility fitted to a campaign's pooled members (campaign fragility) holds the "
    "members' spread in its dispersion, as if each earthquake met another member; the rock "
    "or column has one set of the unknown contact parameters in every earthquake: "
    "survival_per_parameter_set gives the survival with each member's own fit (from the "
    "campaign's fragility_runs.csv) where it is determined.",
    "The fragility is read on the hazard curve's PGA (--hazard-component, RotD50 by "
    "default): a campaign's PGA (the horizontal vector peak, = RotD100) is converted with "
    "the ratio RotD50 / vector peak of its motions (fragility.pga_measure says which and "
    "where it comes from); PGV/PGA is taken as the same on both measures.  A stated "
    "fragility (--median-g, --logistic) is taken on the hazard's measure.",
    "A set of specimens shares one age and the site's earthquakes. common_shaking (the "
    "headline for a set): the specimens overturn independently given the motion of one "
    "event, P(all survive | PGA, PGV/PGA) = prod(1 - P_i); independent: each specimen meets "
    "its own earthquakes (survival = prod exp(-rate_i t)); fully_correlated: in an event "
    "the weakest specimen decides, P(any overturns) = max P_i.",
]


def assess(curve, specimens, ratio_model, age, draws, seed, more_curves=()):
    """(survival.json as a :class:`SurvivalResult`, figure data dict) for ``specimens``
    (:class:`~pipeline.hazard.fragility.kinds.Fragility` objects) at the site of ``curve``
    (:class:`~pipeline.hazard.curves.HazardCurve`); ``ratio_model``: the PGV/PGA model or
    None; ``age``: the specimens' age (:class:`~pipeline.hazard.ages.AgeModel`, years).
    ``more_curves``: further hazard curves of the site (e.g. quantiles): the headline
    again under each (``hazard_curves``)."""
    rng = np.random.default_rng(seed)
    drawn = [f.draws(draws, rng) if draws else None for f in specimens]
    warnings = list(curve.notes)
    entries = []
    for k, fragility in enumerate(specimens):
        entry, said = _specimen_entry(curve, fragility, drawn[k], ratio_model, age, draws)
        entries.append(entry)
        warnings += [f"specimen {k}: {w}" for w in said]
    headline, probability, members = _headline(curve, specimens, drawn, entries, ratio_model,
                                               age, warnings)
    curves = [_curve_row(curve, headline, specimens, ratio_model, age)] \
        if more_curves else []
    for k, other in enumerate(more_curves, start=1):
        result, said = _result(other, probability, members, age)
        warnings += [f"hazard curve {k}: {w}" for w in list(other.notes) + said]
        curves.append(_curve_row(other, result, specimens, ratio_model, age))
    times = sorted({c.source.get("investigation_time_yr") for c in (curve, *more_curves)}
                   - {None})
    if len(times) > 1:
        warnings.append(f"the hazard curves state investigation times of "
                        f"{', '.join(f'{t:g}' for t in times)} yr: each curve's probabilities "
                        "of exceedance converted to annual rates with its own T, "
                        "-ln(1 - poe) / T")
    summary = _summary(curve, specimens, entries, headline, ratio_model, warnings,
                       (age, draws, seed))
    if more_curves:
        survivals = [row.survival_probability for row in curves]
        summary = replace(summary, hazard_curves=curves,
                          survival_range_over_curves=[min(survivals), max(survivals)])
    if len(specimens) > 1:
        summary = replace(summary, site_set=_site_set(curve, specimens, ratio_model, entries,
                                                      age))
    figure = _figure_data(curve, probability, headline, drawn, age, specimens,
                          ratio_model)
    return summary, figure


def _specimen_entry(curve, fragility, drawn, ratio_model, age, draws):
    """(one specimen's entry of ``specimens``, a :class:`SpecimenResult`: its result,
    parameter sets and what comes from outside its grid; its warnings)."""
    def probability(x):
        return overturn_probability([fragility], ratio_model, x)[0]
    members = None if drawn is None else [
        (lambda x, f=d: overturn_probability([f], ratio_model, x)[0]) for d in drawn]
    result, warnings = _result(curve, probability, members, age)
    rate = result["annual_overturning_rate_per_yr"]
    described = fragility.describe()
    outside = _outside_grid(curve, fragility, ratio_model, probability, rate)
    entry = SpecimenResult(
        fragility=described, **result,
        **_per_parameter_set(curve, fragility, ratio_model, age),
        outside_grid=ABSENT if outside is None else outside,
        survival_interval_note=ABSENT if drawn is not None else
        "no uncertainty stated for this fragility" if draws else "--draws 0")
    if outside is None:
        return entry, warnings
    warnings += _above_grid_warning(outside, described, rate)
    for side, share in (("below", outside.share_below_grid),
                        ("above", outside.share_above_grid)):
        if share is not None and share > END_SHARE_WARNING:
            warnings.append(
                f"{100 * share:.0f} % of the overturning rate comes from PGA {side} the "
                "fragility's grid" + (f" (rate {outside.rate_per_yr_zero_below_grid:.3g}"
                                      f" to {outside.rate_per_yr_edge_held_below_grid:.3g}"
                                      " /yr with P = 0 or the edge's P below it)"
                                      if side == "below" else ""))
    return entry, warnings


def _headline(curve, specimens, drawn, entries, ratio_model, age, warnings):
    """(headline result, its probability function, its draws' functions or None): the
    specimen's entry, or the set's under common shaking (its warnings added)."""
    if len(specimens) == 1:
        members = None if drawn[0] is None else [_combined([d], ratio_model, "each")
                                                 for d in drawn[0]]
        return _result_of(entries[0]), _combined(specimens, ratio_model, "each"), members
    probability = _combined(specimens, ratio_model, "any_common")
    members = None
    if all(d is not None for d in drawn):
        members = [_combined(list(group), ratio_model, "any_common") for group in zip(*drawn)]
    headline, said = _result(curve, probability, members, age)
    warnings += [f"set: {w}" for w in said]
    return headline, probability, members


def _result_of(entry):
    """The fields of :func:`_result` of a specimen's entry (its headline)."""
    return {k: getattr(entry, k) for k in (
        "annual_overturning_rate_per_yr", "survival_probability", "survival_interval",
        "rate_scale_bound_5pct", "intensity_scale_bound_5pct", "contribution_by_intensity",
        "curve_ends")}


def _summary(curve, specimens, entries, headline, ratio_model, warnings, run):
    """survival.json but for hazard_curves and site_set; ``run``: (age model,
    draws, seed)."""
    age, draws, seed = run
    one = len(specimens) == 1
    return SurvivalResult(
        hazard_route=HazardRoute(route=Route.CURVE, what="the PGA hazard curve, PGV/PGA at "
                                 "each PGA level " + (
                                     "a mixture over the magnitude-distance disaggregation's "
                                     "bins (the ground-motion model at each)"
                                     if isinstance(ratio_model, RatioMixture) else
                                     "lognormal (stated, or one scenario's ground-motion "
                                     "model)")),
        annual_overturning_rate_per_yr=headline["annual_overturning_rate_per_yr"],
        survival_probability=headline["survival_probability"],
        survival_interval=headline["survival_interval"],
        **({} if headline["survival_interval"] is not None else {
            "survival_interval_note": "no uncertainty stated for the fragility" if draws
            else "--draws 0"}),
        **({k: getattr(entries[0], k) for k in ("survival_per_parameter_set",
                                                "survival_parameter_set_range",
                                                "outside_grid")} if one else {}),
        rate_scale_bound_5pct=headline["rate_scale_bound_5pct"],
        intensity_scale_bound_5pct=headline["intensity_scale_bound_5pct"],
        contribution_by_intensity=headline["contribution_by_intensity"],
        curve_ends=headline["curve_ends"],
        headline="the specimen" if one else "the set under common shaking (all survive)",
        **age_keys(age),
        definitions=_definitions(draws),
        specimens=entries,
        hazard=CurveHazard(source=dict(curve.source), levels_m_s2=curve.levels_m_s2.tolist(),
                           levels_g=(curve.levels_m_s2 / STANDARD_GRAVITY).tolist(),
                           rates_per_yr=curve.rates_per_yr.tolist(), notes=list(curve.notes),
                           interpolation="linear in (ln PGA, ln rate)"),
        pgv_pga=None if ratio_model is None else ratio_model.describe(),
        pgv_pga_used=any(f.uses_ratio for f in specimens),
        assumptions=ASSUMPTIONS, warnings=warnings,
        draws=draws, seed=seed, software=software_versions())


def _definitions(draws):
    """survival.json's ``definitions``."""
    return {
        "annual_overturning_rate_per_yr": "integral of P(overturn | PGA) |d lambda(PGA)| "
        "over the hazard curve, 1/yr",
        "survival_probability": "mean over the age of exp(-rate t)",
        "survival_interval": f"{INTERVAL[0]:g}-{INTERVAL[1]:g} percentiles over "
        f"{draws} draws of the fragility's estimate (parametric bootstrap: of its "
        "fitted parameters, or for a pulse grid of every cell's count, Binomial(n, P): "
        "the Monte Carlo error), or null",
        "survival_per_parameter_set": "the survival probability with each parameter "
        "set's own fragility: a pulse grid's P per set in every cell, or a column "
        "campaign member's own fit (the specimen has one set of the unknown contact "
        "parameters in every earthquake)",
        "outside_grid": "a pulse grid: the rate of overturning from PGA below the "
        "grid's first PGA and above its last (on the hazard's PGA), their shares, and "
        "the rate with P = 0 below the grid (lower bound) and with the edge's P held "
        "down to the uplift acceleration (upper bound); above the grid: the hazard "
        "curve's last level and its ratio to the grid's top PGA, the rate of PGA above "
        "the grid's top on the curve, the rate of overturning with P = 1 above the grid "
        "(an upper bound) and how P is extended there (p_above_grid)",
        "hazard_curves": "the headline under each hazard curve given (--hazard "
        "repeated), the first being the headline's; survival_range_over_curves: min "
        "and max of their survival probabilities",
        "survival_parameter_set_range": "min and max of survival_per_parameter_set: "
        "the members' spread, reported apart from the Monte Carlo error",
        "rate_scale_bound_5pct": "largest factor F on every rate of the hazard curve "
        f"with survival >= {BOUND_SURVIVAL:g} (-ln {BOUND_SURVIVAL:g} / (rate t) for a "
        "fixed age)",
        "intensity_scale_bound_5pct": "largest factor c on the curve's PGA levels "
        f"(lambda_c(x) = lambda(x / c)) with survival >= {BOUND_SURVIVAL:g}; null with a "
        "note when outside 0.001-1000",
        "contribution_by_intensity": "the rate of overturning by PGA interval of the "
        "curve (m/s^2; the last row: exceedances of the last level) and its share"}


def _combined(specimens, ratio_model, combine):
    def probability(x):
        p = overturn_probability(specimens, ratio_model, x, combine)
        return p[0] if combine == "each" else p
    return probability


def _result(curve, probability, members, age):
    """(Rate, survival, interval, bounds, contributions and curve ends of one probability
    function: the fields of a :class:`SpecimenResult` but its fragility; its warnings)."""
    zero = curve.zero_rate_from_m_s2
    rate = overturning_rate(curve.levels_m_s2, curve.rates_per_yr, probability, zero)
    total = rate["rate_per_yr"]
    survival = float(age.survival(total))
    interval = None
    if members:
        rates = np.array([overturning_rate(curve.levels_m_s2, curve.rates_per_yr, p,
                                           zero)["rate_per_yr"] for p in members])
        interval = np.percentile(age.survival(rates), INTERVAL).tolist()
    bound_c, bound_note = intensity_scale_bound(curve.levels_m_s2, curve.rates_per_yr,
                                                probability, age, BOUND_SURVIVAL, zero)
    contribution = contribution_by_intensity(curve.levels_m_s2, curve.rates_per_yr,
                                             probability)
    warnings = []
    for key, where in (("share_first_interval", "first interval"),
                       ("share_at_last_level", "last level")):
        if rate[key] is not None and rate[key] > END_SHARE_WARNING:
            warnings.append(f"{100 * rate[key]:.0f} % of the overturning rate lies at the "
                            f"curve's {where}: extend the hazard curve")
    if rate["last_level_could_add_per_yr"] > END_SHARE_WARNING * max(total, 1e-300):
        warnings.append("exceedances of the last level could add "
                        f"{rate['last_level_could_add_per_yr']:.3g} /yr to the rate "
                        f"{total:.3g} /yr: extend the hazard curve")
    return {"annual_overturning_rate_per_yr": total, "survival_probability": survival,
            "survival_interval": interval,
            "rate_scale_bound_5pct": rate_scale_bound(total, age, BOUND_SURVIVAL),
            "intensity_scale_bound_5pct": bound_c,
            **({"intensity_scale_bound_note": bound_note} if bound_note else {}),
            "contribution_by_intensity": [ContributionRow.of(row) for row in contribution],
            "curve_ends": CurveEnds(**{k: v for k, v in rate.items() if k != "rate_per_yr"})
            }, warnings


def _curve_row(curve, result, specimens, ratio_model, age):
    """One hazard curve's row of ``hazard_curves``: the curve and the headline under it."""
    source = curve.source
    sets = _per_parameter_set(curve, specimens[0], ratio_model, age) \
        if len(specimens) == 1 else {}
    return CurveRow(
        **{k: source.get(k) for k in ("file", "format", "kind", "site_index",
                                      "investigation_time_yr")},
        **{k: result[k] for k in ("annual_overturning_rate_per_yr", "survival_probability",
                                  "survival_interval", "rate_scale_bound_5pct",
                                  "intensity_scale_bound_5pct")},
        survival_parameter_set_range=sets.get("survival_parameter_set_range", ABSENT))


def _per_parameter_set(curve, fragility, ratio_model, age):
    """Survival with each parameter set's own fragility (a pulse grid's sets, a column
    campaign's members), else nothing."""
    members = fragility.members()
    if not members:
        return {}
    zero = curve.zero_rate_from_m_s2
    rates = [overturning_rate(curve.levels_m_s2, curve.rates_per_yr,
                              lambda x, f=m: overturn_probability([f], ratio_model, x)[0],
                              zero)["rate_per_yr"] for m in members]
    survival = age.survival(np.array(rates)).tolist()
    return {"rate_per_parameter_set_per_yr": rates, "survival_per_parameter_set": survival,
            "survival_parameter_set_range": [min(survival), max(survival)]}


def _outside_grid(curve, fragility, ratio_model, probability, rate):
    """How much of the rate comes from outside a pulse grid's PGA range, and the rate
    with P = 0 below it and with the edge's P held below it; nothing for other forms."""
    grid = fragility.grid_range()
    if grid is None:
        return None
    lo, hi = grid
    below, above = rate_outside(curve.levels_m_s2, curve.rates_per_yr, probability, lo, hi)
    zero = curve.zero_rate_from_m_s2
    bounds = {name: overturning_rate(
        curve.levels_m_s2, curve.rates_per_yr,
        lambda x, f=variant: overturn_probability([f], ratio_model, x)[0], zero)["rate_per_yr"]
        for name, variant in fragility.variants().items()}
    last = float(curve.levels_m_s2[-1])
    beyond = rate_exceeding(curve.levels_m_s2, curve.rates_per_yr, hi)
    return OutsideGrid(
        pga_range_m_s2=[lo, hi], pga_range_g=[lo / STANDARD_GRAVITY, hi / STANDARD_GRAVITY],
        rate_below_grid_per_yr=below, rate_above_grid_per_yr=above,
        share_below_grid=below / rate if rate > 0 else None,
        share_above_grid=above / rate if rate > 0 else None,
        rate_per_yr_zero_below_grid=bounds["zero"],
        rate_per_yr_edge_held_below_grid=bounds["edge"],
        hazard_last_level_g=last / STANDARD_GRAVITY,
        hazard_reach_over_grid_top=last / hi,
        hazard_rate_above_grid_per_yr=beyond,
        rate_per_yr_one_above_grid=rate - above + max(beyond, above),
        p_above_grid=fragility.describe().get("above_grid"))


def _above_grid_warning(outside, described, rate):
    """A warning (list of one line, or empty) when the survival rests on P above a pulse
    grid: P = 1 above it would add more than END_SHARE_WARNING of the rate, or more than
    REACH_SHARE with the hazard curve reaching beyond REACH_WARNING x the grid's top PGA
    (P held at 1 above the grid adds nothing: no warning)."""
    could_add = outside.rate_per_yr_one_above_grid - rate
    reach = outside.hazard_reach_over_grid_top
    if not (could_add > END_SHARE_WARNING * rate
            or (reach > REACH_WARNING and could_add > REACH_SHARE * rate)):
        return []
    top = outside.pga_range_g[1]
    how = (described.get("above_grid") or {}).get("summary", "P extended above it")
    return [f"the hazard curve reaches {outside.hazard_last_level_g:.3g} g, {reach:.3g} x "
            f"the grid's top PGA {top:.3g} g (on the hazard's PGA); above it {how}; PGA above "
            f"{top:.3g} g has the "
            f"rate {outside.hazard_rate_above_grid_per_yr:.3g} /yr against the overturning "
            f"rate {rate:.3g} /yr (P = 1 above the grid: "
            f"{outside.rate_per_yr_one_above_grid:.3g} /yr)"]


def _site_set(curve, specimens, ratio_model, entries, age):
    """Survival of all specimens of a set under the three assumptions of ASSUMPTIONS."""
    zero = curve.zero_rate_from_m_s2
    rates = {"independent": sum(e.annual_overturning_rate_per_yr for e in entries)}
    for name, combine in (("common_shaking", "any_common"),
                          ("fully_correlated", "any_correlated")):
        rates[name] = overturning_rate(curve.levels_m_s2, curve.rates_per_yr,
                                       _combined(specimens, ratio_model, combine),
                                       zero)["rate_per_yr"]
    return SiteSet(**{name: SetSurvival(
        annual_rate_any_overturns_per_yr=rate,
        survival_probability_all=float(age.survival(rate)),
        rate_scale_bound_5pct=rate_scale_bound(rate, age, BOUND_SURVIVAL))
        for name, rate in rates.items()})


def _figure_data(curve, probability, headline, drawn, age, specimens, ratio_model):
    """Arrays for :func:`pipeline.figures.survival.plot_survival`."""
    x, density = rate_density(curve.levels_m_s2, curve.rates_per_yr, probability)
    band = age.band_yr
    ages = np.linspace(0.0, 2.0 * (age.typical_yr if band is None
                                   else age.typical_yr + 2.0 * (band[1] - age.typical_yr)), 200)
    rate = headline["annual_overturning_rate_per_yr"]
    survival = np.array([survival_probability(rate, a) for a in ages])
    return {"levels_m_s2": curve.levels_m_s2, "rates_per_yr": curve.rates_per_yr,
            "probability_x": x, "probability": probability(x), "density_x": x,
            "density": density,
            "top_share": headline["contribution_by_intensity"][-1].share,
            "ages_yr": ages, "survival": survival, "age_yr": age.typical_yr, "age_band": band,
            "survival_probability": headline["survival_probability"],
            "survival_interval": headline["survival_interval"],
            "set": len(specimens) > 1, "pgv_pga_used": any(f.uses_ratio for f in specimens)}
