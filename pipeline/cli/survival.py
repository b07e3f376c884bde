"""``survival``: what a standing rock or column says about its site's hazard.

    python -m pipeline survival --site 0 --median-g 0.3 --beta 0.4 --age-ka 15 \\
        --age-sd-ka 3 --hazard records/hazard/oq_classical_case_14_hazard_curve-rlz-000_PGA.csv
    python -m pipeline survival --hazard curve.csv --fragility results/campaigns/fragility \\
        --column monolithic --pgv-pga-median 0.1 --pgv-pga-sigma 0.4 --age-ka 2.5

Writes ``survival.json`` and ``survival.png`` to ``--out`` (the workflow:
:mod:`pipeline.assessment.survival`).
"""
import math

from pipeline.cli._fields import add_arguments, from_args
from pipeline.files import display_path
from pipeline.hazard.ages import AgeKind
from pipeline.assessment.survival import survival_outputs
from pipeline.assessment.options import AGE_FLAGS, SurvivalOptions

NAME = "survival"
ORDER = 45
HELP = "survival of a standing specimen under a site's hazard curve: rate, probability, bounds"
DESCRIPTION = (
    "The annual rate at which a specimen (or a set at one site) overturns under a site's "
    "hazard curve, the probability that it survived its age, the contribution by intensity "
    "and the largest factor on the hazard's rates (and intensities) that leaves survival "
    ">= 5 %. Fragility: a stated lognormal over PGA (--median-g, --beta) or campaign "
    "fragility's fragility.json (--fragility) or a stated logistic surface in PGA and PGV/PGA "
    "(--logistic). The hazard: a PGA curve with PGV/PGA from one scenario or a "
    "disaggregation (--disaggregation), or OpenQuake's joint rate density of PGA and PGV "
    "(--joint-hazard). See docs/survival.md.")


def setup(p):
    """The flags of :class:`~pipeline.assessment.options.SurvivalOptions`, in the
    order of the help."""
    o = SurvivalOptions
    add_arguments(p, o, ("hazard", "joint_hazard", "site"))
    add_arguments(p, o, o.FRAGILITY_FLAGS)
    add_arguments(p.add_argument_group(o.AGE_GROUP), o, AGE_FLAGS)
    add_arguments(p.add_argument_group(o.RATIO_GROUP), o, o.RATIO_FLAGS)
    add_arguments(p.add_argument_group(o.OBSERVATION_GROUP), o,
                  ("observations", "observation_site", "state_lognormal", "at_pgv_pga"))
    add_arguments(p, o, (*o.DRAW_FLAGS, "out"))


def run(args):
    o = from_args(SurvivalOptions, args)
    summary, site_motion, age = survival_outputs(o)
    if summary is None:
        _print_site_motion(site_motion)
        print(f"wrote {display_path(o.out / 'site_motion.json')}")
        return 0
    for line in summary.warnings:
        print(f"warning: {line}")
    interval = summary.survival_interval
    print(f"overturning rate {summary.annual_overturning_rate_per_yr:.3g} /yr; survived "
          f"{_age_words(age)} with P = {summary.survival_probability:.3g}"
          + ("" if interval is None else f" [{interval[0]:.3g}, {interval[1]:.3g}]")
          + f"; hazard rates x {_g(summary.rate_scale_bound_5pct)} or intensities x "
          f"{_g(summary.intensity_scale_bound_5pct)} leave 5 %")
    for row in (summary.given("hazard_curves") or [])[1:]:
        print(f"under {row.kind or row.file}: rate {row.annual_overturning_rate_per_yr:.3g}"
              f" /yr, survival P = {row.survival_probability:.3g}")
    if site_motion is not None:
        _print_site_motion(site_motion)
    print(f"wrote {display_path(o.out / 'survival.json')} and survival.png")
    return 0


def _print_site_motion(result):
    lo, hi = result["pga_interval95_g"]
    ml = result["pga_ml_g"]
    print(f"site {result['site']}: {result['fallen']} of {result['columns']} columns fell; "
          f"PGA {'-' if ml is None else f'{ml:.3g}'} g, 95 % [{_g(lo)}, {_g(hi)}] g"
          + ("" if result["pgv_pga_s"] is None else f" at PGV/PGA {result['pgv_pga_s']:g} s")
          + ("" if result["note"] is None else f" ({result['note']})"))


def _g(value):
    return "-" if value is None or not math.isfinite(value) else f"{value:.3g}"


def _age_words(age):
    """The age as the command line gave it (ka)."""
    if age.kind is AgeKind.NORMAL:
        return f"{age.mean_yr / 1000:g} ka"
    if age.kind is AgeKind.LOWER_BOUND:
        return f"at least {age.min_yr / 1000:g} ka"
    if age.kind is AgeKind.INTERVAL:
        return f"{age.lo_yr / 1000:g}-{age.hi_yr / 1000:g} ka"
    return f"{len(age.ages_yr)} sampled ages (mean {age.typical_yr / 1000:.3g} ka)"
