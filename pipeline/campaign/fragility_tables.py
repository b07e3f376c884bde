"""Tables and fits over the runs of the ``fragility`` campaign (scaled records): the 3D
runs table with the record parameters of the scaled motions (:func:`scaled_runs`), the
fraction toppled per record and level (:func:`level_table`) and ``fragility.json``
(:func:`summarise`: per column type the lognormal fit and binned fractions per intensity
measure and the logistic surface, the 3D columns against the 2D block)."""
import math

import numpy as np
import pandas as pd

from pipeline.campaign.column_file import summary_entry
from pipeline.campaign.pulse_block import block_size
from pipeline.campaign.tables import collect
from pipeline.constants import MODEL_GRAVITY
from pipeline.files import json_safe
from pipeline.hazard.fragility.checker import leaf
from pipeline.hazard.fragility.damage_states import STATES, ColumnStates, StateFits
from pipeline.hazard.fragility.file import Block2d, ColumnFits, FragilityFile
from pipeline.hazard.fragility.fits import LogisticSurface, LognormalFit
from pipeline.rocking.housner import block_constants
from pipeline.stats.ensemble import wilson_interval
from pipeline.stats.fragility import binned_fractions, fragility_fit, logistic_surface

# intensity measures: name -> (runs-table column, unit, label)
INTENSITY_MEASURES = {"PGA": ("pga_m_s2", "m/s^2", "PGA (m/s$^2$)"),
                      "PGV": ("pgv_m_s", "m/s", "PGV (m/s)"),
                      "PGV/PGA": ("pgv_pga_s", "s", "PGV/PGA (s)")}
MODELS_3D = ("monolithic", "drums")
FILE = "fragility.json"
BRACKETS = ("all_stood_up_to_m_s2", "all_toppled_from_m_s2")   # a column's bracketing levels
FILE_FIELDS = ("records", "members", "columns", "block2d")      # FragilityFile's own keys
FILE_ORDER = ("records", "levels_m_s2", "members", "seed", "column", "column_file",
              "azimuths", "intensity_measures", "columns", "comparison", "levels", "block2d",
              "cost")                                           # fragility.json's key order
MODELS_2D = ("block2d", "block2d_worst")
STATE_RANK = {state: k for k, state in enumerate(("none", *STATES))}   # runs-table labels
# amplitude-dependent record parameters, rescaled to the scaled motion in the runs table
SCALED_LINEAR = ("pga", "pgv", "pgd")
SCALED_SQUARE = ("arias",)


def scaled_runs(specs, campaign_dir):
    """The 3D runs table with the record parameters of the scaled motions and the IMs."""
    runs, _ = collect(specs, "fragility", campaign_dir)
    if runs.empty:
        return runs
    by_id = {s.run_id: s.tags for s in specs}
    for key in ("level_m_s2", "level_index", "member", "scale"):
        runs.insert(2, key, runs["run_id"].map(lambda r, k=key: getattr(by_id[r], k)))
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



def level_table(table):
    """Fraction toppled per record and level (and over all records), one column per model
    (p_COLUMN, its Wilson interval p_COLUMN_lo, p_COLUMN_hi, n_COLUMN runs); for a 3D
    column with damage states, the fraction of its runs with damage measures
    (n_COLUMN_states) that reached each state or a worse one, p_COLUMN_STATE with its
    interval (:func:`state_ranks`, as :func:`damage_state_fits` counts them)."""
    rows = []
    pooled = table.assign(record_id="all records")
    for (record, level), group in pd.concat([table, pooled]).groupby(
            ["record_id", "level_m_s2"], sort=True):
        row = {"record_id": record, "level_m_s2": level,
               "pgv_m_s": float(np.exp(np.log(group["pgv_m_s"].astype(float)).mean()))}
        for column, sub in group.groupby("column"):
            row.update(_fraction(f"p_{column}", int(sub["toppled"].sum()), len(sub)))
            row[f"n_{column}"] = len(sub)
            ranked = state_ranks(sub) if column in MODELS_3D else None
            if ranked is not None:
                row[f"n_{column}_states"] = len(ranked)
                for k, state in enumerate(STATES, start=1):
                    row.update(_fraction(f"p_{column}_{state}", int((ranked >= k).sum()),
                                         len(ranked)))
        rows.append(row)
    out = pd.DataFrame(rows)
    for column in MODELS_3D:
        if f"p_{column}" in out:
            for block in MODELS_2D:
                if f"p_{block}" in out:
                    out[f"diff_{column}_{block}"] = out[f"p_{column}"] - out[f"p_{block}"]
    return out



def summarise(table, specs, cost):
    """``fragility.json`` as a :class:`~pipeline.hazard.fragility.file.FragilityFile`, its
    parts built as their types: {"records", "levels_m_s2", "members", "seed", "column",
    "azimuths", "intensity_measures", "columns": {name: {"model": "3D"|"2D",
    "description", "runs", "toppled", "all_stood_up_to_m_s2" (highest PGA level below
    which no run toppled), "all_toppled_from_m_s2" (lowest level from which every run
    toppled), "PGA"|"PGV"|"PGV/PGA": {median, beta,
    median_ci95, beta_ci95, n, toppled, n_distinct, method, separated, note, unit,
    bins: [{lo, hi, im, n, toppled, fraction, ci95}]}, "logistic": {form,
    coefficients {b0, b1, b2}, se, ci95, n, toppled, method, separated, note,
    dimensionless}}}, "comparison": [{column, block, im, median_3d, median_2d,
    ratio_3d_to_2d, ...}], "levels": [per record and level fractions],
    "block2d": {...}, "cost": {...}, "damage_states": {3D column type: P(damage state or
    worse) fitted alike per state, :func:`damage_state_fits`}}"""
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
        "block2d_worst": f"2D rigid block, worst of {first.azimuths} azimuths over 180 deg"}
    columns, brackets = _column_fits(table, descriptions, alpha, p)
    damage = damage_state_fits(table, descriptions, alpha, p)
    comparison = _comparison(columns, brackets)
    levels = level_table(table)
    block = {"alpha_rad": alpha, "p_per_s": p,
             "uplift_acc_m_s2": MODEL_GRAVITY * math.tan(alpha),
             "restitution": "Housner, 1 - 1.5 sin^2 alpha",
             "excitation": "horizontal acceleration projected on an azimuth; no "
                           "vertical motion, no sliding",
             "integrator": "pipeline.rocking.sampled.rocking_response_sampled"}
    extra = json_safe({
        "levels_m_s2": first.levels, "seed": first.seed,
        "column": specs[0].params.column.kind,
        **({"column_file": column_file} if column_file else {}),
        "azimuths": first.azimuths,
        "intensity_measures": {im: {"column": key, "unit": unit,
                                    "definition": _IM_DEFINITIONS[im]}
                               for im, (key, unit, _) in INTENSITY_MEASURES.items()},
        "comparison": comparison, "levels": levels.to_dict(orient="records"),
        "cost": cost})
    return FragilityFile(
        columns=columns, records=tuple(dict.fromkeys(s.record_id for s in specs)),
        members=1 + max(s.tags.member for s in specs),
        block2d=Block2d(alpha_rad=alpha, p_per_s=p,
                        extra=json_safe({k: block[k] for k in list(block)[2:]}),
                        order=tuple(block)),
        damage_states=damage,
        extra=extra, order=tuple(k for k in FILE_ORDER if k in extra or k in FILE_FIELDS))


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
    columns, brackets = {}, {}
    for name in [c for c in (*MODELS_3D, *MODELS_2D) if c in set(table["column"])]:
        sub = table[table["column"] == name]
        y = sub["toppled"].astype(bool).to_numpy()
        brackets[name] = _brackets(sub.groupby("level_m_s2")["toppled"].mean())
        fits, logistic = _fits(sub, y, f"columns.{name}", alpha, p)
        columns[name] = ColumnFits(
            description=descriptions[name], model="3D" if name in MODELS_3D else "2D",
            runs=len(sub), toppled=int(y.sum()), fits=fits, logistic=logistic,
            extra=dict(zip(BRACKETS, brackets[name])),
            order=("model", "description", "runs", "toppled", *BRACKETS, *fits, "logistic"))
    return columns, brackets


def _fits(sub, y, where, alpha, p):
    """A lognormal fit with binned fractions per intensity measure and the logistic
    surface in (PGA, PGV/PGA) of the outcomes ``y`` (bool per row of ``sub``)."""
    fits = {}
    for im, (key, unit, _) in INTENSITY_MEASURES.items():
        values = sub[key].astype(float).to_numpy()
        fits[im] = leaf(LognormalFit, json_safe({**fragility_fit(values, y), "unit": unit,
                                                 "bins": binned_fractions(values, y)}),
                        FILE, f"{where}.{im}")
    surface = logistic_surface(sub["pga_m_s2"].astype(float), sub["pgv_pga_s"].astype(float),
                               y, alpha=alpha, p=p)
    return fits, leaf(LogisticSurface, json_safe(surface), FILE, f"{where}.logistic")


def _fraction(key, k, n):
    """{key: k / n, key_lo, key_hi: its Wilson 95 % interval} (NaN without runs)."""
    lo, hi = wilson_interval(k, n)
    return {key: k / n if n else math.nan, f"{key}_lo": lo, f"{key}_hi": hi}


def state_ranks(runs):
    """The damage-state rank (0 none ... 4 collapse) of each of ``runs`` (rows of one
    column type) that has damage measures, as an int Series on their index; None when no
    run has them (a runs table written before them)."""
    if "damage_state" not in runs:
        return None
    rank = runs["damage_state"].map(STATE_RANK)
    if rank.isna().all():
        return None
    return rank[rank.notna()].astype(int)


def damage_state_fits(table, descriptions, alpha, p):
    """Per 3D column type, P(damage state or worse | IM) for every state above none
    (:data:`~pipeline.hazard.fragility.damage_states.STATES`), fitted as P(toppled):
    column type -> :class:`ColumnStates`, over the runs with damage measures (None when
    no run has them)."""
    out = {}
    for name in [c for c in MODELS_3D if c in set(table["column"])]:
        sub = table[table["column"] == name]
        ranked = state_ranks(sub)
        if ranked is None:
            continue
        sub, rank = sub.loc[ranked.index], ranked.to_numpy()
        states = []
        for k, state in enumerate(STATES, start=1):
            y = rank >= k
            fits, logistic = _fits(sub, y, f"damage_states.{name}.states.{state}", alpha, p)
            states.append(StateFits(state=state, runs=len(sub), reached=int(y.sum()),
                                    fits=fits, logistic=logistic))
        out[name] = ColumnStates(description=descriptions[name], runs=len(sub),
                                 states=tuple(states))
    return out or None


def _comparison(columns, brackets):
    """3D column against 2D block per intensity measure (``columns``: name ->
    :class:`ColumnFits`; ``brackets``: name -> its two bracketing levels): medians, their
    ratio, betas, P(toppled) and (PGA) the bracketing levels."""
    comparison = []
    for column in MODELS_3D:
        for block in MODELS_2D:
            if column not in columns or block not in columns:
                continue
            for im in INTENSITY_MEASURES:
                three, two = columns[column], columns[block]
                m3, m2 = three.fits[im].median, two.fits[im].median
                comparison.append({
                    "column": column, "block": block, "im": im, "median_3d": m3,
                    "median_2d": m2, "ratio_3d_to_2d": None if m3 is None or m2 is None
                    else m3 / m2, "beta_3d": three.fits[im].beta, "beta_2d": two.fits[im].beta,
                    "p_toppled_3d": three.toppled / three.runs,
                    "p_toppled_2d": two.toppled / two.runs,
                    **({"all_stood_up_to_3d": brackets[column][0],
                        "all_stood_up_to_2d": brackets[block][0],
                        "all_toppled_from_3d": brackets[column][1],
                        "all_toppled_from_2d": brackets[block][1]}
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


