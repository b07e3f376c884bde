"""REPORT section of ``survival`` (``make rock-survival`` writes results/rock-survival)."""
import pandas as pd

from pipeline.hazard.ratio_described import ScenarioRatio
from pipeline.hazard.results import read_survival_result
from pipeline.report.common import _figure, _fmt, _table

ROCK_SURVIVAL = "rock-survival"


def survival_section(results, name=ROCK_SURVIVAL):
    """The scanned rock under an example hazard curve: rate, survival with its Monte Carlo
    interval and the parameter sets' spread, bounds, contribution by PGA, figure."""
    heading = "Scanned rock survival under an example hazard curve"
    path = results / name / "survival.json"
    if not path.is_file():
        return (f"## {heading}\n\nNot run yet (`make rock-survival`: SP1's pulse-grid "
                "fragility under the USGS 2014 hazard curve at 34 N, 118 W).\n")
    s = read_survival_result(path)
    specimen = s.specimens[0]
    fragility, hazard, ratio = specimen.fragility, s.hazard, s.pgv_pga
    interval = s.survival_interval
    sets = s.given("survival_parameter_set_range")
    lines = [f"## {heading}\n",
             f"Fragility: {fragility['label']} ({fragility.get('inside', fragility['form'])}"
             f"; outside the grid: {fragility.get('outside', '-')}). Hazard: "
             f"{hazard.format or ''} `{hazard.file or ''}`" + _where(hazard.source)
             + (f"; PGV/PGA from {ratio.model} at M {ratio.magnitude:g}, "
                f"{ratio.distance_jb_km:g} km" if isinstance(ratio, ScenarioRatio) else "")
             + f". Age {_age(s)}.\n",
             f"Annual overturning rate {s.annual_overturning_rate_per_yr:.3g} /yr; "
             f"survival probability {s.survival_probability:.3g}"
             + ("" if interval is None else
                f" (Monte Carlo 95 %: {interval[0]:.3g}-{interval[1]:.3g})")
             + ("" if sets is None else
                f"; per parameter set {sets[0]:.3g}-{sets[1]:.3g} (the members' spread)")
             + f". Hazard rates x {_fmt(s.rate_scale_bound_5pct, 3)} or PGA levels x "
             f"{_fmt(s.intensity_scale_bound_5pct, 3)} leave survival at 5 %.\n"]
    measure, below = fragility.get("pga_measure"), fragility.get("below_grid")
    outside = s.given("outside_grid")
    if measure is not None:
        lines.append(f"PGA on the hazard curve's {measure['hazard']}: the fragility's PGA "
                     f"({measure['fragility']}) times {measure['fraction']:.3f} "
                     f"({measure['source']}).\n")
    if below is not None and outside is not None:
        share = outside.share_below_grid
        lines.append(f"Below the grid's first PGA ({below['first_pga_g']:.3g} g): "
                     f"{below['definition']}; "
                     + ("" if share is None else f"{100 * share:.1f} % of the rate comes "
                        "from there, ")
                     + f"the rate {outside.rate_per_yr_zero_below_grid:.3g} to "
                     f"{outside.rate_per_yr_edge_held_below_grid:.3g} /yr with P = 0 or "
                     "the edge's P held there.\n")
    rows = [{"PGA (g)": f"{r.lo_g:.3g}-" + ("" if r.hi_g is None else f"{r.hi_g:.3g}"),
             "rate (1/yr)": f"{r.rate_per_yr:.3g}",
             "share": "-" if r.share is None else f"{100 * r.share:.1f} %"}
            for r in s.given("contribution_by_intensity") or ()   # none on the joint route
            if (r.share or 0) >= 0.01]
    if rows:
        lines.append("Contribution by PGA (intervals holding 1 % or more of the rate):\n")
        lines.append(_table(pd.DataFrame(rows)) + "\n")
    for w in s.warnings:
        lines.append(f"Warning: {w}\n")
    lines.append(_figure(results, results / name / (s.given("figure") or "survival.png"),
                         "hazard curve and fragility, fragility-weighted rate density, "
                         "survival against age"))
    return "\n".join(lines)


def _where(source):
    """ at lat N/S, lon E/W of a hazard's ``source`` (the loader's; none for a plain table)."""
    lat, lon = source.get("lat"), source.get("lon")
    if lat is None:
        return ""
    return (f" at {abs(lat):g} {'N' if lat >= 0 else 'S'}, "
            f"{abs(lon):g} {'E' if lon >= 0 else 'W'}")


def _age(summary):
    """survival.json's age in words: mean +- sd (ka), or its distribution."""
    if summary.age_ka is not None:
        return f"{summary.age_ka:g} +- {summary.age_sd_ka:g} ka"
    return summary.age_distribution
