"""The ``ensemble`` campaign: probabilities instead of single runs.

N members of one record and column model whose uncertain inputs are sampled
reproducibly (scipy.stats.qmc Latin hypercube, the seed recorded), plus the
nominal run with the paper's values.  Outputs per record: ``ensemble_summary.json``
(toppling probability with its Wilson interval, mean downfall azimuth with a
bootstrap interval, fractions toward / away from / across the epicentre),
``members.csv`` and figures (rose with the circular density, impact times).

The members' parameters, their ranges and sources:
:mod:`pipeline.campaign.ensemble_members`.
"""
from dataclasses import dataclass
import logging
from pathlib import Path

from pipeline.constants import COLUMN_KINDS
from pipeline import paper
from pipeline.campaign import Campaign, register
from pipeline.campaign.column_file import check_stiffness, column_kn, mark, summary_entry
from pipeline.campaign.ensemble_members import (DEFAULT_SEED, ENSEMBLE_RANGES, check_seed,
                                                contact_ranges, nominal, parse_vary,
                                                sample_batches, with_fixed_contact)
from pipeline.campaign.options import (CampaignOptions, column_file_param, contact_file_param,
                                       contact_of, refuse_ignored_stiffness,
                                       stiffness_param)
from pipeline.scenario.contact_file import contact_values
from pipeline.scenario.parameters import param
from pipeline.campaign.column_file import description as column_file_description
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.tables import (collect, colonnade_table, write_colonnade_files,
                                      write_parquet)
from pipeline.files import InputError, write_csv, write_json
from pipeline.simulate import run_code_version
from pipeline.campaign.sizing import (DEFAULT_ARC_DEG, DEFAULT_MAX_MEMBERS, DEFAULT_PRECISION,
                                      run_sized, write_summaries)
from pipeline.stats.ensemble import record_summary
from pipeline.stats.pooled import pooled_summary
from pipeline.campaign.tags import EnsembleTags

log = logging.getLogger(__name__)

DEFAULT_MEMBERS = 16
KEPT_TRAJECTORIES = 2          # the nominal run and the first members keep trajectory.npz

def ensemble_specs(records, campaign_dir, record=None, column="both", members=DEFAULT_MEMBERS,
                   seed=DEFAULT_SEED, vary=None, column_file=None, stiffness="matched",
                   batch=None, record_members=None, contact_file=None):
    """Specs of the nominal run and ``members`` members per record (``record_members``:
    {record: members} overrides it per record), sampled in batches of ``batch``; a
    contact file fixes what it sets (:func:`contact_ranges`)."""
    data = column_file_description(column_file, colonnades=True)
    records = list(records or []) + ([record] if record else [])
    if not records:
        raise InputError("campaign ensemble needs --record ID_OR_FILE (or --records/--set)")
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    check_stiffness(stiffness)
    contact = None if contact_file is None else contact_values(contact_file)
    ranges = contact_ranges(dict(ENSEMBLE_RANGES, **(vary or {})), contact, vary)
    batch = batch or members
    counts = {rec: (record_members or {}).get(rec, members) for rec in records}
    most = max(counts.values())
    if data is None:
        member_params = sample_batches(most, batch, seed, ranges, column,
                                       kn=(contact or {}).get("kn", paper.COLUMN_KN_N_M))
        nominal_params = nominal(column)
    else:
        kn = (contact or {}).get("kn") or column_kn(data, stiffness)
        member_params = sample_batches(most, batch, seed, ranges, column, description=data,
                                       kn=kn)
        nominal_params = nominal(column, data, kn)
    member_params = with_fixed_contact(member_params, contact)
    nominal_params = {**nominal_params, **(contact or {})}
    runs, member_numbers = [], []
    for rec in records:
        runs.append((rec, nominal_params))
        runs += [(rec, p) for p in member_params[:counts[rec]]]
        member_numbers += range(-1, counts[rec])        # -1: the nominal run
    # trajectories of the first members only: summaries for all
    return mark(column_specs(runs, campaign_dir, [EnsembleTags(m, seed) for m in member_numbers],
                             [m < KEPT_TRAJECTORIES for m in member_numbers]), data)


def ensemble_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline.figures.ensemble import plot_ensemble  # lazy: matplotlib, not imported by a run or after Ctrl-C
    campaign_dir = Path(campaign_dir)
    runs, _ = collect(specs, "ensemble", campaign_dir)
    if runs.empty:
        return {"code_version": run_code_version(), **summary_entry(specs), "figures": []}
    member_of = {s.run_id: s.tags.member for s in specs}
    runs.insert(1, "member", runs["run_id"].map(member_of))
    described = summary_entry(specs)
    if described:
        runs.insert(2, "description", described["column_file"]["name"])
    records = list(dict.fromkeys(runs["record_id"]))
    summaries, written = [], []
    for record_id in records:
        out = campaign_dir if len(records) == 1 else campaign_dir / record_id
        sub = runs[runs["record_id"] == record_id].sort_values(["member", "column"])
        write_csv(out / "members.csv", sub)
        write_parquet(out / "members.parquet", sub)
        summary = record_summary(sub, record_id, specs[0].tags.seed)
        summary["record_input"] = next(sp.record for sp in specs
                                       if sp.record_id == record_id)
        if described:
            summary["column_file"] = described["column_file"]["name"]
        summaries.append(summary)
        if figures:
            written += plot_ensemble(sub, summary, out)
        for col in summary["columns"]:
            az = col["mean_downfall_azimuth_deg"]
            log.info(f"{record_id} {col['column']:>10}: P(toppled) {col['p_toppled']:.2f} "
                     f"[{col['p_toppled_ci95'][0]:.2f}, {col['p_toppled_ci95'][1]:.2f}]"
                     + ("" if az is None else f", mean downfall {az:.0f} deg "
                     f"(R {col['resultant_length']:.2f})"))
    write_summaries(campaign_dir, summaries)
    colonnades = colonnade_table(specs, campaign_dir)
    written += write_colonnade_files(campaign_dir, colonnades.assign(
        member=colonnades["run_id"].map(member_of)), figures, runs=runs,
        description=described.get("column_file"))
    if len(records) > 1:
        pooled = pooled_summary(runs)
        if pooled is not None:
            pooled["cost"] = yade_cost(campaign_dir, runs["run_id"])
            write_json(campaign_dir / POOLED_FILE, pooled)
            if figures:
                from pipeline.figures.ensemble import plot_pooled  # lazy: matplotlib, not imported by a run or after Ctrl-C
                written.append(plot_pooled(runs, pooled, campaign_dir))
            for col in pooled["columns"]:
                st = col["statistics"]
                errors = ", ".join(f"{name} +-{st[name]['mc_error']:.2f}" for name in
                                   ("p_toppled", "polarity", "radial_alignment")
                                   if st[name]["mc_error"] is not None)
                log.info(f"over {pooled['records']} records, {col['column']}: {col['answer']} "
                         f"(Monte Carlo error: {errors})")
    return {"code_version": run_code_version(), **described,
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}


POOLED_FILE = "pooled_summary.json"
def yade_cost(campaign_dir, run_ids):
    """What the finished runs ``run_ids`` of the campaign in ``campaign_dir`` cost: their
    number and their YADE processes' wall times summed (s); a campaign on ``--jobs`` N
    parallel processes takes about 1/N of that in wall time."""
    done = [finished_summary(campaign_dir, r) for r in dict.fromkeys(run_ids)]
    done = [s for s in done if s is not None]
    return {"runs": len(done), "yade_wall_s_total": round(float(sum(s.wall_s for s in done)), 1)}


@dataclass(frozen=True)
class EnsembleOptions(CampaignOptions):
    record: str = param(None, "", "catalogue id, record file or processed .npz",
                        flag="--record", metavar="ID_OR_FILE",
                        optional="the records of --records/--set")
    column: str = param("both", "", "column model (both: the twin model)", flag="--column",
                        choices=COLUMN_KINDS)
    members: int = param(DEFAULT_MEMBERS, "", "members of the first Latin-hypercube batch, "
                         "and of each batch added", 1, 10000, flag="--members")
    precision: float = param(DEFAULT_PRECISION, "", "members are added until P(toppled)'s "
                             "95 % interval is within +- this", 0.0, 0.5, flag="--precision",
                             low_open=True)
    arc_deg: float = param(DEFAULT_ARC_DEG, "deg", "... and, where falls gather, the mean "
                           "direction's 95 % interval narrower than this (360: P(toppled) "
                           "alone decides)", 0.0, 360.0, flag="--arc-deg", low_open=True)
    max_members: int = param(DEFAULT_MAX_MEMBERS, "", "the most members per record (equal "
                             "to --members: a fixed ensemble)", 1, 10000, flag="--max-members")
    seed: int = param(DEFAULT_SEED, "", "seed of the Latin hypercube", flag="--seed")
    vary: tuple = param((), "", "override a range: " + ", ".join(
        f"{k} {v[0]:g}-{v[1]:g}" for k, v in ENSEMBLE_RANGES.items())
        + "; scale=LO,HI samples an amplitude scaling", flag="--vary", metavar="NAME=LO,HI",
        optional="the ranges above")
    column_file: str = column_file_param(
        "every member is the described column with the sampled height and diameter "
        "tolerances on every block, the tilt added to its own and the drum offsets on the "
        "blocks above the first (joined blocks keep theirs); with --column both a monolith "
        "of its outline stands beside it; a colonnade's description: the colonnade, every "
        "column with the same tolerances, no sampled tilt or offsets (docs/colonnades.md)")
    stiffness: str = stiffness_param("with --column-file, what kn_factor multiplies")
    contact_file: str = contact_file_param(
        "its damping and friction for every member (not sampled), its kn what kn_factor "
        "multiplies (replacing --stiffness's)")
    DRIVER_ONLY = ("precision", "arc_deg", "max_members")   # the sizing driver reads these

    def check(self):
        contact = contact_of(self)
        contact_ranges(ENSEMBLE_RANGES, contact, parse_vary(self.vary))
        refuse_ignored_stiffness(self, contact, self.column_file is not None)
        if not self.members <= self.max_members:
            raise InputError(f"--max-members must lie in [--members, 10000], got "
                             f"{self.max_members}")
        check_seed(self.seed)
        parse_vary(self.vary)

    def kwargs(self):
        return {**super().kwargs(), "vary": parse_vary(self.vary)}


register(Campaign("ensemble", "N members with sampled friction, damping, stiffness, "
                  "geometry tolerances and rim phase: probabilities of toppling and direction",
                  ensemble_specs, run_column_spec, ensemble_outputs, label="members",
                  options=EnsembleOptions, driver=run_sized))

