"""What survival says under the joint hazard of PGA and PGV at one site (route (a):
OpenQuake's mean rate density, :class:`~pipeline.hazard.joint_hazard.JointHazard`):
``survival.json``'s content and its figure's arrays (:func:`assess_joint`).  The rate of
overturning is :func:`~pipeline.hazard.joint_survival.joint_overturning_rate`; a set at
the site overturns (any of it) with 1 - prod(1 - P_i) in each event, as on the scalar
route."""
import numpy as np

from pipeline.hazard.assess import BOUND_SURVIVAL, END_SHARE_WARNING, INTERVAL
from pipeline.hazard.hazard_described import JointHazardDescribed
from pipeline.hazard.joint_survival import cell_mean_probability, joint_overturning_rate
from pipeline.hazard.results import SurvivalResult
from pipeline.hazard.survival_parts import HazardRoute, Route, SpecimenResult, age_keys
from pipeline.hazard.survival import rate_scale_bound, survival_probability
from pipeline.provenance import software_versions

ASSUMPTIONS = [
    "Overturnings are a Poisson process in time: survival of age t is exp(-rate t); over "
    "an uncertain age, the mean of exp(-rate T) over its distribution.",
    "The joint hazard is OpenQuake's mean rate density of PGA and PGV at the site (mrd): "
    "the annual rate of events in each cell between consecutive levels of PGA and PGV; "
    "PGV/PGA in an event is PGV / PGA of that event (no ground-motion model, no "
    "correlation assumed here: the engine's calculation holds them).",
    "Inside a cell the events spread with a density log-linear in ln PGA and ln PGV, its "
    "slopes from the neighbouring cells; nothing below the first levels or above the last "
    "is counted (a lower bound on the rate; the shares in the top PGA row and PGV column "
    "say where the levels may cut it).",
    "A set of specimens at the site shares its earthquakes and overturns independently "
    "given the motion of one event: P(any overturns) = 1 - prod(1 - P_i) (common_shaking, "
    "the headline for a set).",
    "survival_interval: 95 % of the survival probabilities of fragility parameters drawn "
    "from the uncertainty of their estimate; the joint hazard taken as exact.",
]


def _set_probability(specimens):
    """P(any of ``specimens`` overturns) at (PGA m/s^2, PGV/PGA s), broadcast."""
    def probability(pga, ratio):
        survive = 1.0
        for f in specimens:
            survive = survive * (1.0 - f.probability(pga, ratio))
        return 1.0 - survive
    return probability


def _rate(joint, specimens):
    return joint_overturning_rate(joint.pga_levels_m_s2, joint.pgv_levels_m_s,
                                  joint.cell_rates_per_yr[0], _set_probability(specimens))


def _warnings(rate, what):
    out = []
    for share, where in ((rate.share_top_pga, "top PGA row"),
                         (rate.share_top_pgv, "top PGV column")):
        if share is not None and share > END_SHARE_WARNING:
            out.append(f"{what}{100 * share:.0f} % of the overturning rate lies in the joint "
                       f"hazard's {where}: its levels may cut the rate (extend them)")
    return out


def assess_joint(joint, specimens, age, draws, seed):
    """(survival.json as a :class:`SurvivalResult`, figure data dict) for ``specimens`` under the
    joint hazard ``joint`` of one site (``JointHazard.site(n)``) over the age ``age``
    (:class:`~pipeline.hazard.ages.AgeModel`)."""
    rng = np.random.default_rng(seed)
    drawn = [f.draws(draws, rng) if draws else None for f in specimens]
    headline = _rate(joint, specimens)
    rate = headline.rate_per_yr
    warnings = _warnings(headline, "" if len(specimens) == 1 else "set: ")
    entries = []
    for k, f in enumerate(specimens):
        one = _rate(joint, [f])
        warnings += _warnings(one, f"specimen {k}: ") if len(specimens) > 1 else []
        entries.append(SpecimenResult(
            fragility=f.describe(), annual_overturning_rate_per_yr=one.rate_per_yr,
            survival_probability=float(age.survival(one.rate_per_yr)),
            share_top_pga=one.share_top_pga, share_top_pgv=one.share_top_pgv))
    interval = None
    if all(d is not None for d in drawn):
        rates = [_rate(joint, list(group)).rate_per_yr for group in zip(*drawn)]
        interval = np.percentile(age.survival(np.array(rates)), INTERVAL).tolist()
    summary = SurvivalResult(
        hazard_route=HazardRoute(route=Route.JOINT, what="the joint hazard of PGA and PGV "
                                 "(OpenQuake mean rate density, mrd), PGV/PGA from each "
                                 "event"),
        annual_overturning_rate_per_yr=rate,
        survival_probability=float(age.survival(rate)),
        survival_interval=interval,
        **({} if interval is not None else {
            "survival_interval_note": "no uncertainty stated for the fragility" if draws
            else "--draws 0"}),
        rate_scale_bound_5pct=rate_scale_bound(rate, age, BOUND_SURVIVAL),
        intensity_scale_bound_5pct=None,
        intensity_scale_bound_note="not computed under a joint hazard",
        share_top_pga=headline.share_top_pga, share_top_pgv=headline.share_top_pgv,
        headline="the specimen" if len(specimens) == 1
        else "the set under common shaking (all survive)",
        **age_keys(age),
        specimens=entries,
        hazard=JointHazardDescribed(source=dict(joint.source), site=list(joint.sites[0]),
                                    pga_levels_m_s2=joint.pga_levels_m_s2.tolist(),
                                    pgv_levels_m_s=joint.pgv_levels_m_s.tolist(),
                                    investigation_time_yr=joint.investigation_time_yr,
                                    events_per_yr=headline.events_per_yr),
        pgv_pga=None, pgv_pga_used=any(f.uses_ratio for f in specimens),
        assumptions=ASSUMPTIONS, warnings=warnings,
        draws=draws, seed=seed, software=software_versions())
    return summary, _figure_data(joint, specimens, summary, age)


def _figure_data(joint, specimens, summary, age):
    """Arrays for :func:`pipeline.figures.survival.plot_survival`: the PGA curve the
    joint hazard holds (summed over PGV), P and the rate density per PGA cell."""
    cells = joint.cell_rates_per_yr[0]
    levels = joint.pga_levels_m_s2
    p = cell_mean_probability(levels, joint.pgv_levels_m_s, _set_probability(specimens),
                              cells)
    row_rate = cells.sum(axis=1)
    part = (cells * p).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        marginal = np.where(row_rate > 0, part / row_rate, np.nan)
    mid = np.sqrt(levels[:-1] * levels[1:])
    exceed = np.cumsum(row_rate[::-1])[::-1]
    band = age.band_yr
    ages = np.linspace(0.0, 2.0 * (age.typical_yr if band is None
                                   else age.typical_yr + 2.0 * (band[1] - age.typical_yr)), 200)
    rate = summary.annual_overturning_rate_per_yr
    return {"levels_m_s2": levels[:-1], "rates_per_yr": exceed, "probability_x": mid,
            "probability": marginal, "density_x": mid, "density": part / np.diff(np.log(levels)),
            "top_share": summary.share_top_pga,
            "ages_yr": ages, "survival": np.array([survival_probability(rate, a) for a in ages]),
            "age_yr": age.typical_yr, "age_band": band,
            "survival_probability": summary.survival_probability,
            "survival_interval": summary.survival_interval,
            "set": len(specimens) > 1, "pgv_pga_used": True}
