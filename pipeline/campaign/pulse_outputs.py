"""Outputs of the pulse grid of the ``fragility`` campaign (:mod:`pipeline.campaign.pulse_grid`):
``fragility_runs.csv`` (one row per run and model: the 3D specimen and the 2D block),
``fragility.json`` (``pulse_grid``: cells, contours, logistic surface, the 2D block, the
check against experiments where they exist) and ``fragility_pulse_grid.png``."""
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign import pulse_block, pulse_grid, pulse_summary
from pipeline.campaign.column_file import summary_entry
from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.pulse_check import experiments_check
from pipeline.files import json_safe, write_csv
from pipeline.hazard.fragility.experiments import Experiments
from pipeline.hazard.fragility.file import FragilityFile, write_fragility_file
from pipeline.hazard.fragility.load import BLOCK_MODEL
from pipeline.simulate import run_code_version

log = logging.getLogger(__name__)

SAMPLING = {True: "adaptive: each cell run until its Wilson interval excludes P = 0.5 (up to "
                  "the full grid's runs), starting from a few runs near the 2D block's "
                  "threshold and one probe run elsewhere, more where a probe disagreed with "
                  "the block or a neighbour; a cell's n is the runs it had",
            False: "full grid: every cell x member x direction"}   # by "adaptive"

def pulse_table(specs, campaign_dir):
    """One row per finished run and specimen model, then the 2D block of every such run."""
    rows, done = [], []
    for spec in specs:
        summary = finished_summary(campaign_dir, spec.run_id)
        if summary is None:
            continue
        done.append(spec)
        contact = spec.params.contact
        described = spec.params.column.column_file or {}
        for column in summary.columns:
            rows.append({"run_id": spec.run_id, "model": column.column,
                         "pga_g": spec.tags.pga_g, "pgv_pga_s": spec.tags.pgv_pga_s,
                         "member": spec.tags.member, "heading": spec.tags.heading,
                         "azimuth_deg": spec.tags.azimuth_deg, "toppled": column.toppled,
                         "max_tilt_deg": column.max_tilt_deg,
                         "downfall_azimuth_deg": column.downfall_azimuth_deg,
                         "kn": contact.kn, "damping": contact.damping, "mu_s": contact.mu_s,
                         "mu_k": contact.mu_k,
                         "footprint_tolerance_m": described.get("footprint_tolerance_m")})
    if done:
        fell = pulse_block.block_outcomes(done)
        for spec, toppled in zip(done, fell):
            rows.append({"run_id": spec.run_id, "model": BLOCK_MODEL,
                         "pga_g": spec.tags.pga_g, "pgv_pga_s": spec.tags.pgv_pga_s,
                         "member": spec.tags.member, "heading": spec.tags.heading,
                         "azimuth_deg": spec.tags.azimuth_deg, "toppled": bool(toppled)})
    return pd.DataFrame(rows), done


def pulse_outputs(specs, campaign_dir, figures=True):
    campaign_dir = Path(campaign_dir)
    table, done = pulse_table(specs, campaign_dir)
    if table.empty:
        return {"code_version": run_code_version(), **summary_entry(specs), "figures": []}
    write_csv(campaign_dir / "fragility_runs.csv", table)
    first = specs[0].tags
    grid = pulse_grid.parse_pulses(first.pulses)
    sets = [None] * first.members
    azimuths = {}
    for spec in specs:
        sets[spec.tags.member] = spec.tags.point
        azimuths[(spec.tags.member, spec.tags.heading)] = spec.tags.azimuth_deg
    azimuth_array = np.array([[azimuths.get((m, h), np.nan) for h in range(first.headings)]
                              for m in range(first.members)])
    section = pulse_summary.summarise_grid(table, done, grid, sets, azimuth_array,
                                        first.azimuth, first.ranges
                                        or pulse_grid.DEFAULT_RANGES)
    described = summary_entry(specs)
    name = described["column_file"]["name"] if described else "the paper's column"
    summary = FragilityFile.of(json_safe({"mode": "pulses", "specimen": name,
                                          "seed": first.seed, "pulse_grid": section}))
    section = summary.pulse_grid
    section = replace(
        section, block2d=replace(section.block2d, model=BLOCK_MODEL),
        runs_finished=len(done), runs=len(specs),
        yade_wall_s_total=round(float(sum(
            finished_summary(campaign_dir, s.run_id).wall_s or 0.0 for s in done)), 1),
        full_grid_runs=(len(grid["pga_g"]) * len(grid["pgv_pga_s"]) * first.members
                        * first.headings),
        sampling=SAMPLING[first.adaptive])
    observed = experiments_check(section, name)
    if observed is not None:
        section = replace(section, experiments=Experiments.of(json_safe(observed)))
    summary = replace(summary, pulse_grid=section)
    write_fragility_file(campaign_dir, summary)
    written = []
    if figures:
        from pipeline.figures.fragility import plot_pulse_grid  # lazy: matplotlib, not imported by a run or after Ctrl-C
        written = plot_pulse_grid(summary, campaign_dir / "fragility_pulse_grid.png")
    grid = summary.pulse_grid
    for model, entry in grid.models.items():
        half = [c.pga_g for c in entry.contour(0.5)]
        shown = ", ".join("-" if v is None else f"{v:.2f}" for v in half)
        log.info(f"{model:>14}: {entry.overturned}/{entry.runs} overturned; P = 0.5 at "
                 f"PGA (g) {shown} for PGV/PGA "
                 f"{', '.join(f'{r:g}' for r in grid.pgv_pga_s)} s")
    for warning in grid.warnings:
        log.warning(f"warning: {warning}")
    return {"code_version": run_code_version(), **described,
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}
