"""The ``colonnade-directions`` campaign: a colonnade shaken along its row (in-plane),
across it (out-of-plane) and at 45 deg to it (oblique) by the same one-cosine pulses
(:func:`pipeline.motion.pulses.one_cosine_pulse`, as the fragility's pulse grid shapes
them), one run per pulse and direction.  Outputs: runs.csv, colonnades.csv with the
direction of each run, colonnade_statistics.json grouped by direction
(:class:`~pipeline.stats.colonnade.ColonnadeStatistics`) and directions.csv (per
direction: the runs, those in which a column fell, the columns fallen per pulse).  A
single run is a sample: counts with their Wilson intervals, not probabilities over a
site's motions."""
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from pipeline.campaign import Campaign, register
from pipeline.campaign.column_file import check_stiffness, column_kn, description, mark, \
    summary_entry
from pipeline.campaign.options import CampaignOptions, column_file_param, stiffness_param
from pipeline.campaign.pulse_grid import G, parse_pulses, pulse_file
from pipeline.campaign.runs import column_specs, motion_cache, run_column_spec, twin
from pipeline.campaign.tables import (collect, colonnade_table, row_azimuth_deg,
                                      write_colonnade_files, write_tables)
from pipeline.files import InputError, write_csv
from pipeline.scenario.parameters import param
from pipeline.simulate import run_code_version
from pipeline.stats.ensemble import wilson_interval

NAME = "colonnade-directions"
COLONNADE = "parthenon-north-flank"
DEFAULT_PULSES = "pga_g=0.4:0.8:2;pgv_pga_s=0.3:0.3:1"
# a direction of shaking: its name and its angle (deg) clockwise from the row's axis
DIRECTIONS = (("in-plane", 0.0), ("oblique", 45.0), ("out-of-plane", 90.0))
# the shipped colonnade under a 0.35 g, 0.3 s pulse across its row: every column fell, 15.9 s
# simulated in 134 s of one core (2026-12-07); a run that stands stops sooner
RUN_CORE_S = 140.0


@dataclass(frozen=True)
class DirectionTags:
    """A run of the directions campaign: its ``direction`` (in-plane, oblique,
    out-of-plane), that direction's angle from the row and its azimuth (deg clockwise
    from North), and the pulse's PGA (g) and PGV/PGA (s)."""
    direction: str
    angle_from_row_deg: float
    azimuth_deg: float
    pga_g: float
    pgv_pga_s: float


def directions_specs(records, campaign_dir, column_file=COLONNADE, pulses=DEFAULT_PULSES,
                     stiffness="matched"):
    """One run per pulse of ``pulses`` (``pga_g=LO:HI:N;pgv_pga_s=LO:HI:N``) and per
    direction of :data:`DIRECTIONS` of the colonnade ``column_file``; the pulse along
    North turned to each direction's azimuth."""
    if records:
        raise InputError(f"campaign {NAME} takes no --records (it shakes the colonnade by "
                         "the one-cosine pulses of --pulses)")
    data = description(column_file, colonnades=True)
    if "stylobate" not in data:
        raise InputError(f"--column-file {data['name']}: one column; campaign {NAME} "
                         "shakes a colonnade (docs/colonnades.md)")
    check_stiffness(stiffness)
    grid = parse_pulses(pulses)
    row = row_azimuth_deg(data)
    base = twin(column_file=data, kn=column_kn(data, stiffness))
    cache = motion_cache(campaign_dir)
    runs, tags = [], []
    for ratio in grid["pgv_pga_s"]:
        for pga_g in grid["pga_g"]:
            path = str(pulse_file(cache, round(float(pga_g) * G, 6), round(float(ratio), 6)))
            for direction, angle in DIRECTIONS:
                azimuth = round((row + angle) % 360.0, 6)
                runs.append((path, {**base, "rotate_deg": azimuth}))
                tags.append(DirectionTags(direction, angle, azimuth, float(pga_g),
                                          float(ratio)))
    return mark(column_specs(runs, campaign_dir, tags), data)


def direction_table(colonnades):
    """directions.csv: per direction the runs (single runs: samples), those in which a
    column fell with its Wilson 95 % interval, the columns fallen of those shaken, and
    the columns fallen per pulse (``k of n`` at each PGA, g)."""
    rows = []
    for direction, angle in DIRECTIONS:
        sub = colonnades[colonnades["direction"] == direction].sort_values("pga_g")
        if sub.empty:
            continue
        fell = int((sub["columns_fallen"] > 0).sum())
        lo, hi = wilson_interval(fell, len(sub))
        rows.append({"direction": direction, "angle_from_row_deg": angle,
                     "azimuth_deg": float(sub["azimuth_deg"].iloc[0]), "runs": len(sub),
                     "runs_with_a_fall": fell, "p_fall": fell / len(sub), "p_fall_lo": lo,
                     "p_fall_hi": hi, "columns_fallen": int(sub["columns_fallen"].sum()),
                     "columns_shaken": int(sub["columns"].sum()),
                     "fallen_per_pulse": "; ".join(
                         f"{r.pga_g:g} g, {r.pgv_pga_s:g} s: {r.columns_fallen} of {r.columns}"
                         for r in sub.itertuples())})
    return pd.DataFrame(rows)


def directions_outputs(specs, campaign_dir, failures, animations, figures=True):
    """runs.csv, impacts.csv, colonnades.csv with each run's direction and pulse, its
    statistics grouped by direction and directions.csv."""
    campaign_dir = Path(campaign_dir)
    runs, impacts = collect(specs, NAME, campaign_dir)
    write_tables(campaign_dir, runs, impacts)
    table = colonnade_table(specs, campaign_dir)
    tags = {s.run_id: s.tags for s in specs}
    for key in ("direction", "angle_from_row_deg", "azimuth_deg", "pga_g", "pgv_pga_s"):
        table[key] = [getattr(tags[r], key) for r in table["run_id"]]
    if not runs.empty:
        runs["direction"] = runs["run_id"].map({s.run_id: s.tags.direction for s in specs})
    written = write_colonnade_files(campaign_dir, table, figures, by="direction",
                                    pooled=None, runs=runs,
                                    description=specs[0].column_description)
    if not table.empty:
        write_csv(campaign_dir / "directions.csv", direction_table(table))
    return {"code_version": run_code_version(), **summary_entry(specs),
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}


@dataclass(frozen=True)
class DirectionsOptions(CampaignOptions):
    column_file: str = column_file_param("a colonnade's description", default=COLONNADE)
    pulses: str = param(DEFAULT_PULSES, "", "the one-cosine pulses, each run along, across "
                        "and at 45 deg to the row: pga_g=LO:HI:N;pgv_pga_s=LO:HI:N",
                        flag="--pulses", metavar="SPEC")
    stiffness: str = stiffness_param("")

    def check(self):
        parse_pulses(self.pulses)

    def kwargs(self):
        return {**super().kwargs(), "stiffness": self.stiffness or "matched"}


register(Campaign(NAME, "a colonnade shaken along its row, across it and at 45 deg by the "
                  "same one-cosine pulses: falls per direction",
                  directions_specs, run_column_spec, directions_outputs,
                  options=DirectionsOptions, run_core_s=RUN_CORE_S))
