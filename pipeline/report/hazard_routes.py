"""REPORT section comparing the routes to the joint hazard of PGA and PGV at one site: the
survival and the constrained hazard of one rock under (a) OpenQuake's mean rate density
of PGA and PGV, (b) the PGA curve with PGV given PGA over its magnitude-distance
disaggregation and (c) the PGA curve with PGV given PGA from one scenario
(``make run-all`` writes results/hazard-routes/<route>-survival and -constrain).  Under
(a) and (b) ``constrain`` gives each branch its own realisation's PGV/PGA where the input
holds it, the mean's otherwise: the table says which."""
import pandas as pd

from pipeline.hazard.ratio_described import (DensityRatio, GroupsRatio, MixtureRatio,
                                              ScenarioRatio, SitesRatio)
from pipeline.hazard.record import ABSENT
from pipeline.hazard.results import read_constrain_result, read_survival_result
from pipeline.report.common import _table

HAZARD_ROUTES = "hazard-routes"
HEADING = "Three routes to the joint hazard of PGA and PGV at one site"
# (directory prefix, the route in words); the files hold what each route took
ROUTES = (("joint", "(a) mean rate density of PGA and PGV (OpenQuake `mrd`)"),
          ("disaggregation", "(b) PGA curve, PGV given PGA over the magnitude-distance "
                             "disaggregation"),
          ("scenario", "(c) PGA curve, PGV given PGA from one scenario"))
RATE = 1e-4             # the annual rate at which the constrained mean's PGA is shown
CASE = ("OpenQuake's quality-assurance case `postproc/case_mrd` "
        "(`records/hazard/openquake_postproc_case_mrd/`: one site, one source zone, two "
        "ground-motion branches; a test input of the engine, not the hazard at that place)")


def hazard_routes_section(results):
    """Survival and constrained hazard under each route, from the files of each run; a
    route not run says so."""
    root = results / HAZARD_ROUTES
    lines = [f"## {HEADING}\n",
             f"Double Rock's fragility at the reduced size of `make run-all` (the field rock "
             f"section) at the one site of {CASE}; the same rock, age and PGA curve under "
             "each route, only the PGV that goes with each PGA differs.\n"]
    if not any((root / f"{name}-survival" / "survival.json").is_file() for name, _ in ROUTES):
        return "\n".join(lines + ["Not run yet (`make run-all`).\n"])
    lines += ["### Survival\n", _table(pd.DataFrame(
        [_survival_row(root / f"{name}-survival" / "survival.json", words)
         for name, words in ROUTES])) + "\n"]
    lines += ["### Constrained hazard\n",
              "Each branch's PGV/PGA given PGA (its own realisation's, or the mean's for "
              "every branch), its chance that the rock fell within its age (1 - P_s) and "
              f"its weight after Bayes' rule; the mean curve's PGA at {RATE:g} /yr before "
              "and after.\n",
              _table(pd.DataFrame(
                  [row for name, words in ROUTES
                   for row in _constrain_rows(root / f"{name}-constrain" / "constrain.json",
                                              words)])) + "\n"]
    return "\n".join(lines)


def _survival_row(path, words):
    if not path.is_file():
        return {"route": words, "PGV/PGA from": "not run", "overturning rate (1/yr)": "-",
                "1 - survival": "-", "Monte Carlo 95 % of 1 - survival": "-"}
    s = read_survival_result(path)
    interval = s.survival_interval
    return {"route": words, "PGV/PGA from": _ratio_words(s.pgv_pga),
            "overturning rate (1/yr)": f"{s.annual_overturning_rate_per_yr:.3g}",
            "1 - survival": f"{1 - s.survival_probability:.3g}",
            "Monte Carlo 95 % of 1 - survival": "-" if interval is None else
            f"{1 - interval[1]:.3g}-{1 - interval[0]:.3g} ({s.draws} draws)"}


def _constrain_rows(path, words):
    if not path.is_file():
        return [{"route": words, "branch": "-", "PGV/PGA from": "not run", "prior weight": "-",
                 "1 - P_s": "-", "Bayes weight": "-", f"mean PGA at {RATE:g} /yr (g)": "-"}]
    c = read_constrain_result(path)
    mean = next((r for r in c.ground_motion_at_rates
                 if r.curve == "mean" and r.annual_rate_per_yr == RATE), None)
    motion = "-" if mean is None or mean.prior_g is None else \
        f"{mean.prior_g:.4g} -> {mean.posterior_g:.4g}"
    return [{"route": words if k == 0 else "", "branch": f"{b.branch} {b.path}",
             "PGV/PGA from": _branch_words(c.pgv_pga, k),
             "prior weight": f"{b.prior_weight:.3g}",
             "1 - P_s": f"{1 - b.survival_probability:.3g}",
             "Bayes weight": f"{b.posterior_bayes:.6g}",
             f"mean PGA at {RATE:g} /yr (g)": motion if k == 0 else ""}
            for k, b in enumerate(c.branches)]


def _branch_words(ratio, k):
    """What branch ``k``'s PGV/PGA came from (constrain.json's pgv_pga), in a few words."""
    match ratio:
        case SitesRatio():
            return ("each site's own rate density, "
                    + ("its own realisation's" if ratio.per_branch else
                       "the mean's for every branch"))
        case GroupsRatio():
            return f"{_ratio_words(ratio.group_of(k))}, its own realisation's"
        case MixtureRatio() | DensityRatio() if ratio.per_branch is not ABSENT:
            return f"{_ratio_words(ratio)}, " + (
                "its own realisation's" if ratio.per_branch else "the mean's for every branch")
    return _ratio_words(ratio)


def _ratio_words(ratio):
    """What the file says PGV/PGA came from (one route's record, or None), in a few
    words."""
    match ratio:
        case None:
            return "each event of the rate density"
        case MixtureRatio():
            return f"{ratio.bins_used} magnitude-distance bins"
        case DensityRatio():
            return "rate density"
        case ScenarioRatio():
            return (f"M {ratio.magnitude:g}, {ratio.distance_jb_km:g} km, correlation "
                    f"{ratio.pga_pgv_correlation:g}")
    return ratio.source
