#!/usr/bin/env python3
"""What the shipped 200 Hz table motions lose against the providers' 800 Hz records:
``records/shake_table/table_motion_800hz.csv``, one row per test with a motion file.

Reads the same bare git mirror as ``derive_shake_table.py`` (its parsing and its
decimation are imported from there, so the 200 Hz signal is the shipped one) and
writes deterministically (reruns give the same bytes), per test:

* ``pga_800hz_g``, ``pga_200hz_g``: peak |a| (g) of the raw 800 Hz source column and of
  its decimation, the shipped file (both raw: the static offset included, as shipped);
  ``pga_ratio`` = 200 Hz / 800 Hz.
* ``pgv_800hz_m_s``, ``pgv_200hz_m_s``: peak |v| (m/s) of each signal processed as the
  toolkit processes a table motion before a run (``pipeline.records.processing``'s
  default steps: offset, taper, 0.1-25 Hz band-pass, baseline, trapezoidal integration);
  ``run_pga_ratio``: the peak |a| of that processed motion, 200 Hz over 800 Hz (what a
  run's drive loses).
* ``energy_above_25hz``, ``energy_above_80hz``, ``energy_above_100hz``: share of the
  800 Hz signal's energy (sum of a^2 with the record's mean removed, i.e. of its Arias
  intensity) above 25 Hz (the runs' band), 80 Hz and 100 Hz (the shipped Nyquist), from
  the one-sided periodogram (Parseval).
* ``above_shipped_s``: time (s) the 800 Hz |a| spends above the shipped PGA;
  ``above_shipped_m_s``: the velocity it carries there, integral of (|a| - pga_200hz)+ dt
  (m/s): the part of the peaks the shipped file does not have.
* ``peak_pulse_s``: duration (s) of the one-sided pulse of the 800 Hz acceleration (its
  mean removed) that holds its peak: the samples of the peak's sign around it.

Usage: derive_table_motion.py [MIRROR_GIT_DIR] [--out CSV]
Needs numpy, scipy, pandas and the toolkit (``pipeline``) importable.
"""
from __future__ import annotations

import argparse
import csv
import io
import os
import sys
from pathlib import Path

import numpy as np

from derive_shake_table import (COMMIT_EXPECTED, DEFAULT_MIRROR, DEFAULT_OUT, FS_OUT, FS_RAW,
                                blob_status, decimated, git, read_record)
from pipeline.constants import STANDARD_GRAVITY
from pipeline.records import processing

NAME = "table_motion_800hz.csv"
BANDS_HZ = (25.0, 80.0, 100.0)
COLUMNS = ("test", "pga_800hz_g", "pga_200hz_g", "pga_ratio", "pgv_800hz_m_s",
           "pgv_200hz_m_s", "run_pga_ratio", *(f"energy_above_{f:g}hz" for f in BANDS_HZ),
           "above_shipped_s", "above_shipped_m_s", "peak_pulse_s")


def run_peaks(acc_g: np.ndarray, fs: float, name: str) -> tuple[float, float]:
    """Peak |a| (g) and |v| (m/s) of ``acc_g`` (g, one axis, ``fs`` Hz) processed as a run's
    table motion is (the default processing steps)."""
    enz = np.zeros((len(acc_g), 3))
    enz[:, 0] = acc_g * STANDARD_GRAVITY
    acc, vel, _, _ = processing.process(enz, 1.0 / fs, steps=processing.DEFAULT_STEPS,
                                        name=name)
    return float(np.max(np.abs(acc[:, 0]))) / STANDARD_GRAVITY, float(np.max(np.abs(vel[:, 0])))


def energy_above(acc_g: np.ndarray, fs: float, freqs_hz) -> list[float]:
    """Share of sum((a - mean)^2) above each frequency (Hz), from the one-sided periodogram."""
    x = acc_g - np.mean(acc_g)
    power = np.abs(np.fft.rfft(x)) ** 2
    power[1:(len(x) + 1) // 2] *= 2.0          # one-sided: every bin but DC and Nyquist twice
    f = np.fft.rfftfreq(len(x), 1.0 / fs)
    total = float(np.sum(power))
    return [float(np.sum(power[f > fc])) / total for fc in freqs_hz]


def peak_pulse_s(acc_g: np.ndarray, fs: float) -> float:
    """Duration (s) of the run of samples of one sign, the record's mean removed, that holds
    the largest |a|."""
    x = acc_g - np.mean(acc_g)
    k = int(np.argmax(np.abs(x)))
    other = np.flatnonzero(np.sign(x) != np.sign(x[k]))
    start = other[other < k].max() + 1 if np.any(other < k) else 0
    end = other[other > k].min() if np.any(other > k) else len(x)
    return (end - start) / fs


def measures(test: str, acc_800_g: np.ndarray) -> list:
    """One row of the table (COLUMNS) for the raw 800 Hz acceleration (g)."""
    acc_200_g = decimated(acc_800_g)
    pga_800, pga_200 = float(np.max(np.abs(acc_800_g))), float(np.max(np.abs(acc_200_g)))
    run_800 = run_peaks(acc_800_g, FS_RAW, f"{test} (800 Hz)")
    run_200 = run_peaks(acc_200_g, FS_OUT, f"{test} (200 Hz)")
    excess = np.clip(np.abs(acc_800_g) - pga_200, 0.0, None)
    return [test, pga_800, pga_200, pga_200 / pga_800, run_800[1], run_200[1],
            run_200[0] / run_800[0], *energy_above(acc_800_g, FS_RAW, BANDS_HZ),
            np.count_nonzero(excess) / FS_RAW,
            float(np.sum(excess)) / FS_RAW * STANDARD_GRAVITY, peak_pulse_s(acc_800_g, FS_RAW)]


def table_text(rows: list[list]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([row[0], *(f"{v:.6g}" for v in row[1:])])
    return buf.getvalue()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mirror", nargs="?", default=DEFAULT_MIRROR)
    ap.add_argument("--out", default=str(DEFAULT_OUT / NAME))
    args = ap.parse_args(argv)
    head = git(args.mirror, "rev-parse", "HEAD").decode().strip()
    if not head.startswith(COMMIT_EXPECTED):
        print(f"warning: mirror HEAD {head} is not {COMMIT_EXPECTED}", file=sys.stderr)
    rows = []
    for test, sha in sorted(blob_status(args.mirror).items()):
        if sha is not None:
            rows.append(measures(test, read_record(args.mirror, test)[:, 1]))
    out = Path(args.out)
    part = out.with_name(out.name + ".part")
    part.write_text(table_text(rows))
    os.replace(part, out)
    print(f"{out}: {len(rows)} tests")
    return 0


if __name__ == "__main__":
    sys.exit(main())
