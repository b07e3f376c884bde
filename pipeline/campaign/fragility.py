"""The ``fragility`` campaign: P(toppled | intensity) by incremental dynamic analysis.

Each record is scaled to a ladder of horizontal PGA targets (``--levels``, m/s^2,
the peak of the horizontal acceleration vector of the scaled motion; the
vertical is scaled with it) and, at every level, the same small ensemble of
column models (``pipeline.campaign.ensemble_members.sample_members``: friction, damping,
stiffness, geometry tolerances, rim phase; one Latin hypercube for all levels,
so each member is one column shaken ever harder) is run in YADE through the
``scale`` parameter of :func:`pipeline.simulate.simulate`.

The same scaled records shake the project's 2D rigid block
(:func:`pipeline.rocking.sampled.rocking_response_sampled`, Housner's equation and
restitution) of each member's size and slenderness (width = diameter, so
alpha = atan(d / h)), without friction limit, sliding or vertical motion: once
along the record's strongest azimuth (``az_max_acc_deg``, the direction of the
horizontal PGA: ``block2d``) and at ``--azimuths`` directions over 180 deg
(``block2d_worst``: toppled when any of them topples).

For IM = PGA, PGV (horizontal vector peaks of the scaled motion) and PGV/PGA
(unchanged by scaling: identified only across records) the outputs give the
lognormal fragility (median and dispersion beta with 95 % intervals,
:func:`pipeline.stats.fragility.fragility_fit`) per column type, the binned
fractions with Wilson intervals, and the two-parameter logistic surface
logit P = b0 + b1 ln PGA + b2 ln(PGV/PGA) after Purvance et al. (2008)
(:func:`pipeline.stats.fragility.logistic_surface`).  Files (see ``fragility.json`` keys in
:func:`pipeline.campaign.fragility_tables.summarise`): ``fragility.json``,
``fragility_runs.csv`` (one row per run and column, 3D and 2D), ``fragility_levels.csv``
(fraction toppled per record and level, 3D columns beside the 2D block), figures
``fragility_curves.png``,
``fragility_2d_vs_3d.png`` and ``fragility_surface.png``.

With ``--column-file`` the members are the described column with the sampled height and
diameter tolerances (its tilt and offsets as described, none sampled), and the 2D block
has each member's overall height and base width
(:func:`pipeline.campaign.pulse_block.block_size`).

This module is the campaign (specs, options, the adaptive driver); the 2D block batch is
:mod:`pipeline.campaign.fragility_block`, the tables and fits
:mod:`pipeline.campaign.fragility_tables`, the files
:mod:`pipeline.campaign.fragility_outputs`, the pulse grid
:mod:`pipeline.campaign.pulse_grid` (its 2D block :mod:`pipeline.campaign.pulse_block`,
summary :mod:`pipeline.campaign.pulse_summary`, adaptive sampling
:mod:`pipeline.campaign.pulse_adaptive`, files :mod:`pipeline.campaign.pulse_outputs`).
"""
import logging
import math
from dataclasses import dataclass, replace

import numpy as np

from pipeline import paper
from pipeline.campaign import Campaign, register
from pipeline.campaign import ensemble_members
from pipeline.campaign import pulse_adaptive, pulse_block, pulse_grid
from pipeline.campaign.column_file import check_stiffness, column_kn, mark
from pipeline.campaign.executor import RUN_CORE_S
from pipeline.campaign.column_file import description as column_file_description
from pipeline.campaign.fragility_block import DEFAULT_AZIMUTHS
from pipeline.campaign.fragility_outputs import fragility_outputs
from pipeline.campaign.options import (CampaignOptions, column_file_param, contact_file_param,
                                       contact_of, refuse_ignored_stiffness, stiffness_param)
from pipeline.scenario.contact_file import contact_values
from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.runs import column_specs, motion_cache, pulse_record, run_column_spec
from pipeline.constants import COLUMN_KINDS
from pipeline.files import InputError, duration_text
from pipeline.motion.measures import horizontal_peak
from pipeline.records import processed_motion
from pipeline.scenario.parameters import param
from pipeline.campaign.tags import LevelTags, PulseTags

log = logging.getLogger(__name__)

DEFAULT_LEVELS = tuple(round(float(v), 3) for v in np.geomspace(0.5, 8.0, 8))   # m/s^2
DEFAULT_MEMBERS = 4
DEFAULT_HEADINGS = 4            # pulse grid: shaking directions per parameter set
LEVELS_WITH_PULSES = ("--levels scales records; the pulse grid has its own PGA axis (--pulses "
                      "pga_g=LO:HI:N): give one or the other")


def default_records():
    """The paper's sweep record (GM20) and the pulse record that replaces its GM23."""
    return [paper.SWEEP_RECORD, pulse_record()]


def parse_levels(text):
    """'0.5,1,2' -> (0.5, 1.0, 2.0): positive, finite, distinct, increasing order."""
    if isinstance(text, (list, tuple)):
        values = [float(v) for v in text]
    else:
        try:
            values = [float(v) for v in str(text).split(",") if v.strip()]
        except ValueError:
            raise InputError(f"--levels {text!r}: expected comma-separated PGA values in "
                             "m/s^2, e.g. 0.5,1,2,4") from None
    if not values or len(values) > 50:
        raise InputError(f"--levels needs 1 to 50 PGA values, got {len(values)}")
    if not all(math.isfinite(v) and 0 < v <= 100 for v in values):
        raise InputError(f"--levels: PGA values must lie in (0, 100] m/s^2, got {text!r}")
    values = sorted({round(v, 6) for v in values})
    return tuple(values)


def parse_grid(text):
    """:func:`pipeline.campaign.pulse_grid.parse_pulses`, refusing an axis whose values
    agree to 6 significant digits (the resolution of the pulses' files: one cell would
    be run and counted twice)."""
    grid = pulse_grid.parse_pulses(text)
    for name, values in grid.items():
        distinct = {f"{v:.6g}" for v in values}
        if len(distinct) < len(values):
            raise InputError(f"--pulses {name}: its {len(values)} values are only "
                             f"{len(distinct)} distinct to 6 significant digits (the pulses' "
                             "resolution): a cell would be run twice; give fewer steps or a "
                             "wider LO:HI")
    return grid


def planned_runs(records, options):
    """(runs, core-s a run) of the campaign from its ``options`` (the keyword options of
    :class:`FragilityOptions`, with ``only_runs`` in an adaptive stage) alone, the long-run gate's
    count before any spec is built: cells x members x headings on the pulse grid (its
    runs' cost, :func:`pipeline.campaign.pulse_grid.run_core_s`), records x levels x
    members on scaled records; None for the runs of an adaptive stage."""
    if options.get("only_runs") is not None:
        return None
    column_file, pulses = options.get("column_file"), options.get("pulses")
    members = options.get("members", DEFAULT_MEMBERS)
    headings, levels = options.get("headings", DEFAULT_HEADINGS), options.get("levels")
    if pulses is None and not records and column_file is not None:
        if "mesh" in column_file_description(column_file, meshes=True):
            pulses = "vsr"
    if pulses is not None:
        grid = parse_grid(pulses)
        core_s = [pulse_grid.run_core_s(ratio) for ratio in grid["pgv_pga_s"]]
        return (len(grid["pga_g"]) * len(core_s) * members * headings,
                float(np.mean(core_s)))
    levels = parse_levels(DEFAULT_LEVELS if levels is None else levels)
    return len(records or default_records()) * len(levels) * members, RUN_CORE_S


def fragility_specs(records, campaign_dir, levels=None, members=DEFAULT_MEMBERS,
                    column="both", seed=None, azimuths=DEFAULT_AZIMUTHS, column_file=None,
                    stiffness="matched", pulses=None, azimuth=None,
                    headings=DEFAULT_HEADINGS, ranges=None, jobs=None, only_runs=None,
                    adaptive=False, contact_file=None, grid_specs=None):
    """Run specs: every record x level x member; ``scale`` = level / PGA of the record.
    With ``column_file`` every member is the described column with the sampled height
    and diameter tolerances (its own tilt and offsets as described), and the 2D block
    has each member's overall height and base width.  With ``pulses`` (the default for
    a mesh specimen: the preset vsr) the pulse grid of :mod:`pipeline.campaign.pulse_grid`
    instead; ``only_runs`` (run ids) keeps those of its runs, taken from ``grid_specs``
    when the adaptive driver has made the grid's specs already.  A contact file fixes what
    it sets for every member (:func:`pipeline.campaign.ensemble_members.contact_ranges`; on the
    pulse grid, :func:`pipeline.campaign.pulse_grid.pulse_runs`).  ``levels``: None for
    :data:`DEFAULT_LEVELS`; given with the pulse grid, refused (it has its own PGA axis)."""
    data = column_file_description(column_file, meshes=True)
    contact = None if contact_file is None else contact_values(contact_file)
    mesh = data is not None and "mesh" in data
    if pulses is None and mesh and not records:
        pulses = "vsr"
        log.info("fragility: a mesh specimen: the pulse grid vsr (PGA 0.2-1.1 g x PGV/PGA "
                 "0.1-1.0 s, 10 x 10; --pulses to change it)")
    if pulses is not None:
        if levels is not None:
            raise InputError(LEVELS_WITH_PULSES)
        specs = grid_specs if grid_specs is not None else _pulse_specs(
            records, campaign_dir, data, column, pulses, members, headings, azimuth, seed,
            ranges, stiffness, jobs, quiet=only_runs is not None, contact=contact)
        if only_runs is not None:
            keep = set(only_runs)
            specs = [replace(s, tags=replace(s.tags, adaptive=True)) for s in specs
                     if s.run_id in keep]
        return specs
    if adaptive:
        raise InputError("--adaptive belongs to the pulse grid: add --pulses")
    if mesh:
        raise InputError(f"--column-file {data['name']}: a mesh specimen takes the pulse grid "
                         "(--pulses), not scaled --records")
    if azimuth is not None or ranges is not None:
        raise InputError("--azimuth and --ranges belong to the pulse grid: add --pulses")
    check_stiffness(stiffness)
    records = list(records) if records else default_records()
    levels = parse_levels(DEFAULT_LEVELS if levels is None else levels)
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    if not (isinstance(azimuths, int) and 1 <= azimuths <= 360):
        raise InputError(f"--azimuths must be an integer in [1, 360], got {azimuths!r}")
    seed = ensemble_members.DEFAULT_SEED if seed is None else seed
    # the 2D block needs each member's height and h/d: no tilt or offset descriptions here
    ranges = ensemble_members.contact_ranges({k: v for k, v in ensemble_members.ENSEMBLE_RANGES.items()
                                      if k not in ensemble_members.GEOMETRY_KEYS}, contact)
    base_kn = (contact or {}).get("kn")
    if data is None:
        member_params = ensemble_members.sample_members(members, seed, ranges, column=column,
                                                kn=base_kn or paper.COLUMN_KN_N_M)
    else:
        member_params = ensemble_members.sample_members(members, seed, ranges, column=column,
                                                description=data,
                                                kn=base_kn or column_kn(data, stiffness))
    member_params = ensemble_members.with_fixed_contact(member_params, contact)
    runs, extra = _level_runs(records, levels, member_params, seed, azimuths, campaign_dir)
    return mark(column_specs(runs, campaign_dir, extra), data)


def _level_runs(records, levels, member_params, seed, azimuths, campaign_dir):
    """(record, parameters with ``scale``) per record x level (m/s^2) x member, and their
    :class:`LevelTags`: each record scaled to the level's horizontal PGA."""
    cache = motion_cache(campaign_dir)
    runs, extra = [], []
    for record in records:
        motion, _ = processed_motion(record, cache_dir=cache)
        pga = horizontal_peak(motion.acc)[0]
        if not pga > 0:
            raise InputError(f"record {record}: no horizontal acceleration to scale")
        for li, level in enumerate(levels):
            scale = round(level / pga, 6)
            for mi, params in enumerate(member_params):
                runs.append((record, {**params, "scale": scale}))
                extra.append(LevelTags(level, li, mi, scale, seed, azimuths, list(levels)))
    return runs, extra


def _pulse_specs(records, campaign_dir, data, column, pulses, members, headings, azimuth,
                 seed, ranges, stiffness, jobs, quiet=False, contact=None):
    """Run specs of the pulse grid (every cell x parameter set x heading), the cost said
    before any run."""
    if records:
        raise InputError("--pulses shakes the specimen with pulses: drop --records (or "
                         "--pulses to scale records)")
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    check_stiffness(stiffness)
    seed = ensemble_members.DEFAULT_SEED if seed is None else seed
    grid, sets, azimuths, runs = pulse_grid.pulse_runs(
        data, column, pulses, members, headings, azimuth, seed, ranges, stiffness, contact)
    cache = motion_cache(campaign_dir)
    pairs, tags, costs = [], [], []
    for pga, ratio, params, tag in runs:
        pairs.append((str(pulse_grid.pulse_file(cache, pga, ratio)), params))
        costs.append(round(pulse_grid.run_core_s(ratio), 3))
        tags.append(PulseTags(**{**tag, "cell": tuple(tag["cell"])}, seed=seed, pulses=pulses,
                              ranges=ranges, azimuth=azimuth, headings=headings,
                              members=members))
    n_cells = len(grid["pga_g"]) * len(grid["pgv_pga_s"])
    core_s = sum(costs)
    if not quiet:
        log.info(f"fragility: {n_cells} pulse cells x {len(sets)} parameter sets x "
                 f"{azimuths.shape[1]} heading(s) = {len(runs)} YADE runs, at most about "
                 f"{duration_text(core_s / max(jobs or 1, 1))} on {jobs or 1} core(s) (a run "
                 "stops early once the specimen has fallen or settled; finished runs are "
                 "kept and not run again)")
    specs = column_specs(pairs, campaign_dir, tags, core_s=costs)
    return mark(specs, data)




@dataclass(frozen=True)
class FragilityOptions(CampaignOptions):
    levels: str = param(None, "m/s^2", "horizontal PGA targets of the scaled records",
                        flag="--levels", metavar="A,A,...",
                        optional="8 levels 0.5-8, geometric: "
                        + ",".join(f"{v:g}" for v in DEFAULT_LEVELS))
    members: int = param(DEFAULT_MEMBERS, "", "ensemble members per record and level "
                         "(sampled like campaign ensemble, the same at every level)", 1, 10000,
                         flag="--members")
    column: str = param("both", "", "column model (both: the twin model)", flag="--column",
                        choices=COLUMN_KINDS)
    seed: int = param(ensemble_members.DEFAULT_SEED, "", "seed of the Latin hypercube", flag="--seed")
    azimuths: int = param(DEFAULT_AZIMUTHS, "", "2D block: shaking directions over 180 deg for "
                          "its worst case", 1, 360, flag="--azimuths")
    column_file: str = column_file_param(
        "every member is the described column with the sampled height and diameter "
        "tolerances (tilt and offsets as described); the 2D block has its overall height and "
        "base width")
    stiffness: str = stiffness_param("with --column-file, what kn_factor multiplies")
    pulses: str = param(None, "", "shake with a grid of one-cosine pulses instead of scaled "
                        "records: pga_g=LO:HI:N;pgv_pga_s=LO:HI:N, or the preset vsr (PGA "
                        "0.2-1.1 g x PGV/PGA 0.1-1.0 s, 10 x 10)", flag="--pulses",
                        metavar="GRID", optional="scaled records; a mesh specimen: vsr")
    azimuth: float = param(None, "deg", "pulse grid: shake along this fixed azimuth (a "
                           "table)", flag="--azimuth", metavar="DEG",
                           optional="sampled per member over 360 deg (a field rock)")
    headings: int = param(None, "", "pulse grid: sampled shaking directions per parameter "
                          "set", 1, 360, flag="--headings",
                          optional=f"{DEFAULT_HEADINGS}; 1 with --azimuth, which fixes the "
                          "direction")
    ranges: str = param(None, "", "pulse grid: ranges the members' unknowns are drawn from "
                        "(LO = HI fixes one)", flag="--ranges", metavar="NAME=LO:HI;...",
                        optional=pulse_grid.DEFAULT_RANGES)
    adaptive: bool = param(False, "", "pulse grid: run each cell only until it is decided "
                           "on which side of P = 0.5 it lies (the 2D block as a guide: a few "
                           "runs near its threshold, one probe run elsewhere; more where a "
                           "cell's Wilson interval still holds 0.5 or a probe disagrees)",
                           flag="--adaptive")
    contact_file: str = contact_file_param(
        "its damping and friction for every member (not sampled or drawn), its kn what "
        "kn_factor multiplies (scaled records, replacing --stiffness's) or every run's kn "
        "(pulse grid); a --ranges of a field it sets is refused")
    TAKES_JOBS = True

    def check(self):
        refuse_ignored_stiffness(self, contact_of(self), self.column_file is not None)
        if self.levels is not None:
            parse_levels(self.levels)
        ensemble_members.check_seed(self.seed)
        if self.pulses is not None:
            parse_grid(self.pulses)
        if self.levels is not None and (self.pulses is not None or (
                self.column_file is not None and "mesh" in column_file_description(
                    self.column_file, meshes=True))):       # a mesh: the pulse grid
            raise InputError(LEVELS_WITH_PULSES)
        if self.ranges is not None:
            pulse_grid.parse_ranges(self.ranges)
        if self.adaptive and self.pulses is None and self.column_file is None:
            raise InputError("--adaptive belongs to the pulse grid: add --pulses")
        if self.azimuth is not None and not (math.isfinite(self.azimuth)
                                             and 0 <= self.azimuth < 360):
            raise InputError(f"--azimuth must be in [0, 360) deg, got {self.azimuth:g}")
        if self.azimuth is not None and self.headings not in (None, 1):
            raise InputError(f"--azimuth fixes the direction: --headings {self.headings} "
                             "would repeat it (leave --headings out, or drop --azimuth to "
                             "sample directions)")

    def kwargs(self):
        headings = self.headings if self.headings is not None else \
            1 if self.azimuth is not None else DEFAULT_HEADINGS    # a fixed direction: one
        return {**super().kwargs(), "headings": headings,
                "levels": None if self.levels is None else parse_levels(self.levels)}


def drive(run, records, campaign_dir, options, gate=None):
    """Run the campaign; with ``adaptive`` (pulse grid) in stages that decide, cell by
    cell, on which side of P = 0.5 it lies (:func:`pulse_adaptive.next_targets`): first
    :data:`pulse_adaptive.ADAPTIVE_FIRST_RUNS` runs where the 2D block of the same members
    and directions is uncertain or steps (and one cell either side in PGA), one probe run
    elsewhere; then a cell whose Wilson interval still holds 0.5 doubles its runs (up to
    the full grid's), and a probe goes to the first count where it disagrees with the
    block or a neighbour; until nothing changes (at most :data:`pulse_adaptive.MAX_STAGES`
    stages). A cell's runs are taken in :func:`pulse_adaptive.run_order`."""
    if not options.get("adaptive"):
        return run(options)
    if gate is not None:          # before the specs: a grid of hours takes minutes to build
        runs, core_s = planned_runs(records, options)
        gate("campaign fragility (adaptive; at most the full grid)", runs, core_s,
             "a smaller --pulses grid")
    full = fragility_specs(records, campaign_dir, **options)
    guide = pulse_block.block_outcomes(full)
    by_cell, guide_by_cell = {}, {}
    for spec, fell in zip(full, guide):
        by_cell.setdefault(pulse_adaptive.cell_key(spec), []).append(spec)
        guide_by_cell.setdefault(pulse_adaptive.cell_key(spec), []).append(fell)
    headings = full[0].tags.headings
    for rows in by_cell.values():
        rows.sort(key=lambda s: pulse_adaptive.run_order(s.tags.member, s.tags.heading,
                                                         headings))
    guide_p = {cell: float(np.mean(fell)) for cell, fell in guide_by_cell.items()}
    per_cell = len(full) // len(by_cell)
    result = None

    def run_stage(stage, targets):
        nonlocal result
        chosen = [s.run_id for cell, rows in by_cell.items() for s in rows[:targets[cell]]]
        counts = sorted(set(targets.values()))
        log.info(f"fragility (adaptive), stage {stage}: {len(chosen)} of {len(full)} runs "
                 "(runs per cell: " + ", ".join(
                     f"{n} in {sum(t == n for t in targets.values())}" for n in counts) + ")")
        result = run({**options, "only_runs": chosen, "grid_specs": full})
        return {cell: [any(c.toppled for c in summary.columns)
                       for spec in rows[:targets[cell]]
                       if (summary := finished_summary(campaign_dir, spec.run_id)) is not None]
                for cell, rows in by_cell.items()}

    _, settled = pulse_adaptive.adaptive_sampling(guide_p, per_cell, run_stage)
    if not settled:
        log.warning(f"fragility (adaptive): stopped after {pulse_adaptive.MAX_STAGES} stages "
                    "with cells still undecided (their Wilson intervals say so)")
    return result


register(Campaign("fragility", "P(toppled | PGA, PGV, PGV/PGA) by incremental dynamic analysis: "
                  "records scaled to a PGA ladder, a small ensemble per level, lognormal and "
                  "logistic fits, the 2D rigid block side by side (default records GM20, NF04)",
                  fragility_specs, run_column_spec, fragility_outputs, label="runs",
                  options=FragilityOptions, driver=drive, estimate=planned_runs))
