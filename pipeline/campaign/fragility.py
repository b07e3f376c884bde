"""The ``fragility`` campaign: P(toppled | intensity) by incremental dynamic analysis.

Each record is scaled to a ladder of horizontal PGA targets (``--levels``, m/s^2,
the peak of the horizontal acceleration vector of the scaled motion; the
vertical is scaled with it) and, at every level, the same small ensemble of
column models (``pipeline.campaign.ensemble.sample_members``: friction, damping,
stiffness, geometry tolerances, rim phase; one Latin hypercube for all levels,
so each member is one column shaken ever harder) is run in YADE through the
``scale`` parameter of :func:`pipeline.simulate.simulate`.

The same scaled records shake the project's 2D rigid block
(:func:`pipeline.rocking.rocking_response_sampled`, Housner's equation and
restitution) of each member's size and slenderness (width = diameter, so
alpha = atan(d / h)), without friction limit, sliding or vertical motion: once
along the record's strongest azimuth (``az_max_acc_deg``, the direction of the
horizontal PGA: ``block2d``) and at ``--azimuths`` directions over 180 deg
(``block2d_worst``: toppled when any of them topples).

For IM = PGA, PGV (horizontal vector peaks of the scaled motion) and PGV/PGA
(unchanged by scaling: identified only across records) the outputs give the
lognormal fragility (median and dispersion beta with 95 % intervals,
:func:`pipeline.stats.ensemble.fragility_fit`) per column type, the binned
fractions with Wilson intervals, and the two-parameter logistic surface
logit P = b0 + b1 ln PGA + b2 ln(PGV/PGA) after Purvance et al. (2008)
(:func:`pipeline.stats.ensemble.logistic_surface`).  Files (see ``fragility.json``
keys in :func:`summarise`): ``fragility.json``, ``fragility_runs.csv`` (one row per
run and column, 3D and 2D), ``fragility_levels.csv`` (fraction toppled per record
and level, 3D columns beside the 2D block), figures ``fragility_curves.png``,
``fragility_2d_vs_3d.png`` and ``fragility_surface.png``.

With ``--column-file`` the members are the described column with the sampled height and
diameter tolerances (its tilt and offsets as described, none sampled), and the 2D block
has each member's overall height and base width (:func:`block_size`).
"""
from dataclasses import dataclass
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import paper
from pipeline.campaign import Campaign, register
from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.column_file import (check_stiffness, column_kn, mark, summary_entry)
from pipeline.campaign.options import CampaignOptions, column_file_param, stiffness_param
from pipeline.scenario.parameters import param
from pipeline.campaign.column_file import description as column_file_description
from pipeline.campaign.definitions import (column_specs, motion_cache, pulse_record,
                                           run_code_version, run_column_spec)
from pipeline.campaign import ensemble   # module: imported while ensemble may still load
from pipeline.campaign.tables import collect
from pipeline.constants import COLUMN_KINDS, MODEL_GRAVITY
from pipeline.campaign import pulse_grid
from pipeline.campaign.pulse_grid import block_size
from pipeline.files import InputError, duration_text, json_safe, write_csv, write_json
from pipeline.motion import Motion
from pipeline.motion.measures import horizontal_peak, record_parameters
from pipeline.records import processed_motion
from pipeline.rocking import block_constants, rocking_response_sampled
from pipeline.stats.ensemble import (binned_fractions, fragility_fit, logistic_surface,
                                     wilson_interval)

DEFAULT_LEVELS = tuple(round(float(v), 3) for v in np.geomspace(0.5, 8.0, 8))   # m/s^2
DEFAULT_MEMBERS = 4
DEFAULT_AZIMUTHS = 12
DEFAULT_HEADINGS = 4            # pulse grid: shaking directions per parameter set
BLOCK_T_AFTER_S = 30.0          # free rocking after the motion, at most (2D model)
BLOCK_MAX_STEP_S = 1e-3         # 2D model integration step, at most
BLOCK_CHUNK_SAMPLES = 10_000_000   # acceleration samples x cases integrated at once (memory)
# intensity measures: name -> (runs-table column, unit, label)
INTENSITY_MEASURES = {"PGA": ("pga_m_s2", "m/s^2", "PGA (m/s$^2$)"),
                      "PGV": ("pgv_m_s", "m/s", "PGV (m/s)"),
                      "PGV/PGA": ("pgv_pga_s", "s", "PGV/PGA (s)")}
MODELS_3D = ("monolithic", "drums")
MODELS_2D = ("block2d", "block2d_worst")
# amplitude-dependent record parameters, rescaled to the scaled motion in the runs table
SCALED_LINEAR = ("pga", "pgv", "pgd")
SCALED_SQUARE = ("arias",)


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


def fragility_specs(records, campaign_dir, levels=DEFAULT_LEVELS, members=DEFAULT_MEMBERS,
                    column="both", seed=None, azimuths=DEFAULT_AZIMUTHS, column_file=None,
                    stiffness="matched", pulses=None, azimuth=None,
                    headings=DEFAULT_HEADINGS, ranges=None, jobs=None, only_runs=None,
                    adaptive=False, **_):
    """Run specs: every record x level x member; ``scale`` = level / PGA of the record.
    With ``column_file`` every member is the described column with the sampled height
    and diameter tolerances (its own tilt and offsets as described), and the 2D block
    has each member's overall height and base width.  With ``pulses`` (the default for
    a mesh specimen: the preset vsr) the pulse grid of :mod:`pipeline.campaign.pulse_grid`
    instead."""
    data = column_file_description(column_file, meshes=True)
    mesh = data is not None and "mesh" in data
    if pulses is None and mesh and not records:
        pulses = "vsr"
        print("fragility: a mesh specimen: the pulse grid vsr (PGA 0.2-1.1 g x PGV/PGA "
              "0.1-1.0 s, 10 x 10; --pulses to change it)", flush=True)
    if pulses is not None:
        specs = _pulse_specs(records, campaign_dir, data, column, pulses, members, headings,
                             azimuth, seed, ranges, stiffness, jobs, quiet=only_runs is not None)
        if only_runs is not None:
            keep = set(only_runs)
            specs = [s.tagged(sampling="adaptive") for s in specs if s.run_id in keep]
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
    levels = parse_levels(levels)
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    if not (isinstance(azimuths, int) and 1 <= azimuths <= 360):
        raise InputError(f"--azimuths must be an integer in [1, 360], got {azimuths!r}")
    seed = ensemble.DEFAULT_SEED if seed is None else seed
    # the 2D block needs each member's height and h/d: no tilt or offset descriptions here
    ranges = {k: v for k, v in ensemble.ENSEMBLE_RANGES.items()
              if k not in ensemble.GEOMETRY_KEYS}
    if data is None:
        member_params = ensemble.sample_members(members, seed, ranges, column=column)
    else:
        member_params = ensemble.sample_members(members, seed, ranges, column=column,
                                                description=data, kn=column_kn(data, stiffness))
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
                extra.append({"level_m_s2": level, "level_index": li, "member": mi,
                              "scale": scale})
    return mark(column_specs(runs, campaign_dir, extra, seed=seed, azimuths=azimuths,
                             levels=list(levels)), data)


def _pulse_specs(records, campaign_dir, data, column, pulses, members, headings, azimuth,
                 seed, ranges, stiffness, jobs, quiet=False):
    """Run specs of the pulse grid (every cell x parameter set x heading), the cost said
    before any run."""
    if records:
        raise InputError("--pulses shakes the specimen with pulses: drop --records (or "
                         "--pulses to scale records)")
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    check_stiffness(stiffness)
    seed = ensemble.DEFAULT_SEED if seed is None else seed
    grid, sets, azimuths, runs = pulse_grid.pulse_runs(
        data, column, pulses, members, headings, azimuth, seed, ranges, stiffness)
    cache = motion_cache(campaign_dir)
    pairs, tags = [], []
    for pga, ratio, params, tag in runs:
        pairs.append((str(pulse_grid.pulse_file(cache, pga, ratio)), params))
        tags.append({"mode": "pulses", "core_s": round(pulse_grid.run_core_s(ratio), 3), **tag})
    n_cells = len(grid["pga_g"]) * len(grid["pgv_pga_s"])
    core_s = sum(t["core_s"] for t in tags)
    if not quiet:
        print(f"fragility: {n_cells} pulse cells x {len(sets)} parameter sets x "
              f"{azimuths.shape[1]} heading(s) = {len(runs)} YADE runs, at most about "
              f"{duration_text(core_s / max(jobs or 1, 1))} on {jobs or 1} core(s) (a run "
              "stops early once the specimen has fallen or settled; finished runs are kept "
              "and not run again)", flush=True)
    specs = column_specs(pairs, campaign_dir, tags, seed=seed, pulses=pulses,
                         ranges=ranges, azimuth=azimuth, headings=headings, members=members)
    return mark(specs, data)



# ---------------------------------------------------------------- tables
def scaled_runs(specs, campaign_dir):
    """The 3D runs table with the record parameters of the scaled motions and the IMs."""
    runs, _ = collect(specs, "fragility", campaign_dir)
    if runs.empty:
        return runs
    by_id = {s.run_id: s.tags for s in specs}
    for key in ("level_m_s2", "level_index", "member", "scale"):
        runs.insert(2, key, runs["run_id"].map(lambda r, k=key: by_id[r][k]))
    runs.insert(2, "model", "3D")
    scale = runs["scale"].astype(float)
    runs["record_pga_h"] = runs["pga_h"]
    for column in list(runs.columns):
        stem = column.rsplit("_", 1)[0]
        if stem in SCALED_LINEAR and column.rsplit("_", 1)[1] in ("e", "n", "z", "h"):
            runs[column] = pd.to_numeric(runs[column], errors="coerce") * scale
        elif stem in SCALED_SQUARE and column.rsplit("_", 1)[1] in ("e", "n", "z", "h"):
            runs[column] = pd.to_numeric(runs[column], errors="coerce") * scale ** 2
    runs["pga_m_s2"] = runs["pga_h"]
    runs["pgv_m_s"] = runs["pgv_h"]
    runs["pgv_pga_s"] = runs["pgv_pga_h"]
    runs["toppled"] = runs["toppled"].astype(bool)
    return runs


def block_runs(specs, azimuths=None, max_step=BLOCK_MAX_STEP_S, t_after=BLOCK_T_AFTER_S):
    """The 2D rigid-block runs (one per spec, i.e. record x level x member) as a table
    with the columns of the 3D table (``model`` 2D, ``column`` block2d and
    block2d_worst); returns (table, cost dict)."""
    started = time.perf_counter()
    rows, cases = [], 0
    by_motion = {}
    for spec in specs:
        by_motion.setdefault(spec.motion_file, []).append(spec)
    for motion_file, specs_of_motion in by_motion.items():
        motion = Motion.load(motion_file)
        rp = record_parameters(motion)
        n_az = int(azimuths or specs_of_motion[0].tags.get("azimuths", DEFAULT_AZIMUTHS))
        strongest = float(rp["az_max_acc_deg"])
        directions = (strongest + np.arange(n_az) * 180.0 / n_az) % 360.0
        rad = np.radians(directions)
        along = motion.acc[:, 0:1] * np.sin(rad) + motion.acc[:, 1:2] * np.cos(rad)   # (n, n_az)
        size = max(1, BLOCK_CHUNK_SAMPLES // (motion.npts * n_az))     # specs per batch
        for c in range(0, len(specs_of_motion), size):
            group = specs_of_motion[c:c + size]
            rows += _block_batch(group, motion_file, rp, along, directions, motion.dt,
                                 max_step, t_after, motion.start_in_file_s)
            cases += len(group) * n_az
    cost = {"block2d_cases": cases, "block2d_wall_s": round(time.perf_counter() - started, 3),
            "block2d_max_step_s": max_step}
    return pd.DataFrame(rows), cost


def _block_batch(group, motion_file, rp, along, directions, dt, max_step, t_after,
                 start_in_file_s=0.0):
    """Rows of the 2D table for ``group`` (specs of one motion), integrated at once;
    times on the record's clock (the motion's + ``start_in_file_s``, s)."""
    n_az = len(directions)
    rows = []
    sizes = np.array([block_size(s.params) for s in group], float)
    heights, widths = sizes[:, 0], sizes[:, 1]
    scales = np.array([s.params.drive.scale for s in group], float)
    acc = (along[:, None, :] * scales[None, :, None]).reshape(len(along), -1)
    out = rocking_response_sampled(np.repeat(heights, n_az), np.repeat(widths, n_az), acc,
                                   dt, t_after=t_after, max_step=max_step)
    shape = (len(group), n_az)
    fell = out["overturned"].reshape(shape)
    when = out["overturn_time"].reshape(shape) + start_in_file_s
    side = out["overturn_direction"].reshape(shape)
    tilt = np.degrees(out["max_abs_theta"]).reshape(shape)
    for i, spec in enumerate(group):
        s, tags, column = spec.params.drive.scale, spec.tags, spec.params.column
        base = {"campaign": "fragility", "run_id": spec.run_id, "model": "2D",
                "scale": s, "member": tags["member"], "level_index": tags["level_index"],
                "level_m_s2": tags["level_m_s2"], "record_id": spec.record_id,
                "hd": round(heights[i] / widths[i], 6) if column.column_file is not None
                else column.hd, "height_m": float(heights[i]),
                "pga_m_s2": rp["pga_h"] * s, "pgv_m_s": rp["pgv_h"] * s,
                "pgv_pga_s": rp["pgv_pga_h"], "record_pga_h": rp["pga_h"],
                "pga_h": rp["pga_h"] * s, "pgv_h": rp["pgv_h"] * s,
                "pgv_pga_h": rp["pgv_pga_h"], "back_azimuth_deg": rp["back_azimuth_deg"],
                "alpha_rad": float(out["alpha"][i * n_az]),
                "p_per_s": float(out["p"][i * n_az]),
                "restitution": float(out["restitution"][i * n_az]),
                "motion_file": motion_file}
        toppled_any = fell[i].any()
        k = int(np.nanargmin(np.where(fell[i], when[i], np.inf))) if toppled_any \
            else int(np.argmax(tilt[i]))
        for name, j, toppled in (("block2d", 0, bool(fell[i, 0])),
                                 ("block2d_worst", k, bool(toppled_any))):
            rows.append({**base, "column": name, "toppled": toppled,
                         "shaking_azimuth_deg": float(directions[j]),
                         "downfall_azimuth_deg": _fall_azimuth(directions[j], side[i, j])
                         if fell[i, j] else math.nan,
                         "impact_time_s": float(when[i, j]) if fell[i, j] else math.nan,
                         "max_tilt_deg": float(tilt[i, j]),
                         "azimuths_toppled": int(fell[i].sum()) if name == "block2d_worst"
                         else int(fell[i, 0]),
                         "azimuths": n_az if name == "block2d_worst" else 1})
    return rows


def _fall_azimuth(shaking_azimuth, direction):
    """Azimuth a block shaken along ``shaking_azimuth`` falls toward: +1 along it, -1 opposite."""
    return float((shaking_azimuth + (0.0 if direction > 0 else 180.0)) % 360.0)


def level_table(table):
    """Fraction toppled per record and level (and over all records), one column per model."""
    rows = []
    pooled = table.assign(record_id="all records")
    for (record, level), group in pd.concat([table, pooled]).groupby(
            ["record_id", "level_m_s2"], sort=True):
        row = {"record_id": record, "level_m_s2": level,
               "pgv_m_s": float(np.exp(np.log(group["pgv_m_s"].astype(float)).mean()))}
        for column, sub in group.groupby("column"):
            k, n = int(sub["toppled"].sum()), len(sub)
            lo, hi = wilson_interval(k, n)
            row.update({f"p_{column}": k / n, f"p_{column}_lo": lo, f"p_{column}_hi": hi,
                        f"n_{column}": n})
        rows.append(row)
    out = pd.DataFrame(rows)
    for column in MODELS_3D:
        if f"p_{column}" in out:
            for block in MODELS_2D:
                if f"p_{block}" in out:
                    out[f"diff_{column}_{block}"] = out[f"p_{column}"] - out[f"p_{block}"]
    return out


# ---------------------------------------------------------------- summary
def summarise(table, specs, cost):
    """``fragility.json``: {"records", "levels_m_s2", "members", "seed", "column",
    "azimuths", "intensity_measures", "columns": {name: {"model": "3D"|"2D",
    "description", "runs", "toppled", "all_stood_up_to_m_s2" (highest PGA level below
    which no run toppled), "all_toppled_from_m_s2" (lowest level from which every run
    toppled), "PGA"|"PGV"|"PGV/PGA": {median, beta,
    median_ci95, beta_ci95, n, toppled, n_distinct, method, separated, note, unit,
    bins: [{lo, hi, im, n, toppled, fraction, ci95}]}, "logistic": {form,
    coefficients {b0, b1, b2}, se, ci95, n, toppled, method, separated, note,
    dimensionless}}}, "comparison": [{column, block, im, median_3d, median_2d,
    ratio_3d_to_2d, ...}], "levels": [per record and level fractions],
    "block2d": {...}, "cost": {...}}"""
    first = specs[0].tags
    alpha, p = _block_alpha_p(table, specs)
    described = summary_entry(specs)
    column_file = described["column_file"]["name"] if described else None
    descriptions = {
        "monolithic": "3D YADE monolithic column" if column_file is None
        else f"3D YADE monolith of the outline of {column_file}",
        "drums": "3D YADE multi-drum column" if column_file is None
        else f"3D YADE column as described in {column_file}",
        "block2d": "2D rigid block (Housner), shaken along the strongest azimuth",
        "block2d_worst": f"2D rigid block, worst of {first['azimuths']} azimuths over 180 deg"}
    columns = _column_fits(table, descriptions, alpha, p)
    comparison = _comparison(columns)
    levels = level_table(table)
    return json_safe({
        "records": list(dict.fromkeys(s.record_id for s in specs)),
        "levels_m_s2": first["levels"], "members": 1 + max(s.tags["member"] for s in specs),
        "seed": first["seed"], "column": specs[0].params.column.kind,
        **({"column_file": column_file} if column_file else {}),
        "azimuths": first["azimuths"],
        "intensity_measures": {im: {"column": key, "unit": unit,
                                    "definition": _IM_DEFINITIONS[im]}
                               for im, (key, unit, _) in INTENSITY_MEASURES.items()},
        "columns": columns, "comparison": comparison,
        "levels": levels.to_dict(orient="records"),
        "block2d": {"alpha_rad": alpha, "p_per_s": p,
                    "uplift_acc_m_s2": MODEL_GRAVITY * math.tan(alpha),
                    "restitution": "Housner, 1 - 1.5 sin^2 alpha",
                    "excitation": "horizontal acceleration projected on an azimuth; no "
                                  "vertical motion, no sliding",
                    "integrator": "pipeline.rocking.rocking_response_sampled"},
        "cost": cost})


def _block_alpha_p(table, specs):
    """The 2D block's slenderness angle alpha (rad) and frequency parameter p (1/s): the
    medians of its runs, or from the members' sizes when no block ran."""
    blocks = table[table["model"] == "2D"]
    if len(blocks):
        return float(blocks["alpha_rad"].median()), float(blocks["p_per_s"].median())
    sizes = np.array([block_size(s.params) for s in specs], float)
    hd = float(np.median(sizes[:, 0] / sizes[:, 1]))
    height = float(np.median(sizes[:, 0]))
    c = block_constants(height, height / hd)
    return c["alpha"], c["p"]


def _column_fits(table, descriptions, alpha, p):
    """Per column type present: counts, the bracketing levels, a lognormal fit and binned
    fractions per intensity measure, and the logistic surface in (PGA, PGV/PGA)."""
    columns = {}
    for name in [c for c in (*MODELS_3D, *MODELS_2D) if c in set(table["column"])]:
        sub = table[table["column"] == name]
        y = sub["toppled"].astype(bool).to_numpy()
        stood_to, toppled_from = _brackets(sub.groupby("level_m_s2")["toppled"].mean())
        entry = {"model": "3D" if name in MODELS_3D else "2D", "description": descriptions[name],
                 "runs": len(sub), "toppled": int(y.sum()),
                 "all_stood_up_to_m_s2": stood_to, "all_toppled_from_m_s2": toppled_from}
        for im, (key, unit, _) in INTENSITY_MEASURES.items():
            values = sub[key].astype(float).to_numpy()
            entry[im] = {**fragility_fit(values, y), "unit": unit,
                         "bins": binned_fractions(values, y)}
        entry["logistic"] = logistic_surface(sub["pga_m_s2"].astype(float),
                                             sub["pgv_pga_s"].astype(float), y, alpha=alpha, p=p)
        columns[name] = entry
    return columns


def _comparison(columns):
    """3D column against 2D block per intensity measure: medians, their ratio, betas,
    P(toppled) and (PGA) the bracketing levels."""
    comparison = []
    for column in MODELS_3D:
        for block in MODELS_2D:
            if column not in columns or block not in columns:
                continue
            for im in INTENSITY_MEASURES:
                m3, m2 = columns[column][im]["median"], columns[block][im]["median"]
                comparison.append({
                    "column": column, "block": block, "im": im, "median_3d": m3,
                    "median_2d": m2, "ratio_3d_to_2d": None if m3 is None or m2 is None
                    else m3 / m2, "beta_3d": columns[column][im]["beta"],
                    "beta_2d": columns[block][im]["beta"],
                    "p_toppled_3d": columns[column]["toppled"] / columns[column]["runs"],
                    "p_toppled_2d": columns[block]["toppled"] / columns[block]["runs"],
                    **({"all_stood_up_to_3d": columns[column]["all_stood_up_to_m_s2"],
                        "all_stood_up_to_2d": columns[block]["all_stood_up_to_m_s2"],
                        "all_toppled_from_3d": columns[column]["all_toppled_from_m_s2"],
                        "all_toppled_from_2d": columns[block]["all_toppled_from_m_s2"]}
                       if im == "PGA" else {})})
    return comparison


def _brackets(fraction_by_level):
    """(highest level up to which no run toppled at any level, lowest level from which
    every run toppled at every level); None where there is none."""
    fraction = fraction_by_level.sort_index()
    levels, values = fraction.index.to_numpy(float), fraction.to_numpy(float)
    none = np.cumprod(values == 0).astype(bool)               # all stood up to here
    every = np.cumprod((values == 1)[::-1]).astype(bool)[::-1]   # all toppled from here
    return (float(levels[none][-1]) if none.any() else None,
            float(levels[every][0]) if every.any() else None)


_IM_DEFINITIONS = {
    "PGA": "peak of the horizontal acceleration vector of the scaled motion",
    "PGV": "peak of the horizontal velocity vector of the scaled motion",
    "PGV/PGA": "PGV / PGA (s), unchanged by scaling: varies only between records"}



def fragility_outputs(specs, campaign_dir, failures, animations, figures=True):
    campaign_dir = Path(campaign_dir)
    if specs and specs[0].tags.get("mode") == "pulses":
        from pipeline.campaign.pulse_outputs import pulse_outputs
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
    write_json(campaign_dir / "fragility.json", summary)
    write_csv(campaign_dir / "fragility_levels.csv", level_table(table))
    written = []
    if figures:
        from pipeline.figures.fragility import plot_fragility
        written = plot_fragility(table, summary, campaign_dir)
    for name, entry in summary["columns"].items():
        fit = entry["PGA"]
        print(f"{name:>14}: {entry['toppled']}/{entry['runs']} toppled; PGA median "
              + ("-" if fit["median"] is None else
                 f"{fit['median']:.2f} m/s^2 [{fit['median_ci95'][0]:.2f}, "
                 f"{fit['median_ci95'][1]:.2f}], beta {fit['beta']:.2f}"))
    print(f"2D block: {cost['block2d_cases']} cases in {cost['block2d_wall_s']:.1f} s; "
          f"YADE: {cost['yade_runs']} runs, {cost['yade_wall_s_total']:.0f} s")
    return {"code_version": run_code_version(), **summary_entry(specs),
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}


@dataclass(frozen=True)
class FragilityOptions(CampaignOptions):
    levels: str = param(",".join(f"{v:g}" for v in DEFAULT_LEVELS), "m/s^2",
                        "horizontal PGA targets of the scaled records (8 levels 0.5-8, "
                        "geometric)", flag="--levels", metavar="A,A,...")
    members: int = param(DEFAULT_MEMBERS, "", "ensemble members per record and level "
                         "(sampled like campaign ensemble, the same at every level)", 1, 10000,
                         flag="--members")
    column: str = param("both", "", "column model (both: the twin model)", flag="--column",
                        choices=COLUMN_KINDS)
    seed: int = param(ensemble.DEFAULT_SEED, "", "seed of the Latin hypercube", flag="--seed")
    azimuths: int = param(DEFAULT_AZIMUTHS, "", "2D block: shaking directions over 180 deg for "
                          "its worst case", 1, 360, flag="--azimuths")
    column_file: str = column_file_param(
        "every member is the described column with the sampled height and diameter "
        "tolerances (tilt and offsets as described); the 2D block has its overall height and "
        "base width")
    stiffness: str = stiffness_param("with --column-file, what kn_factor multiplies")
    pulses: str = param(None, "", "shake with a grid of one-cosine pulses instead of scaled "
                        "records: pga_g=LO:HI:N;pgv_pga_s=LO:HI:N, or the preset vsr (PGA "
                        "0.2-1.1 g x PGV/PGA 0.1-1.0 s, 10 x 10; the default for a mesh "
                        "specimen)", flag="--pulses", metavar="GRID")
    azimuth: float = param(None, "deg", "pulse grid: shake along this fixed azimuth (a "
                           "table); default: sampled per member over 360 deg (a field rock)",
                           flag="--azimuth", metavar="DEG")
    headings: int = param(DEFAULT_HEADINGS, "", "pulse grid: sampled shaking directions per "
                          "parameter set (1 with --azimuth)", 1, 360, flag="--headings")
    ranges: str = param(None, "", "pulse grid: ranges the members' unknowns are drawn from "
                        f"(default {pulse_grid.DEFAULT_RANGES}; LO = HI fixes one)",
                        flag="--ranges", metavar="NAME=LO:HI;...")
    adaptive: bool = param(False, "", "pulse grid: run every member only where P is uncertain "
                           "(the 2D block as a guide, one probe run elsewhere, widened where a "
                           "probe disagrees)", flag="--adaptive")
    TAKES_JOBS = True

    def check(self):
        parse_levels(self.levels)
        ensemble.check_seed(self.seed)
        if self.pulses is not None:
            pulse_grid.parse_pulses(self.pulses)
        if self.ranges is not None:
            pulse_grid.parse_ranges(self.ranges)
        if self.adaptive and self.pulses is None and self.column_file is None:
            raise InputError("--adaptive belongs to the pulse grid: add --pulses")
        if self.azimuth is not None and not (math.isfinite(self.azimuth)
                                             and 0 <= self.azimuth < 360):
            raise InputError(f"--azimuth must be in [0, 360) deg, got {self.azimuth:g}")

    def kwargs(self):
        kwargs = {**super().kwargs(), "levels": parse_levels(self.levels)}
        if self.azimuth is not None and self.headings == DEFAULT_HEADINGS:
            kwargs["headings"] = 1          # a fixed direction: one heading
        return kwargs


def drive(run, records, campaign_dir, options, gate=None):
    """Run the campaign; with ``adaptive`` (pulse grid) in stages: every member where the
    2D block of the same members and directions is uncertain (0 < P < 1) and one cell
    either side in PGA, one probe run (first member, first direction) in every other
    cell; a probe that disagrees with the block's certainty adds its cell and one either
    side; until none does (at most :data:`pulse_grid.MAX_STAGES` stages)."""
    if not options.get("adaptive"):
        return run(options)
    full = fragility_specs(records, campaign_dir, **options)
    if gate is not None:
        gate("campaign fragility (adaptive; at most the full grid)", len(full),
             sum(s.tags["core_s"] for s in full) / len(full), "a smaller --pulses grid")
    guide = pulse_grid.block_outcomes(full)
    by_cell = {}
    for spec, fell in zip(full, guide):
        by_cell.setdefault(pulse_grid.cell_key(spec), []).append((spec, fell))
    guide_p = {cell: float(np.mean([f for _, f in rows])) for cell, rows in by_cell.items()}
    whole = pulse_grid.guide_cells(guide_p)
    probes = {cell: rows[0][0] for cell, rows in by_cell.items()}
    result = None
    for stage in range(1, pulse_grid.MAX_STAGES + 1):
        chosen = [s.run_id for cell, rows in by_cell.items() for s, _ in rows
                  if cell in whole or s is probes[cell]]
        print(f"fragility (adaptive), stage {stage}: {len(whole)} of {len(by_cell)} cells in "
              f"full, a probe run in the others: {len(chosen)} of {len(full)} runs", flush=True)
        result = run({**options, "only_runs": chosen})
        outcomes = {}
        for cell, spec in probes.items():
            summary = finished_summary(campaign_dir, spec.run_id)
            if summary is not None:
                outcomes[cell] = any(c.toppled for c in summary.columns)
        added = pulse_grid.expand(guide_p, whole, outcomes)
        if not added:
            break
        whole |= added
    return result


register(Campaign("fragility", "P(toppled | PGA, PGV, PGV/PGA) by incremental dynamic analysis: "
                  "records scaled to a PGA ladder, a small ensemble per level, lognormal and "
                  "logistic fits, the 2D rigid block side by side (default records GM20, NF04)",
                  fragility_specs, run_column_spec, fragility_outputs, label="runs",
                  options=FragilityOptions, driver=drive))
