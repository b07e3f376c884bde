"""Campaign tables from the run summaries: runs.csv (one row per run and column) and
impacts.csv (one row per struck body), and the same tables as Parquet (runs.parquet,
impacts.parquet: typed columns, compressed, fast to read for large campaigns)."""
import math
import os
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet  # noqa: F401  (pandas' to_parquet engine, loaded before any run)

from pipeline.files import atomic_path, write_csv
from pipeline.campaign.run_dirs import finished_runs
from pipeline.motion import Motion
from pipeline.motion.measures import record_parameters
from pipeline.stats.colonnade import ALL_RECORDS, ColonnadeStatistics
from pipeline.stats.colonnade_falls import fall_directions

SYNTHETIC_SITE_KEYS = ("source", "station", "x_km", "y_km", "ring_km")  # from synthetic meta
IMPACT_COLUMNS = ["run_id", "column", "body_index", "impact_time_s", "x_m", "y_m", "hd",
                  "mu_s", "record_id"]


def collect(specs, campaign, campaign_dir):
    """runs and impacts tables (DataFrames) from the summaries of finished runs
    (written by the campaign with :func:`write_tables`)."""
    return _tables(specs, campaign, campaign_dir)


def write_tables(campaign_dir, runs, impacts):
    """runs.csv, impacts.csv and their Parquet twins in ``campaign_dir``."""
    campaign_dir = Path(campaign_dir)
    for name, frame in (("runs", runs), ("impacts", impacts)):
        write_csv(campaign_dir / f"{name}.csv", frame)
        write_parquet(campaign_dir / f"{name}.parquet", frame)


def write_parquet(path, frame):
    """Write a DataFrame atomically as Parquet (pyarrow, no index).  Object columns
    mixing types (a text value in one run, a number in another) are written as text."""
    frame = frame.copy()
    for column in frame.columns[frame.dtypes.eq(object)]:
        try:
            pa.array(frame[column], from_pandas=True)
        except (pa.ArrowInvalid, pa.ArrowTypeError):
            frame[column] = [None if _missing(v) else str(v) for v in frame[column]]
    with atomic_path(path) as tmp:
        frame.to_parquet(tmp, index=False, engine="pyarrow")


COLONNADE_COLUMNS = ("run_id", "record_id", "colonnade", "columns", "columns_fallen", "beams",
                     "beams_fallen", "fall_azimuth_mean_deg", "fall_azimuth_spread_deg",
                     "parallel", "fall_order", "in_sequence")


def colonnade_table(specs, campaign_dir):
    """One row per finished run of a colonnade: what its ``summary.json`` says of the
    colonnade as a whole (:class:`~pipeline.outcome.colonnade.ColonnadeOutcome`: columns
    and beams fallen, the fallen columns' azimuth mean and spread, parallel, the fall
    order as names joined by spaces, in sequence); empty without colonnades."""
    rows = []
    for spec, summary in finished_runs(campaign_dir, specs):
        whole = summary.colonnade
        if whole is None:
            continue
        rows.append({"run_id": spec.run_id, "record_id": spec.record_id,
                     "colonnade": whole.name, "columns": whole.columns,
                     "columns_fallen": whole.columns_fallen, "beams": whole.beams,
                     "beams_fallen": whole.beams_fallen,
                     "fall_azimuth_mean_deg": _nan(whole.fall_azimuth_mean_deg),
                     "fall_azimuth_spread_deg": _nan(whole.fall_azimuth_spread_deg),
                     "parallel": whole.parallel, "fall_order": " ".join(whole.fall_order),
                     "in_sequence": whole.in_sequence})
    return pd.DataFrame(rows, columns=COLONNADE_COLUMNS)


def write_colonnade_files(campaign_dir, table, figures=True, by="record_id",
                          pooled=ALL_RECORDS, runs=None, description=None):
    """colonnades.csv (``table``: :func:`colonnade_table`'s rows, an ensemble's with its
    members), colonnade_statistics.json beside it
    (:class:`~pipeline.stats.colonnade.ColonnadeStatistics` grouped ``by`` a column,
    ``pooled`` over the groups) and, with ``figures``, colonnade_statistics.png and, given
    ``runs`` (runs.csv's rows) and the colonnade's ``description`` (dict),
    colonnade_falls.png; nothing without colonnade runs.  Returns the figures."""
    if table.empty:
        return []
    statistics = ColonnadeStatistics.of(table, by, pooled)   # checked before any file
    write_csv(Path(campaign_dir) / "colonnades.csv", table)
    statistics.save(Path(campaign_dir))
    if not figures:
        return []
    from pipeline.figures.colonnade import plot_colonnade_statistics  # lazy: matplotlib, not imported by a run or after Ctrl-C
    written = [plot_colonnade_statistics(statistics,
                                         Path(campaign_dir) / "colonnade_statistics.png")]
    if runs is not None and description is not None and not runs.empty:
        written.append(plot_falls(campaign_dir, table, runs, description, by))
    return written


def row_azimuth_deg(description):
    """The azimuth (deg clockwise from North, in [0, 180)) of a colonnade description's
    row: its stylobate's axis from start to end."""
    (x0, y0), (x1, y1) = description["stylobate"]["start"], description["stylobate"]["end"]
    return math.degrees(math.atan2(x1 - x0, y1 - y0)) % 180.0


def plot_falls(campaign_dir, table, runs, description, by="record_id"):
    """colonnade_falls.png: the fall azimuths of the colonnade's columns in ``runs``
    grouped as ``table`` (colonnades.csv's rows) groups them ``by``, the row's axis drawn,
    and each group's shaking azimuth where ``table`` has ``azimuth_deg``."""
    from pipeline.figures.colonnade_falls import plot_fall_directions  # lazy: matplotlib
    groups = dict(zip(table["run_id"], table[by].astype(str)))
    members = table[["run_id", "member"]] if "member" in table else None
    if members is not None and "member" not in runs:
        runs = runs.merge(members, on="run_id")
    falls = fall_directions(runs, groups, [c["name"] for c in description["columns"]])
    shaking = None
    if "azimuth_deg" in table:
        shaking = dict(zip(table[by].astype(str), table["azimuth_deg"].astype(float)))
    return plot_fall_directions(falls, row_azimuth_deg(description),
                                Path(campaign_dir) / "colonnade_falls.png", shaking,
                                f"{description['name']}: where the columns fell "
                                "(arrow: circular mean, its length R)")


def _missing(value):
    return value is None or (isinstance(value, float) and math.isnan(value))


def _tables(specs, campaign, campaign_dir):
    runs_dir = Path(campaign_dir) / "runs"
    record_params = {}
    run_rows, impact_rows = [], []
    for spec, summary in finished_runs(campaign_dir, specs):
        if spec.motion_file not in record_params:
            motion = Motion.load(spec.motion_file)
            site = {k: motion.meta[k] for k in SYNTHETIC_SITE_KEYS if k in motion.meta}
            if "station" in site:
                site["site_id"] = site.pop("station")
            record_params[spec.motion_file] = {**record_parameters(motion), **site}
        rp = record_params[spec.motion_file]
        sizes, contact = spec.params.column.sizes(), spec.params.contact
        base = {"campaign": campaign, "run_id": spec.run_id, "record_id": spec.record_id,
                "hd": sizes["hd"], "height_m": sizes["height"], "n_drums": sizes["n_drums"],
                "mu_s": contact.mu_s, "mu_k": contact.mu_k, "kn": contact.kn,
                "damping": contact.damping}
        for col in summary.columns:
            point = col.impact_point_m or [math.nan, math.nan]
            run_rows.append({
                **base, "column": col.column, "toppled": col.toppled,
                "downfall_azimuth_deg": _nan(col.downfall_azimuth_deg),
                "impact_time_s": _nan(col.impact_time_s), "impact_x_m": point[0],
                "impact_y_m": point[1], "max_tilt_deg": col.max_tilt_deg,
                "base_slip_m": col.base_slip_m, **damage_columns(col.damage),
                "simulated": summary.simulated,
                "simulated_from_s": _nan((summary.simulated_window_s or [None])[0]),
                "simulated_s": summary.simulated_s,
                "start_in_file_s": summary.start_in_file_s,
                **{k: v if isinstance(v, str) else _nan(v) for k, v in rp.items()},
                "back_azimuth_deg": _nan(summary.back_azimuth_deg),
                "motion_file": spec.motion_file,
                "run_dir": os.path.relpath(runs_dir / spec.run_id, campaign_dir)})
            for body in col.bodies:
                if body["struck"]:
                    impact_rows.append({
                        "run_id": spec.run_id, "column": col.column,
                        "body_index": body["index"], "impact_time_s": body["impact_time_s"],
                        "x_m": body["impact_point_m"][0], "y_m": body["impact_point_m"][1],
                        "hd": sizes["hd"], "mu_s": contact.mu_s,
                        "record_id": spec.record_id})
    return pd.DataFrame(run_rows), pd.DataFrame(impact_rows, columns=IMPACT_COLUMNS)


def _nan(value):
    return math.nan if value is None else value


DAMAGE_COLUMNS = ("peak_capital_displacement_m", "capital_displacement_ratio",
                  "max_residual_slide_m", "max_residual_twist_deg", "rotation_ratio")


def damage_columns(damage):
    """A run row's damage measures and state (:mod:`pipeline.outcome.damage`; NaN and
    an empty state for a summary written before them)."""
    if damage is None:
        return {**dict.fromkeys(DAMAGE_COLUMNS, math.nan), "damage_state": ""}
    return {**{k: _nan(getattr(damage, k)) for k in DAMAGE_COLUMNS},
            "damage_state": damage.damage_state.label}
