"""The ``ensemble`` campaign: probabilities instead of single runs.

N members of one record and column model whose uncertain inputs are sampled
reproducibly (scipy.stats.qmc Latin hypercube, the seed recorded), plus the
nominal run with the paper's values.  Outputs per record: ``ensemble_summary.json``
(toppling probability with its Wilson interval, mean downfall azimuth with a
bootstrap interval, fractions toward / away from / across the epicentre),
``members.csv`` and figures (rose with the circular density, impact times).

Ranges (``ENSEMBLE_RANGES``, all around the paper's values; override with
``--vary NAME=LO,HI``):

- ``mu_s`` 0.55-0.85: marble on marble; Hinzen (2009) used 0.7, DEM studies of
  classical marble columns use values in this band; mu_k = 0.6 / 0.7 mu_s (the
  paper's ratio, :func:`pipeline.scenario.parameters.kinetic_friction`) unless given;
- ``damping`` 0.2-0.5 around the paper's 0.36;
- ``kn_factor`` 0.5-2 (log-uniform) on the paper's 1.2e8 N/m per point: the
  rocking response changes < 0.5 % for kn 1.2e7-1.2e9 (measured on the block);
- ``height_tolerance`` and ``diameter_tolerance`` +-1 % of the nominal column
  (masonry tolerances of cut drums; a real column's geometry: ``--column-file``);
- ``rim_phase_deg`` 0 to one rim spacing: the rim discretisation moves a fall by
  up to ~12 deg (make bench); sampling its phase turns that bias into noise;
- ``tilt_deg`` 0-0.5 deg toward ``tilt_azimuth_deg`` 0-360: a column already out
  of plumb (every block leans alike; joints square to the inclined axis);
- ``drum_offset_mm`` 0-3 mm: each drum above the first sits this far at most off
  the centre of the drum below, in a random direction (seeded per member);
- ``scale`` (off by default): an amplitude scaling of the motion.

Tilt and offsets make each member a column description (``pipeline.scenario.geometry``);
with ``--column both`` the monolith beside it has the same outline and tilt.

With ``--column-file`` every member is the described column with the same sampled values
applied to its blocks (:func:`pipeline.campaign.column_file.perturbed`: tolerances on
every block, the tilt added to the described one, drum offsets on the blocks above the
first that are not joined), and ``kn_factor`` multiplies the description's contact
stiffness (``--stiffness``, as in ``campaign columns``).
"""
from dataclasses import dataclass
import logging
import math
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from pipeline.constants import COLUMN_KINDS
from pipeline import paper
from pipeline.campaign import Campaign, register
from pipeline.campaign.column_file import (check_stiffness, column_kn, mark, perturbed,
                                           summary_entry)
from pipeline.campaign.options import (CampaignOptions, column_file_param, contact_file_param,
                                       contact_of, refuse_ignored_stiffness,
                                       stiffness_param)
from pipeline.scenario.contact_file import contact_values, refuse_set_twice
from pipeline.scenario.parameters import check_time_step, kinetic_friction, param
from pipeline.campaign.column_file import description as column_file_description
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.tables import collect, write_parquet
from pipeline.files import InputError, write_csv, write_json
from pipeline.scenario import Contact, Numerics
from pipeline.simulate import check_scale, run_code_version
from pipeline.scenario.column_format import MAX_OFFSET_M
from pipeline.constants import RIM_POINTS
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.campaign.sizing import (DEFAULT_ARC_DEG, DEFAULT_MAX_MEMBERS, DEFAULT_PRECISION,
                                      run_sized, write_summaries)
from pipeline.stats.ensemble import record_summary
from pipeline.stats.pooled import pooled_summary

log = logging.getLogger(__name__)

DEFAULT_MEMBERS = 16
KEPT_TRAJECTORIES = 2          # the nominal run and the first members keep trajectory.npz
DEFAULT_SEED = 20091001        # BSSA 99(5), October 2009
ENSEMBLE_RANGES = {            # name: (low, high, "uniform" | "log")
    "mu_s": (0.55, 0.85, "uniform"),
    "damping": (0.2, 0.5, "uniform"),
    "kn_factor": (0.5, 2.0, "log"),
    "height_tolerance": (-0.01, 0.01, "uniform"),
    "diameter_tolerance": (-0.01, 0.01, "uniform"),
    "rim_phase_deg": (0.0, 360.0 / RIM_POINTS, "uniform"),
    "tilt_deg": (0.0, 0.5, "uniform"),
    "tilt_azimuth_deg": (0.0, 360.0, "uniform"),
    "drum_offset_mm": (0.0, 3.0, "uniform"),
}
GEOMETRY_KEYS = ("tilt_deg", "tilt_azimuth_deg", "drum_offset_mm")
# what --vary may ask of the parameters without a home of their own (the others are
# checked by their dataclass: Contact, Numerics; scale by simulate.check_scale)
VARY_LIMITS = {"kn_factor": (0.01, 100.0), "height_tolerance": (-0.2, 0.2),
               "diameter_tolerance": (-0.2, 0.2), "tilt_deg": (0.0, 10.0),
               "tilt_azimuth_deg": (0.0, 360.0), "drum_offset_mm": (0.0, 50.0)}


def check_seed(seed):
    """InputError unless the Latin-hypercube seed is a non-negative integer (--seed)."""
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)
                             or not 0 <= seed < 2 ** 63):
        raise InputError(f"--seed must be an integer in [0, 2^63), got {seed!r}")
    return seed


def check_vary_value(name, value):
    """InputError when ``value`` of --vary parameter ``name`` is outside what a run of
    that parameter allows (the same check as its flag)."""
    flag = f"--vary {name}="
    if name == "scale":
        check_scale(value, flag.rstrip("="))
    elif name in ("mu_s", "damping"):
        try:
            check_time_step(Contact(**{name: value}), Numerics())
        except InputError as exc:
            raise InputError(f"{flag}: {exc}") from None
    elif name == "rim_phase_deg":
        try:
            Numerics(rim_phase_deg=value)
        except InputError as exc:
            raise InputError(f"{flag}: {exc}") from None
    else:
        lo, hi = VARY_LIMITS[name]
        if not lo <= value <= hi:
            raise InputError(f"{flag}{value:g} outside the allowed range [{lo:g}, {hi:g}]")


def sample_batches(members, batch, seed, ranges=None, column="both", description=None,
                   kn=paper.COLUMN_KN_N_M):
    """Parameters of ``members`` runs in Latin-hypercube batches of ``batch``: batch 0 is
    :func:`sample_members` of ``seed`` (a fixed ensemble of ``batch`` members), batch b
    a hypercube of its own (seed [seed, b]), so that adding a batch reuses every member
    that ran."""
    rows = []
    for b in range(-(-members // batch)):
        rows += sample_members(batch, seed if b == 0 else [seed, b], ranges, column,
                               description=description, kn=kn, first_index=b * batch)
    return rows[:members]


def sample_members(members, seed, ranges=None, column="both", description=None, kn=paper.COLUMN_KN_N_M, first_index=0):
    """Parameters of ``members`` runs (list of dicts for run_column_spec), Latin hypercube
    (``seed``: an integer, or a list for a batch; members numbered from ``first_index``).

    ``description`` (a column description dict): every member is that column with the
    sampled tolerances, tilt and offsets applied
    (:func:`pipeline.campaign.column_file.perturbed`), validated; ``kn``: the contact
    stiffness the sampled ``kn_factor`` multiplies."""
    ranges = dict(ENSEMBLE_RANGES if ranges is None else ranges)
    if not (isinstance(members, int) and 1 <= members <= 10000):
        raise InputError(f"--members must be an integer in [1, 10000], got {members!r}")
    names = sorted(ranges)
    rng = seed if isinstance(seed, int) else np.random.default_rng(seed)
    unit = qmc.LatinHypercube(d=len(names), seed=rng).random(members)
    rows = []
    for index, u in enumerate(unit, start=first_index):
        v = {}
        for name, x in zip(names, u):
            lo, hi, kind = ranges[name]
            v[name] = float(math.exp(math.log(lo) + x * (math.log(hi) - math.log(lo)))
                            if kind == "log" else lo + x * (hi - lo))
        height = paper.COLUMN_HEIGHT_M * (1 + v.get("height_tolerance", 0.0))
        diameter = paper.COLUMN_HEIGHT_M / paper.COLUMN_HD * (1 + v.get("diameter_tolerance", 0.0))
        mu_s = round(v.get("mu_s", paper.MU_STATIC), 6)
        params = {"column": column, "hd": round(height / diameter, 6), "height": round(height, 6),
                  "mu_s": mu_s, "mu_k": kinetic_friction(mu_s),
                  "damping": round(v.get("damping", paper.DAMPING_RATIO), 6),
                  "kn": round(kn * v.get("kn_factor", 1.0), 1),
                  "rim_phase_deg": round(v.get("rim_phase_deg", 0.0), 6)}
        if "scale" in v:
            params["scale"] = round(v["scale"], 6)
        if description is not None:
            params["column_file"] = described_member(description, v, _first(seed), index)
        elif any(v.get(k) for k in GEOMETRY_KEYS):
            params["column_file"] = perturbed(
                paper_drums(height, diameter), tilt_deg=v.get("tilt_deg", 0.0),
                tilt_azimuth_deg=v.get("tilt_azimuth_deg", 0.0),
                max_offset_m=v.get("drum_offset_mm", 0.0) / 1000.0,
                rng=np.random.default_rng([_first(seed), index]))
        if "column_file" in params:             # the description fixes the sizes
            del params["hd"], params["height"]
        rows.append(params)
    return rows


def _first(seed):
    """The campaign's seed of an integer seed or a batch's [seed, b]."""
    return seed if isinstance(seed, int) else int(seed[0])


def described_member(data, v, seed, index):
    """Member ``index`` of a described column from its sampled values ``v``.  Validated
    before anything runs without the sampled offsets (sizes, tilts, statics: milliseconds;
    a member with offset joints takes about a second), whose size is checked alone."""
    args = (data, 1 + v.get("height_tolerance", 0.0), 1 + v.get("diameter_tolerance", 0.0),
            v.get("tilt_deg", 0.0), v.get("tilt_azimuth_deg", 0.0))
    member = perturbed(*args, v.get("drum_offset_mm", 0.0) / 1000.0,
                       np.random.default_rng([seed, index]))
    try:
        ColumnGeometry.from_dict(perturbed(*args))
        for k, block in enumerate(member["blocks"]):
            if max(map(abs, block.get("offset_m", [0.0, 0.0]))) > MAX_OFFSET_M:
                raise InputError(f"blocks[{k}]: offset_m above {MAX_OFFSET_M:g} m")
    except InputError as exc:
        raise InputError(f"ensemble member {index} of {data['name']}: {exc}") from None
    return member


def paper_drums(height, diameter):
    """Description of the paper's drum column (equal cylindrical drums) of this size."""
    drum = {"shape": "frustum", "height": round(height / paper.N_DRUMS, 9),
            "bottom_diameter": round(diameter, 9), "top_diameter": round(diameter, 9)}
    return {"name": "drums", "density": paper.MARBLE_DENSITY_KG_M3,
            "blocks": [dict(drum) for _ in range(paper.N_DRUMS)]}


SAMPLED_CONTACT = {"mu_s": ("mu_s", "mu_k"), "damping": ("damping",)}   # range: file fields


def contact_ranges(ranges, contact, vary=None):
    """The ranges without those a contact file fixes (``contact``: its values, or None):
    its damping and friction replace the sampled ones; its kn is what kn_factor
    multiplies.  A ``vary`` range of a field the file sets is refused (one line)."""
    if not contact:
        return ranges
    refuse_set_twice(contact, [f for name in (vary or {}) for f in SAMPLED_CONTACT.get(name, ())
                               if name in SAMPLED_CONTACT], "--vary")
    return {k: v for k, v in ranges.items()
            if not any(f in contact for f in SAMPLED_CONTACT.get(k, ()))}


def with_fixed_contact(rows, contact):
    """Member parameters with a contact file's damping and friction (its kn is the base
    of their kn, given to the sampling)."""
    fixed = {k: v for k, v in (contact or {}).items() if k != "kn"}
    return [{**row, **fixed} for row in rows]


def nominal(column="both", description=None, kn=None):
    """The nominal run: the paper's values (and a description as described, with ``kn``)."""
    params = {"column": column, "hd": paper.COLUMN_HD, "mu_s": paper.MU_STATIC,
              "mu_k": paper.MU_KINETIC}
    if description is not None:
        params.update(column_file=description, kn=kn)
    return params


def ensemble_specs(records, campaign_dir, record=None, column="both", members=DEFAULT_MEMBERS,
                   seed=DEFAULT_SEED, vary=None, column_file=None, stiffness="matched",
                   batch=None, record_members=None, contact_file=None, **_):
    """Specs of the nominal run and ``members`` members per record (``record_members``:
    {record: members} overrides it per record), sampled in batches of ``batch``; a
    contact file fixes what it sets (:func:`contact_ranges`)."""
    data = column_file_description(column_file)
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
    tags = [{"member": m, "keep_trajectory": m < KEPT_TRAJECTORIES} for m in member_numbers]
    return mark(column_specs(runs, campaign_dir, tags, seed=seed), data)


def ensemble_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline.figures.ensemble import plot_ensemble
    campaign_dir = Path(campaign_dir)
    runs, _ = collect(specs, "ensemble", campaign_dir)
    if runs.empty:
        return {"code_version": run_code_version(), **summary_entry(specs), "figures": []}
    member_of = {s.run_id: s.tags["member"] for s in specs}
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
        summary = record_summary(sub, record_id, specs[0].tags["seed"])
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
    if len(records) > 1:
        pooled = pooled_summary(runs)
        if pooled is not None:
            pooled["cost"] = yade_cost(campaign_dir, runs["run_id"])
            write_json(campaign_dir / POOLED_FILE, pooled)
            if figures:
                from pipeline.figures.ensemble import plot_pooled
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
                        flag="--record", metavar="ID_OR_FILE")
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
        + "; scale=LO,HI samples an amplitude scaling", flag="--vary", metavar="NAME=LO,HI")
    column_file: str = column_file_param(
        "every member is the described column with the sampled height and diameter "
        "tolerances on every block, the tilt added to its own and the drum offsets on the "
        "blocks above the first (joined blocks keep theirs); with --column both a monolith "
        "of its outline stands beside it")
    stiffness: str = stiffness_param("with --column-file, what kn_factor multiplies")
    contact_file: str = contact_file_param(
        "its damping and friction for every member (not sampled), its kn what kn_factor "
        "multiplies (replacing --stiffness's)")

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


def parse_vary(items):
    ranges = {}
    for item in items or []:
        name, _, values = item.partition("=")
        try:
            lo, hi = (float(v) for v in values.split(","))
        except ValueError:
            raise InputError(f"--vary {item!r}: expected NAME=LO,HI") from None
        if name not in ENSEMBLE_RANGES and name != "scale":
            raise InputError(f"--vary: unknown parameter {name!r} (known: "
                             f"{', '.join(ENSEMBLE_RANGES)}, scale)")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise InputError(f"--vary {item!r}: need finite LO <= HI")
        if name in ranges:
            raise InputError(f"--vary {name} given twice")
        check_vary_value(name, lo)
        check_vary_value(name, hi)
        kind = ENSEMBLE_RANGES.get(name, (0, 0, "uniform"))[2]
        if kind == "log" and lo <= 0:
            raise InputError(f"--vary {item!r}: {name} is sampled log-uniformly: LO > 0")
        ranges[name] = (lo, hi, kind)
    return ranges


register(Campaign("ensemble", "N members with sampled friction, damping, stiffness, "
                  "geometry tolerances and rim phase: probabilities of toppling and direction",
                  ensemble_specs, run_column_spec, ensemble_outputs, label="members",
                  options=EnsembleOptions, driver=run_sized))
