"""Report section of the contact stiffness alone at x1, x3, x10 (make
contact-convergence): the rock on its shake-table tests, Housner free rocking, the twin
model's ensembles, the rock's restitution (kn in N/m, time steps and wall times in s)."""
import json
import re
from pathlib import Path

import pandas as pd

from pipeline.report.common import _fmt


def contact_stiffness_section(results):
    """The contact stiffness alone at x1, x3, x10 (make contact-convergence): the rock on
    its tests, Housner free rocking of a block and a column, the twin model's ensembles."""
    path = Path(results) / "contact-convergence" / "convergence.json"
    title = "## Contact stiffness\n"
    if not path.exists():
        return title + "\nNot run yet (`make contact-convergence`).\n"
    conv = json.loads(path.read_text())
    lines = [title, "What the contact work changed: a mesh specimen's contact spheres near "
             "its base now start touching the table, none inside it (one started loaded and "
             "threw the rock at a stiff contact); released starts for free rocking and the "
             "contact file are new inputs.  The contact law and a column's rims are as "
             "before, so the column model's checks against rocking theory (the Verification "
             "section: Housner free rocking, one-sine pulses, rocking and sliding) are those "
             "of the same model.\n",
             "The contact springs' stiffness kn is a numerical parameter: each part "
             "below runs at kn x1, x3 and x10 with the physical parameters fixed (damping "
             "ratio, friction, geometry); the time step follows the stiffness "
             "(dt proportional to 1 / sqrt(kn)).\n"]
    if "factors" in conv:
        lines += _stiffness_rock_tests(conv)
    for body, table in conv.get("free_rocking", {}).items():
        lines += _stiffness_free_rocking(body, table)
    if conv.get("twin"):
        lines += _stiffness_twin(conv["twin"])
    if conv.get("rock_restitution"):
        lines += _stiffness_rock_restitution(conv["rock_restitution"])
    return "\n".join(lines)


def _stiffness_cost(row, wall="wall_s_per_run"):
    """A factor's time step and wall time, as table cells."""
    return {"time step (s)": f"{row['time_step_s']:.3g}" if row.get("time_step_s")
            else "-",
            "wall per run (s)": _fmt(row.get(wall), 1),
            "wall vs x1": "-" if row.get("wall_vs_x1") is None
            else f"{row['wall_vs_x1']:.2f}"}


def _stiffness_rock_tests(conv):
    """The rock SP1 on its fixed shake-table tests at each factor (lines)."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)", "tests": r["n"],
             "accuracy [95 %]": f"{r['accuracy']:.2f} [{r['accuracy_95'][0]:.2f}, "
             f"{r['accuracy_95'][1]:.2f}]",
             "predicted overturned (observed)": f"{r['predicted_overturned']} "
             f"({r['observed_overturned']})", "as at x1": r["same_as_x1"],
             **_stiffness_cost(r)} for k, r in conv["factors"].items()]
    fixed = re.sub(r"[,;]?\s*kn=[^,;]*", "", conv["grid_point"]).strip(",; ")
    return [f"The rock SP1 on {len(conv['tests'])} fixed shake-table tests (`{fixed}`):\n",
            _text_table(rows) + "\n"]


def _stiffness_free_rocking(body, table):
    """Housner free rocking of one body at each factor, and at other damping ratios."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)",
             "restitution per impact": " ".join(f"{e:.4f}" for e in
                                                r["restitution_per_impact"]),
             "max diff. from x1": _fmt(r["max_abs_restitution_minus_x1"], 4),
             "impact times vs Housner": f"{100 * r['max_rel_error_impact_times_housner']:.1f} %",
             "impact times vs x1 (ms)": _fmt(1e3 * r["max_abs_impact_time_minus_x1_s"], 1),
             **_stiffness_cost(r, "wall_s")} for k, r in table["factors"].items()]
    size = f"{table['height_m']:g} m x {table['width_m']:.3g} m"
    lines = [f"Housner free rocking of {table.get('body', body)} ({table['shape']}, "
             f"{size}, released at "
             f"{table['theta0_ratio']:g} alpha, damping ratio "
             f"{table['contact']['damping']:g}); Housner's restitution "
             f"{table['housner_restitution']:.4f}:\n", _text_table(rows) + "\n"]
    other = [{"damping ratio": f"{entry['damping']:g}",
              **{f"restitution {k}": f"{r['restitution']:.4f}"
                 for k, r in entry["factors"].items()},
              "largest diff. of an impact's from x1": _fmt(max(
                  r["max_abs_restitution_minus_x1"] or 0.0
                  for r in entry["factors"].values()), 4)}
             for entry in table.get("at_damping", [])]
    if other:
        lines += ["The same body at other damping ratios (restitution, mean over the "
                  "impacts):\n", _text_table(other) + "\n"]
    return lines


def _stiffness_twin(twin):
    """The twin model's ensembles at each factor (lines)."""
    rows = []
    for k, r in twin["factors"].items():
        for column, c in r["columns"].items():
            ci = c["p_toppled_ci95"]
            rows.append({"kn": k, "column": column, "members": c["members"],
                         "P(toppled) [95 %]": f"{c['p_toppled']:.2f} [{ci[0]:.2f}, "
                         f"{ci[1]:.2f}]",
                         "mean downfall (deg), R": "-" if c["mean_downfall_azimuth_deg"]
                         is None else f"{c['mean_downfall_azimuth_deg']:.0f}, "
                         f"{c['resultant_length']:.2f}",
                         "outcome as at x1": f"{c['same_outcome_as_x1']}/"
                         f"{c['paired_with_x1']}",
                         "P vs x1 (McNemar p)": _fmt(c.get("p_value_vs_x1"), 2),
                         "median turn vs x1 (deg)": _fmt(c["median_turn_vs_x1_deg"]),
                         **_stiffness_cost(r)})
    return [f"The twin model's ensembles on {twin['record']} (the same sampled members "
            "at every factor):\n", _text_table(rows) + "\n"]


def _stiffness_rock_restitution(rock):
    """The rock's free-rocking restitution at each factor and damping ratio (lines)."""
    rows = [{"kn": f"{k} ({r['kn']:g} N/m)", "damping ratio": f"{rock['damping']:g}",
             "restitution": f"{r['restitution']:.4f}"} for k, r in rock["factors"].items()]
    rows += [{"kn": "x1", "damping ratio": f"{r['damping']:g}",
              "restitution": f"{r['restitution']:.4f}"} for r in rock["by_damping"]]
    return [f"The rock {rock['specimen']} rocking freely in the same model (footprint "
            f"tolerance {rock['footprint_tolerance_m']:g} m, released toward "
            f"{rock['azimuth_deg']:g} deg; median over three releases): the rocking "
            "restitution a damping ratio stands for.  Housner's restitution for a "
            f"block of its critical angle that way ({rock['critical_angle_along_deg']:.1f} "
            f"deg) is {rock['housner_block_restitution']:.4f}.\n", _text_table(rows) + "\n"]


def _text_table(rows):
    """A Markdown table of rows whose cells are written as given (0.9450 keeps its 0)."""
    return pd.DataFrame(rows).to_markdown(index=False, disable_numparse=True)
