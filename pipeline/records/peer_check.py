"""Processed peaks against PEER's own: does the processing keep what topples a column?

PEER's records (NGA-West2 triplets, FEMA P695 pairs) are already processed by PEER.
For each, the RotD50 (Boore 2010) PGA and PGV of our processed motion are compared
with (a) the same measure of PEER's record as given (acceleration untouched, velocity
its integral: ``--processing none``), and (b) for NGA-West2, the flatfile's RotD50 PGA
and PGV.  FEMA P695's pulse-like flag marks the pulse records.  Written by ``records``
as ``peer_check.csv``; the report quotes its median and worst ratios.
"""
import numpy as np
import pandas as pd

from pipeline.files import csv_true_column

ROTATIONS_DEG = np.arange(0.0, 180.0, 1.0)


def rotd(east, north, percentile=50.0):
    """RotD (Boore 2010) of two horizontal series: the ``percentile`` over rotation angles
    0-179 deg of the peak |x cos a + y sin a|."""
    angles = np.radians(ROTATIONS_DEG)
    peaks = np.abs(np.outer(np.asarray(east), np.cos(angles))
                   + np.outer(np.asarray(north), np.sin(angles))).max(axis=0)
    return float(np.percentile(peaks, percentile))


def rotd50(series):
    """RotD50 of the horizontals of an (n, 3) East/North/Up series."""
    return rotd(series[:, 0], series[:, 1])


def peer_row(record_id, motion, given):
    """One row (dict) comparing the processed ``motion`` with ``given`` (PEER's record as
    given) and the flatfile's values in its ``meta["peer_reference"]``; None when the
    record is not PEER's."""
    ref = motion.meta.get("peer_reference")
    if not ref:
        return None
    pga, pgv = rotd50(motion.acc), rotd50(motion.vel)
    pga_given, pgv_given = rotd50(given.acc), rotd50(given.vel)
    row = {"id": record_id, "rsn": ref.get("rsn"), "source": ref["source"],
           "pulse_like": ref.get("pulse_like"), "pga_ms2": pga, "pgv_ms": pgv,
           "given_pga_ms2": pga_given, "given_pgv_ms": pgv_given,
           "pga_ratio_given": pga / pga_given, "pgv_ratio_given": pgv / pgv_given,
           "flatfile_pga_ms2": None, "flatfile_pgv_ms": None,
           "pga_ratio_flatfile": None, "pgv_ratio_flatfile": None}
    if ref["measure"] == "RotD50":
        row.update(flatfile_pga_ms2=ref["pga_ms2"], flatfile_pgv_ms=ref["pgv_ms"],
                   pga_ratio_flatfile=pga / ref["pga_ms2"], pgv_ratio_flatfile=pgv / ref["pgv_ms"])
    return row


def peer_table(motions, given_motion):
    """DataFrame of :func:`peer_row` for (record id, Motion) pairs of PEER's records;
    ``given_motion(record_id)`` returns the record as given (processing "none")."""
    rows = [peer_row(rid, m, given_motion(rid)) for rid, m in motions
            if m.meta.get("peer_reference")]
    return pd.DataFrame(rows)


def summary(table):
    """Median and worst ratios, all records and pulse-like ones (dict, JSON-ready)."""
    def stats(frame):
        if frame.empty:
            return {"records": 0}
        out = {"records": int(len(frame))}
        for key in ("pga_ratio_given", "pgv_ratio_given", "pga_ratio_flatfile",
                    "pgv_ratio_flatfile"):
            values = pd.to_numeric(frame[key], errors="coerce").dropna()
            if values.empty:
                continue
            worst = frame.loc[(values - 1.0).abs().idxmax()]
            out[key] = {"records": int(len(values)), "median": float(values.median()),
                        "worst": float(worst[key]),
                        "worst_id": str(worst["id"])}
        return out
    pulses = table[csv_true_column(table["pulse_like"])] if not table.empty else table
    return {"all": stats(table), "pulse_like": stats(pulses)}
