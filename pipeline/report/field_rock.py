"""REPORT section of the field rock Double Rock: its fragility over a pulse grid, its
survival and the logic tree its survival constrains (``make field-rock`` writes
results/field-rock-*; ``make run-all`` the same at a reduced size, results/field-rock-quick-*)."""
import pandas as pd

from pipeline.hazard.constrain_assess import BAND_CURVE, MEAN_CURVE, fractile_curve
from pipeline.hazard.fragility.file import read_fragility_file
from pipeline.hazard.results import read_constrain_result
from pipeline.report.fragility import rock_fragility_section
from pipeline.report.common import _figure, _fmt, _table
from pipeline.report.hazard import survival_section

FIELD_ROCK = "field-rock"
FIELD_ROCK_QUICK = "field-rock-quick"
MOTION_ROWS = (MEAN_CURVE, fractile_curve(0.5), BAND_CURVE)   # the rows REPORT shows
HEADINGS = {FIELD_ROCK: "Field rock: Double Rock",
            FIELD_ROCK_QUICK: "Field rock at a reduced size: Double Rock"}
NO_PUBLISHED = ("No published fragility exists for this rock to compare with: its providers "
                "(Chen et al. 2024, Seismica 3(1)) use the mesh to demonstrate their simulator "
                "and report no overturning surface for it.")
HAZARD_NOTE = ("The hazard is illustrative, not Arizona's: the OpenQuake engine's logic-tree "
               "quality-assurance case 19 (`records/hazard/openquake_logictree_case_19/`: "
               "\"SHARE OpenQuake Computational Settings\", four sources of the SHARE model of "
               "the Ionian region around a site in Calabria, southern Italy; 16 branches, 4 "
               "in-slab x 4 interface ground-motion models; the engine's curves from its "
               "unchanged test input), a test of the engine, not the hazard at that site. The "
               "numbers below show what the toolkit does with a rock's survival, not the "
               "hazard at Granite Dells.")


def field_rock_section(results, prefix=FIELD_ROCK):
    """Double Rock's fragility, survival and constrained hazard (``prefix``-fragility,
    -survival, -constrain under ``results``), each part saying when it has not run."""
    heading = HEADINGS.get(prefix, f"Field rock ({prefix})")
    full = "`make field-rock`"
    if prefix == FIELD_ROCK:
        size, command = f"Full size: {full} (docs/field-rock.md).", full
    else:
        size = ("Reduced size, as `make run-all` runs it (the same 4 parameter sets x 4 "
                "directions over a coarser pulse grid, 6 x 4 cells: coarser contours); the "
                f"full size is {full}.")
        command = "`make run-all`"
    lines = [f"## {heading}\n",
             "Double Rock, a precariously balanced granite rock of the Granite Dells, "
             "Arizona (`records/field_rocks/double_rock/`: the Virtual Shake Robot's mesh, "
             "1437.6 kg), shaken by one-cosine pulses from directions sampled over 360 deg "
             f"(the field default). {size} {NO_PUBLISHED}\n", HAZARD_NOTE + "\n"]
    fragility = results / f"{prefix}-fragility" / "fragility.json"
    if fragility.is_file():
        lines.append("### Fragility\n")
        lines.append(_cost(read_fragility_file(fragility)))
        lines.append(_demote(rock_fragility_section(results, f"{prefix}-fragility")))
    else:
        lines.append(f"Fragility: not run yet ({command}).\n")
    if (results / f"{prefix}-survival" / "survival.json").is_file():
        lines.append("### Survival\n")
        lines.append(_demote(survival_section(results, f"{prefix}-survival")))
    else:
        lines.append(f"Survival: not run yet ({command}).\n")
    lines.append(constrain_part(results, f"{prefix}-constrain", command))
    return "\n".join(lines)


def _cost(summary):
    """What the adaptive design ran against the full grid, and its YADE time."""
    grid = summary.pulse_grid
    runs, full = grid.runs, grid.full_grid_runs
    if runs is None or full is None or runs == 0:       # 0 runs: nothing to compare
        return ""
    return (f"Cost: {runs} runs of the full grid's {full} ({full / runs:.1f} times fewer; "
            f"{(grid.sampling or '').split(':')[0]}), "
            f"{(grid.yade_wall_s_total or 0) / 60:.1f} min of YADE wall time summed over "
            "the runs.\n")


def _demote(text):
    """A section's body one heading level down, without its own ``## `` heading."""
    body = text.split("\n")
    if body and body[0].startswith("## "):
        body = body[1:]
    return "\n".join("#" + line if line.startswith("#") else line for line in body)


def constrain_part(results, name, command):
    """The logic tree reweighted by the rock's survival (constrain.json): the weights per
    branch, the mean and the 5-95 % range at the stated rates, the warnings."""
    path = results / name / "constrain.json"
    if not path.is_file():
        return f"Constrained hazard: not run yet ({command}).\n"
    c = read_constrain_result(path)
    ages = ", ".join(f"{s.age_ka:g} +- {s.age_sd_ka:g} ka" for s in c.specimens)
    lines = ["### Constrained hazard\n",
             f"{c.branch_count} branches; age {ages} (assumed for the demonstration); "
             f"headline rule `{c.rule}`. " + c.headline + "\n"]
    rows = [{"branch": b.branch, "path": b.path, "prior weight": _fmt(b.prior_weight, 3),
             "P_s": f"{b.survival_probability:.3g}", "Bayes": _fmt(b.posterior_bayes, 3),
             "elimination": _fmt(b.posterior_eliminate, 3)}
            for b in c.branches]
    lines.append(_table(pd.DataFrame(rows)) + "\n")
    best = max(b.survival_probability for b in c.branches)
    floor = c.floor
    if best < floor:
        lines.append(f"Under every branch the rock's survival of its age is below "
                     f"{floor:g} (at most {best:.2g}): this hazard is too high for a rock of "
                     "this fragility and age, and the reweighting ranks branches that are all "
                     "unlikely.\n")
    motion = [{"annual rate (1/yr)": f"{r.annual_rate_per_yr:g}", "curve": r.curve,
               "prior (g)": _fmt(r.prior_g, 3), "constrained (g)": _fmt(r.posterior_g, 3),
               "change": "-" if r.change_percent is None else f"{r.change_percent:+.1f} %"}
              for r in c.ground_motion_at_rates if r.curve in MOTION_ROWS]
    if motion:
        lines.append("PGA at stated annual rates, before and after (the fractiles in "
                     f"`{name}/constrain.json` and `constrained_curves.csv`):\n")
        lines.append(_table(pd.DataFrame(motion)) + "\n")
    lines += [f"Warning: {w}\n" for w in c.warnings]
    lines.append(_figure(results, results / name / "constrain.png",
                         "branch fan, prior and constrained mean and fractiles, the rock's age"))
    return "\n".join(lines)
