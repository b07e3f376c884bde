"""Where the members and the laboratory disagree, and what decided the runs: each test's
:class:`~pipeline.campaign.shake_table_disagreement_file.Disagreement` built from a
finished members campaign's files alone (``members.csv``, ``members_runs.csv``, each
member run's ``summary.json`` and, where kept, ``trajectory.npz``; no YADE), the error
rate of the members' majority per region (PGA bin, PGV/PGA bin, month, split) with its
Wilson 95 % interval, and the figure ``shake_table_disagreements.png``.

A member run's mechanism: toppled; else rocking when theta_max / alpha reached the
damage states' first rotation limit (uplift at the asperities); else sliding when its
residual base slide over the base width reached their first residual limit
(:data:`pipeline.outcome.damage.LEVELS`, docs/damage.md); else still.  From a trajectory,
the first uplift and first slip are the first samples past the same two limits (the tilt
of the bottom body's vertical from its placement; the horizontal shift of its base
face's centre)."""
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from pipeline.campaign.shake_table_disagreement_file import (FILE, PARAMETERS, Disagreement,
                                                             DisagreementTable, Mechanism)
from pipeline.campaign.shake_table_regions import DisagreementSummary
from pipeline.files import InputError, csv_true_column
from pipeline.outcome import Trajectory
from pipeline.outcome.columns import body_rims
from pipeline.outcome.damage import LEVELS, base_rim, rim_centre
from pipeline.outcome.summary import RunSummary

UPLIFT_RATIO = LEVELS.rotation[0]        # theta_max / alpha: uplift at the asperities
SLIDE_RATIO = LEVELS.residual[0]         # residual base slide / base width: sliding
FIGURE = "shake_table_disagreements.png"
MEMBERS_COLUMNS = ("test", "date", "split", "pga_g", "pgv_pga_s", "observed", "runs",
                   "overturned")
RUNS_COLUMNS = ("test", "member", "predicted", "run_id")


def run_evidence(run_dir):
    """What one member run did: {toppled, mechanism, tilt_over_critical, base_slip_m,
    residual_slide_m, residual_twist_deg, first_uplift_s, first_slip_s (record clock; NaN: never, or no
    trajectory), timed, and its contact parameters (NaN where its summary holds none)}."""
    summary = RunSummary.load(Path(run_dir) / "summary.json")
    column = summary.columns[0]
    damage = column.damage
    if damage is None:
        raise InputError(f"{run_dir}: summary.json holds no damage measures (written by an "
                         "older version: run it again)")
    ratio = damage.rotation_ratio
    slide = damage.max_residual_slide_m
    mechanism = (Mechanism.TOPPLED if column.toppled else
                 Mechanism.ROCKING if ratio is not None and ratio >= UPLIFT_RATIO else
                 Mechanism.SLIDING if slide >= SLIDE_RATIO * damage.base_width_m else
                 Mechanism.STILL)
    uplift_s, slip_s, timed = math.nan, math.nan, False
    path = Path(run_dir) / "trajectory.npz"
    if path.is_file():
        uplift_s, slip_s = first_times(Trajectory.load(path), damage.critical_angle_deg,
                                       damage.base_width_m)
        uplift_s += summary.start_in_file_s
        slip_s += summary.start_in_file_s
        timed = True
    return {"toppled": column.toppled, "mechanism": mechanism,
            "tilt_over_critical": math.nan if ratio is None else ratio,
            "base_slip_m": column.base_slip_m, "residual_slide_m": slide,
            "residual_twist_deg": damage.max_residual_twist_deg,
            "first_uplift_s": uplift_s, "first_slip_s": slip_s, "timed": timed,
            **contact_parameters(summary.parameters)}


def contact_parameters(parameters):
    """kn (N/m), damping, mu_s, the mesh's footprint tolerance (m) and the table motion's
    turn (deg, ``rotate_deg`` in (-180, 180]) of a run's parameters (summary.json
    ``parameters``); NaN for one it does not hold."""
    geometry = parameters.get("geometry")
    footprint = geometry.get("footprint_tolerance_m") if isinstance(geometry, dict) else None
    turn = parameters.get("rotate_deg")
    values = {"kn_n_per_m": parameters.get("kn"), "damping": parameters.get("damping"),
              "mu_s": parameters.get("mu_s"), "footprint_tolerance_m": footprint,
              "motion_turn_deg": None if turn is None else
              180.0 - (180.0 - float(turn)) % 360.0}
    return {k: math.nan if v is None else float(v) for k, v in values.items()}


def first_times(trajectory, critical_deg, base_width_m):
    """(first uplift, first slip) in s on the trajectory's clock (NaN: never) of its
    bottom body: the tilt of its vertical from its placement past UPLIFT_RATIO x
    ``critical_deg``; its base face's centre shifted horizontally past SLIDE_RATIO x
    ``base_width_m``."""
    body = trajectory.bodies[0]
    rot0 = np.asarray(body.get("initial_rotation", np.eye(3)), float)
    rot = Rotation.from_quat(np.asarray(trajectory.quat[:, 0], float)[:, [1, 2, 3, 0]])
    mats = rot.as_matrix()
    tilt = np.degrees(np.arccos(np.clip((mats @ rot0.T)[:, 2, 2], -1.0, 1.0)))
    point = rim_centre(base_rim(body_rims(body)))
    base = trajectory.pos[:, 0] + mats @ point
    start = np.asarray(body["initial_pos"], float) + rot0 @ point
    shift = np.hypot(base[:, 0] - start[0], base[:, 1] - start[1])

    def first(values, limit):
        past = np.flatnonzero(values >= limit)
        return float(trajectory.t[past[0]]) if past.size else math.nan
    return (math.nan if critical_deg is None else first(tilt, UPLIFT_RATIO * critical_deg),
            first(shift, SLIDE_RATIO * base_width_m))


def _read(path, columns, dtype):
    """A campaign table with ``columns`` at least; one-line InputError otherwise."""
    try:
        frame = pd.read_csv(path, dtype=dtype)
    except FileNotFoundError:
        raise InputError(f"{path.name} not found in {path.parent}: not a finished "
                         "shake-table members campaign") from None
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: not readable ({str(exc).splitlines()[0]})") from None
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise InputError(f"{path}: no column {missing[0]}")
    return frame


def _median(values):
    values = [v for v in values if not math.isnan(v)]
    return float(np.median(values)) if values else math.nan


def test_disagreement(row, evidence):
    """The :class:`Disagreement` of one members.csv ``row`` from its member runs'
    ``evidence`` (:func:`run_evidence`)."""
    def over(which, key):
        return _median([e[key] for e in evidence if e["toppled"] == which])
    timed = [e for e in evidence if e["timed"]]
    slipped_first = [e for e in timed if not math.isnan(e["first_slip_s"]) and (
        math.isnan(e["first_uplift_s"]) or e["first_slip_s"] < e["first_uplift_s"])]
    return Disagreement(
        test=row["test"], date=str(row["date"]), split=row["split"], pga_g=row["pga_g"],
        pgv_pga_s=row["pgv_pga_s"], observed=bool(row["observed"]), runs=len(evidence),
        overturned=sum(e["toppled"] for e in evidence),
        runs_uplift=sum(e["mechanism"] in (Mechanism.TOPPLED, Mechanism.ROCKING)
                        for e in evidence),
        runs_sliding=sum(e["mechanism"] is Mechanism.SLIDING for e in evidence),
        runs_timed=len(timed), runs_slip_first=len(slipped_first),
        median_tilt_over_critical=_median([e["tilt_over_critical"] for e in evidence]),
        max_base_slip_m=max(e["base_slip_m"] for e in evidence),
        max_residual_slide_m=max(e["residual_slide_m"] for e in evidence),
        max_residual_twist_deg=max(e["residual_twist_deg"] for e in evidence),
        first_uplift_s=_median([e["first_uplift_s"] for e in timed]),
        first_slip_s=_median([e["first_slip_s"] for e in timed]),
        **{f"{p}_{side}": over(which, p) for p in PARAMETERS
           for side, which in (("overturned", True), ("standing", False))})


def disagreement_table(campaign_dir):
    """Every scored test's :class:`Disagreement` from the campaign's files; a one-line
    InputError where members.csv and members_runs.csv disagree on a test's runs."""
    campaign_dir = Path(campaign_dir)
    members = _read(campaign_dir / "members.csv", MEMBERS_COLUMNS,
                    {"test": str, "date": str, "split": str})
    runs = _read(campaign_dir / "members_runs.csv", RUNS_COLUMNS,
                 {"test": str, "run_id": str})
    runs = runs[runs["member"] >= 0]
    members["observed"] = csv_true_column(members["observed"])
    out = []
    for row in members.to_dict("records"):
        if not row["runs"] > 0:
            continue                                  # not scored: no member run
        ids = list(runs.loc[runs["test"] == row["test"], "run_id"])
        evidence = [run_evidence(campaign_dir / "runs" / i) for i in ids]
        toppled = sum(e["toppled"] for e in evidence)
        if len(ids) != row["runs"] or toppled != row["overturned"]:
            raise InputError(f"{campaign_dir}: members_runs.csv holds {len(ids)} runs of "
                             f"test {row['test']}, {toppled} overturned; members.csv says "
                             f"{row['runs']}, {row['overturned']}")
        out.append(test_disagreement(row, evidence))
    return DisagreementTable(tuple(out))


def write_disagreements(campaign_dir, title):
    """Write disagreements.csv and shake_table_disagreements.png in ``campaign_dir``
    from its files; return the :class:`DisagreementSummary`."""
    campaign_dir = Path(campaign_dir)
    table = disagreement_table(campaign_dir)
    summary = DisagreementSummary.of(table)
    table.save(campaign_dir)
    from pipeline.figures.shake_table_disagreements import plot_disagreements  # lazy: matplotlib
    rows = [(t.pga_g, t.pgv_pga_s, t.verdict.value, t.split) for t in table.tests]
    regions = [(f"{r.kind.label} {r.label}", r.wrong.count, r.wrong.of, *r.wrong.ci95)
               for r in summary.regions]
    plot_disagreements(rows, regions, campaign_dir / FIGURE, title)
    return summary


__all__ = ["FILE", "FIGURE", "write_disagreements", "disagreement_table", "run_evidence"]
