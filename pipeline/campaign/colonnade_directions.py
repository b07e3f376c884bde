"""The ``colonnade-directions`` campaign: a colonnade shaken along its row (in-plane),
across it (out-of-plane) and at 45 deg to it (oblique) by the same one-cosine pulses
(:func:`pipeline.motion.pulses.one_cosine_pulse`, as the fragility's pulse grid shapes
them), one run per pulse and direction, or per pulse, direction and member (the
ensemble's sampled contact and tolerances, :mod:`pipeline.campaign.ensemble_members`).
Outputs: runs.csv, colonnades.csv with the direction of each run,
colonnade_statistics.json grouped by direction
(:class:`~pipeline.stats.colonnade.ColonnadeStatistics`), direction_statistics.json
(P(k columns fall) per direction and pulse:
:class:`~pipeline.stats.colonnade_directions.DirectionStatistics`), directions.csv (per
direction: the runs, those in which a column fell, the columns fallen per pulse) and
colonnade_falls.png.  Runs are samples: counts with their Wilson intervals."""
from dataclasses import dataclass
import logging
from pathlib import Path

import pandas as pd

from pipeline.campaign import Campaign, register
from pipeline.campaign.column_file import check_stiffness, column_kn, description, mark, \
    summary_entry
from pipeline.campaign.ensemble_members import (DEFAULT_SEED, ENSEMBLE_RANGES, check_seed,
                                                sample_batches)
from pipeline.campaign.options import CampaignOptions, column_file_param, stiffness_param
from pipeline.campaign.pulse_grid import G, parse_pulses, pulse_file
from pipeline.campaign.runs import column_specs, motion_cache, run_column_spec, twin
from pipeline.campaign.tables import (collect, colonnade_table, row_azimuth_deg,
                                      write_colonnade_files, write_tables)
from pipeline.files import InputError, write_csv
from pipeline.scenario.parameters import param
from pipeline.simulate import run_code_version
from pipeline.stats.colonnade_directions import DirectionStatistics
from pipeline.stats.ensemble import wilson_interval

log = logging.getLogger(__name__)

NAME = "colonnade-directions"
COLONNADE = "parthenon-north-flank"
DEFAULT_PULSES = "pga_g=0.4:0.8:2;pgv_pga_s=0.3:0.3:1"
DEFAULT_MEMBERS = 0            # the colonnade as described, one run per pulse and direction
MAX_MEMBERS = 1000
# a direction of shaking: its name and its angle (deg) clockwise from the row's axis
DIRECTIONS = (("in-plane", 0.0), ("oblique", 45.0), ("out-of-plane", 90.0))
# the shipped colonnade under a 0.35 g, 0.3 s pulse across its row: every column fell, 15.9 s
# simulated in 134 s of one core (2026-12-07); a run that stands stops sooner
RUN_CORE_S = 140.0


@dataclass(frozen=True)
class DirectionTags:
    """A run of the directions campaign: its ``direction`` (in-plane, oblique,
    out-of-plane), that direction's angle from the row and its azimuth (deg clockwise
    from North), the pulse's PGA (g) and PGV/PGA (s), and its ``member`` (-1: the
    colonnade as described)."""
    direction: str
    angle_from_row_deg: float
    azimuth_deg: float
    pga_g: float
    pgv_pga_s: float
    member: int = -1


def directions_specs(records, campaign_dir, column_file=COLONNADE, pulses=DEFAULT_PULSES,
                     stiffness="matched", members=DEFAULT_MEMBERS, seed=DEFAULT_SEED):
    """One run per pulse of ``pulses`` (``pga_g=LO:HI:N;pgv_pga_s=LO:HI:N``), direction
    of :data:`DIRECTIONS` and member of the colonnade ``column_file`` (``members`` 0: the
    colonnade as described; else that many members, each drawn on its own from ``seed``
    and its number, so that more members keep the runs done); the pulse along North
    turned to each direction's azimuth."""
    if records:
        raise InputError(f"campaign {NAME} takes no --records (it shakes the colonnade by "
                         "the one-cosine pulses of --pulses)")
    data = description(column_file, colonnades=True)
    if "stylobate" not in data:
        raise InputError(f"--column-file {data['name']}: one column; campaign {NAME} "
                         "shakes a colonnade (docs/colonnades.md)")
    check_stiffness(stiffness)
    check_seed(seed)
    grid = parse_pulses(pulses)
    row = row_azimuth_deg(data)
    kn = column_kn(data, stiffness)
    base = twin(column_file=data, kn=kn)
    samples = [(-1, base)] if members == 0 else [
        (m, {**base, **p}) for m, p in enumerate(sample_batches(
            members, 1, seed, ENSEMBLE_RANGES, base["column"], description=data, kn=kn))]
    cache = motion_cache(campaign_dir)
    runs, tags = [], []
    for ratio in grid["pgv_pga_s"]:
        for pga_g in grid["pga_g"]:
            path = str(pulse_file(cache, round(float(pga_g) * G, 6), round(float(ratio), 6)))
            for direction, angle in DIRECTIONS:
                azimuth = round((row + angle) % 360.0, 6)
                for member, params in samples:
                    runs.append((path, {**params, "rotate_deg": azimuth}))
                    tags.append(DirectionTags(direction, angle, azimuth, float(pga_g),
                                              float(ratio), member))
    return mark(column_specs(runs, campaign_dir, tags), data)


def direction_table(colonnades):
    """directions.csv: per direction the runs (samples), those in which a column fell
    with its Wilson 95 % interval, the columns fallen of those shaken, and the columns
    fallen per pulse (``k of n`` at each PGA, g, over that pulse's runs)."""
    rows = []
    for direction, angle in DIRECTIONS:
        sub = colonnades[colonnades["direction"] == direction]
        if sub.empty:
            continue
        fell = int((sub["columns_fallen"] > 0).sum())
        lo, hi = wilson_interval(fell, len(sub))
        per_pulse = sub.groupby(["pgv_pga_s", "pga_g"])[["columns_fallen", "columns"]].sum()
        rows.append({"direction": direction, "angle_from_row_deg": angle,
                     "azimuth_deg": float(sub["azimuth_deg"].iloc[0]), "runs": len(sub),
                     "runs_with_a_fall": fell, "p_fall": fell / len(sub), "p_fall_lo": lo,
                     "p_fall_hi": hi, "columns_fallen": int(sub["columns_fallen"].sum()),
                     "columns_shaken": int(sub["columns"].sum()),
                     "fallen_per_pulse": "; ".join(
                         f"{pga:g} g, {ratio:g} s: {int(r.columns_fallen)} of {int(r.columns)}"
                         for (ratio, pga), r in per_pulse.iterrows())})
    return pd.DataFrame(rows)


def directions_outputs(specs, campaign_dir, failures, animations, figures=True):
    """runs.csv, impacts.csv, colonnades.csv with each run's direction, pulse (and
    member), its statistics grouped by direction, direction_statistics.json,
    directions.csv and the figures."""
    campaign_dir = Path(campaign_dir)
    runs, impacts = collect(specs, NAME, campaign_dir)
    write_tables(campaign_dir, runs, impacts)
    table = colonnade_table(specs, campaign_dir)
    tags = {s.run_id: s.tags for s in specs}
    keys = ["direction", "angle_from_row_deg", "azimuth_deg", "pga_g", "pgv_pga_s"]
    if any(t.member >= 0 for t in tags.values()):
        keys.append("member")
    for key in keys:
        table[key] = [getattr(tags[r], key) for r in table["run_id"]]
    if table.empty:
        return {"code_version": run_code_version(), **summary_entry(specs), "figures": []}
    statistics = DirectionStatistics.of(table)          # checked before any file
    runs["direction"] = runs["run_id"].map({r: t.direction for r, t in tags.items()})
    written = write_colonnade_files(campaign_dir, table, figures, by="direction",
                                    pooled=None, runs=runs,
                                    description=specs[0].column_description)
    statistics.save(campaign_dir)
    write_csv(campaign_dir / "directions.csv", direction_table(table))
    for case in statistics.cases:
        log.info(f"{case.direction}, {case.pga_g:g} g, {case.pgv_pga_s:g} s: P(k columns "
                 "fall) " + ", ".join(f"{k}: {f.p:.2f} [{f.ci95[0]:.2f}, {f.ci95[1]:.2f}]"
                                      for k, f in enumerate(case.fallen)))
    return {"code_version": run_code_version(), **summary_entry(specs),
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}


@dataclass(frozen=True)
class DirectionsOptions(CampaignOptions):
    column_file: str = column_file_param("a colonnade's description", default=COLONNADE)
    pulses: str = param(DEFAULT_PULSES, "", "the one-cosine pulses (several amplitudes and "
                        "PGV/PGA ratios as a grid), each run along, across and at 45 deg to "
                        "the row: pga_g=LO:HI:N;pgv_pga_s=LO:HI:N",
                        flag="--pulses", metavar="SPEC")
    members: int = param(DEFAULT_MEMBERS, "", "members per pulse and direction, each with "
                         "the ensemble's sampled contact and tolerances, so that P(k columns "
                         "fall) has a Wilson interval of that many runs (0: the colonnade as "
                         "described, one run)", 0, MAX_MEMBERS, flag="--members")
    seed: int = param(DEFAULT_SEED, "", "seed of the members' sampling (member m drawn "
                      "from the seed and m; an integer in [0, 2^63))", flag="--seed")
    stiffness: str = stiffness_param("")

    def check(self):
        parse_pulses(self.pulses)
        check_seed(self.seed)

    def kwargs(self):
        return {**super().kwargs(), "stiffness": self.stiffness or "matched"}


register(Campaign(NAME, "a colonnade shaken along its row, across it and at 45 deg by the "
                  "same one-cosine pulses: falls per direction",
                  directions_specs, run_column_spec, directions_outputs,
                  options=DirectionsOptions, run_core_s=RUN_CORE_S))
