"""Outputs of the ``fragility`` campaign: ``fragility_runs.csv`` (one row per run and
column, 3D and 2D), ``fragility.json`` (:func:`pipeline.campaign.fragility_tables.summarise`),
``fragility_levels.csv`` and the figures; the pulse grid's in
:mod:`pipeline.campaign.pulse_outputs`."""
import logging
from pathlib import Path

import pandas as pd

from pipeline.campaign.column_file import summary_entry
from pipeline.campaign.fragility_block import block_runs
from pipeline.campaign.fragility_tables import level_table, scaled_runs, summarise
from pipeline.campaign.pulse_outputs import pulse_outputs
from pipeline.campaign.run_dirs import finished_summary
from pipeline.files import write_csv
from pipeline.hazard.fragility.file import write_fragility_file
from pipeline.simulate import run_code_version
from pipeline.campaign.tags import PulseTags

log = logging.getLogger(__name__)


def fragility_outputs(specs, campaign_dir, failures, animations, figures=True):
    """Write the campaign's files from its finished runs (the pulse grid's:
    :func:`pulse_outputs`) and say the fits; returns the campaign summary's entry."""
    campaign_dir = Path(campaign_dir)
    if specs and isinstance(specs[0].tags, PulseTags):
        return pulse_outputs(specs, campaign_dir, figures)
    runs = scaled_runs(specs, campaign_dir)
    if runs.empty:
        return {"code_version": run_code_version(), **summary_entry(specs), "figures": []}
    done = set(runs["run_id"])
    blocks, cost = block_runs([s for s in specs if s.run_id in done])
    wall = [finished_summary(campaign_dir, r).wall_s for r in done]
    simulated = runs.drop_duplicates("run_id")["simulated"].astype(bool)
    cost.update({"yade_runs": int(simulated.sum()), "runs_not_simulated": int((~simulated).sum()),
                 "yade_wall_s_total": round(float(sum(w or 0.0 for w in wall)), 1)})
    table = pd.concat([runs, blocks], ignore_index=True, sort=False)
    first = ["campaign", "model", "column", "record_id", "level_index", "level_m_s2", "member",
             "scale", "pga_m_s2", "pgv_m_s", "pgv_pga_s", "toppled", "downfall_azimuth_deg",
             "impact_time_s", "max_tilt_deg", "shaking_azimuth_deg"]
    table = table[[c for c in first if c in table] + [c for c in table if c not in first]]
    table = table.sort_values(["record_id", "level_index", "member", "model", "column"],
                              kind="stable")
    write_csv(campaign_dir / "fragility_runs.csv", table)
    summary = summarise(table, specs, cost)
    write_fragility_file(campaign_dir, summary)
    write_csv(campaign_dir / "fragility_levels.csv", level_table(table))
    written = []
    if figures:
        from pipeline.figures.fragility import plot_fragility  # lazy: matplotlib, not imported by a run or after Ctrl-C
        written = plot_fragility(table, summary, campaign_dir)
        if summary.damage_states:
            from pipeline.figures.damage_states import plot_damage_states  # lazy: matplotlib, as above
            written.append(plot_damage_states(summary, campaign_dir /
                                              "fragility_damage_states.png"))
    for name, entry in summary.columns.items():
        fit = entry.fits["PGA"]
        log.info(f"{name:>14}: {entry.toppled}/{entry.runs} toppled; PGA median "
                 + ("-" if fit.median is None else
                    f"{fit.median:.2f} m/s^2 [{fit.median_ci95[0]:.2f}, "
                    f"{fit.median_ci95[1]:.2f}], beta {fit.beta:.2f}"))
    for name, entry in (summary.damage_states or {}).items():
        log.info(f"{name:>14}: damage states reached (of {entry.runs} runs): " + ", ".join(
            f"{s.state} {s.reached}" + ("" if s.fits["PGA"].median is None else
                                        f" (PGA median {s.fits['PGA'].median:.2f} m/s^2)")
            for s in entry.states))
    log.info(f"2D block: {cost['block2d_cases']} cases in {cost['block2d_wall_s']:.1f} s; "
             f"YADE: {cost['yade_runs']} runs, {cost['yade_wall_s_total']:.0f} s")
    return {"code_version": run_code_version(), **summary_entry(specs),
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}
