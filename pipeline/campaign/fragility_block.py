"""The 2D rigid block of the ``fragility`` campaign: the project's Housner block
(:func:`pipeline.rocking.sampled.rocking_response_sampled`, Housner's equation and restitution)
of each member's size and slenderness (:func:`pipeline.campaign.pulse_block.block_size`),
without friction limit, sliding or vertical motion, shaken by the same scaled records as
the 3D runs: once along the record's strongest azimuth (``az_max_acc_deg``, the direction
of the horizontal PGA: ``block2d``) and at ``azimuths`` directions over 180 deg
(``block2d_worst``: toppled when any of them topples), many cases integrated at once."""
import math
import time

import numpy as np
import pandas as pd

from pipeline.campaign.pulse_block import BLOCK_MAX_STEP_S, BLOCK_T_AFTER_S, block_size
from pipeline.motion import Motion
from pipeline.motion.measures import record_parameters
from pipeline.rocking.sampled import rocking_response_sampled

DEFAULT_AZIMUTHS = 12
BLOCK_CHUNK_SAMPLES = 10_000_000   # acceleration samples x cases integrated at once (memory)


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
        n_az = int(azimuths or specs_of_motion[0].tags.azimuths)
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
                "scale": s, "member": tags.member, "level_index": tags.level_index,
                "level_m_s2": tags.level_m_s2, "record_id": spec.record_id,
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

