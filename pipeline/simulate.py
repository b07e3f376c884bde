"""One run: a processed motion through one YADE scenario to ``summary.json``.

    record -> Motion (pipeline.records) -> scene directory (pipeline.scenario)
           -> Trajectory -> per-column outcome (pipeline.outcome) -> summary.json
"""
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError, code_hash
from pipeline.provenance import software_versions
from pipeline.outcome.columns import summarise
from pipeline.outcome.summary import RunSummary
from pipeline.scenario import RunParams, run_yade, scene_params, write_scenario
from pipeline.scenario.colonnade_file import to_dict as colonnade_to_dict
from pipeline.scenario.parameters import MAX_SCALE


# the code that turns a motion and parameters into an outcome: one list for the run ids,
# summary.json's code hash and the Dask workers' check
RUN_CODE = ("scenario", "outcome", "motion", "simulate", "yade_scripts")


def run_code_version():
    """Hash of the code that turns a motion and parameters into an outcome (RUN_CODE)."""
    return code_hash(*RUN_CODE)


def check_scale(value, flag="--scale"):
    """InputError unless 0 <= value <= MAX_SCALE (finite)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not (math.isfinite(value) and 0.0 <= value <= MAX_SCALE):
        raise InputError(f"{flag} {value!r} outside the allowed range [0, {MAX_SCALE:g}]")


def motion_window(motion, window):
    """``window`` = (start_s, end_s) on the record's clock (s after the record's first
    sample, as every time a user reads) as times on ``motion``'s own clock."""
    start, end = (float(t) - motion.start_in_file_s for t in window)
    if -1e-9 < start < 0.0:         # the motion's first sample, but for round-off
        start = 0.0
    if not (math.isfinite(start) and math.isfinite(end) and 0.0 <= start < end):
        raise InputError(f"window {window[0]:g}-{window[1]:g} s (record's clock) must lie "
                         f"within the motion, which starts at {motion.start_in_file_s:g} s")
    return start, end


def drive_motion(motion, window=None, rotate_deg=0.0, scale=1.0):
    """The pedestal's motion: ``motion`` cut to ``window`` = (start_s, end_s) on the
    record's clock, turned clockwise by ``rotate_deg`` and scaled by ``scale``."""
    if window is not None:
        motion = motion.window(*motion_window(motion, window))
    return motion.rotate(rotate_deg).scale(scale)


def back_azimuth_of(motion, override=None):
    """Back azimuth (deg) from the command line or the motion's metadata; None if unknown."""
    if override is not None:
        if not (math.isfinite(override) and 0.0 <= override < 360.0):
            raise InputError(f"--back-azimuth {override:g} not in [0, 360)")
        return float(override)
    return motion.back_azimuth


PRECHECK_MARGIN = 0.9   # skip YADE only below 90 % of the rigid-block thresholds


def movable_samples(drive, columns, contact):
    """Per sample of ``drive``: True where a body at rest could start to rock or slide
    (rigid-body statics): the horizontal acceleration reaches (g + a_up) min(uplift
    ratio, mu_s) x margin, or the vertical cancels gravity.

    A column's uplift ratio (``params.json`` columns[].uplift_ratio, from
    :mod:`pipeline.scenario.geometry`) is the smallest, over its joints, of the
    horizontal distance from the rocking edge to the centre of mass of the stack above
    over that centre's height: d/h for a cylinder; lower for a heavy wide capital."""
    tan_alpha = min(c["uplift_ratio"] for c in columns)
    effective_g = MODEL_GRAVITY + drive.acc[:, 2]
    horizontal = np.hypot(drive.acc[:, 0], drive.acc[:, 1])
    limit = PRECHECK_MARGIN * effective_g * min(tan_alpha, contact.mu_s)
    return (effective_g <= 0) | (horizontal >= limit)


def can_move(drive, columns, contact):
    """False when no body can rock or slide at any sample (see :func:`movable_samples`)."""
    return bool(movable_samples(drive, columns, contact).any())


def quiet_window(drive, columns, contact, lead_s):
    """Times (s, on the motion's clock) between which the scene must simulate:
    ``start_s``, ``lead_s`` before the first sample that can move a body at rest (on the
    sample grid, not before 0), and ``quiet_after_s``, one sample after the last such
    sample (after it no sample can set a resting body moving).  None when no sample can."""
    movable = np.flatnonzero(movable_samples(drive, columns, contact))
    if not len(movable):
        return None
    first = max(0, movable[0] - int(math.floor(lead_s / drive.dt + 1e-9)))
    last = min(movable[-1] + 1, drive.npts - 1)
    return first * drive.dt, last * drive.dt


def geometry_parameters(column):
    """Summary parameters of a described column (none for the paper's columns): hd,
    height, drums and density of the description, its name and the description itself;
    of a colonnade its name and its description (``colonnade``)."""
    g = column.geometry
    if g is None:
        return {}
    if column.colonnade is not None:
        return {"column_file": (column.column_file if isinstance(column.column_file, str)
                                else column.colonnade.name),
                "colonnade": colonnade_to_dict(column.colonnade)}
    return {**column.sizes(),
            "column_file": (column.column_file if isinstance(column.column_file, str)
                            else g.name), "geometry": g.to_dict()}


def simulate(motion, out_dir, run=None, back_azimuth=None, record=None, motion_file=None,
             timeout_s=None):
    """Run one scenario of ``motion`` (a processed :class:`~pipeline.motion.Motion`) and
    write ``out_dir/summary.json`` last (atomically); return its
    :class:`~pipeline.outcome.summary.RunSummary`.  ``run``: the run's parameters, whole
    (:class:`~pipeline.scenario.parameters.RunParams`: column, contact, numerics and
    drive; default the paper's, the whole motion).  The drive's ``window`` (s) and the
    summary's times are on the record's clock; the scene and its trajectory on the
    motion's.
    """
    run = RunParams() if run is None else run
    column, contact, numerics = run.column, run.contact, run.numerics
    window, rotate_deg, scale = run.drive.window, run.drive.rotate_deg, run.drive.scale
    if back_azimuth is not None:
        motion = dataclasses.replace(motion, meta=dict(motion.meta,
                                                       back_azimuth_deg=back_azimuth_of(
                                                           motion, back_azimuth)))
    drive = drive_motion(motion, window, rotate_deg, scale)
    signal_end = motion.meta.get("signal_end_s")
    if signal_end is not None:          # the stop checks treat the motion as over there
        shift = drive.start_in_file_s - motion.start_in_file_s     # the window's start
        signal_end = float(min(max(signal_end - shift, 0.0), drive.duration))
    params = scene_params(columns=column.specs(), colonnade=column.colonnade,
                          contact=contact, numerics=numerics,
                          motion_duration=drive.duration,
                          t_max=None if signal_end is None else signal_end + numerics.tail_s)
    params = dataclasses.replace(params, signal_end_s=signal_end)
    out_dir = Path(out_dir)
    for name in ("summary.json", "trajectory.npz", "yade.log"):   # none of an earlier run
        (out_dir / name).unlink(missing_ok=True)
    started = time.perf_counter()
    window_s = quiet_window(drive, params.columns, contact, numerics.quiet_lead_s)
    if window_s is not None and numerics.quiet_motion == "skip":
        params = dataclasses.replace(params, start_s=window_s[0], quiet_after_s=window_s[1])
    write_scenario(out_dir, params, drive)
    trajectory = run_yade(out_dir, timeout_s=timeout_s) if window_s is not None else None
    parameters = {**run.to_dict(), **geometry_parameters(column),
                  "dt_factor": params.dt_factor,
                  "motion_file": None if motion_file is None else str(motion_file),
                  "processing": motion.processing_mode}
    provenance = {"software": software_versions(), "motion": motion.meta.get("processing"),
                  "code": {"scenario": run_code_version(), "packages": list(RUN_CODE)}}
    record = record or motion.record_id
    if trajectory is None:
        summary = RunSummary.still(
            record, params.columns, back_azimuth_deg=drive.back_azimuth,
            parameters=parameters,
            note="not simulated: the horizontal acceleration stays below the uplift and "
                 "sliding thresholds at every sample, so no body can move",
            motion_end_s=drive.duration + drive.start_in_file_s,
            wall_s=time.perf_counter() - started, provenance=provenance,
            start_in_file_s=drive.start_in_file_s,
            colonnade=None if column.colonnade is None else column.colonnade.name)
    else:
        summary = summarise(trajectory, record=record, back_azimuth_deg=drive.back_azimuth,
                            parameters=parameters, provenance=provenance,
                            quiet_after_s=params.quiet_after_s,
                            start_in_file_s=drive.start_in_file_s,
                            colonnade=None if column.colonnade is None
                            else column.colonnade.name)
    summary.save(out_dir / "summary.json")
    return summary
