"""Campaign figures: impact maps (paper Figs 9-10), roses, toppling against
ground-motion parameters, downfall against reference directions.

Azimuths are degrees clockwise from North in [0, 360); impact points are
East/North offsets (m) from the column's initial axis.

Input tables (see ``pipeline.campaign``): ``runs`` has one row per run and
column type, ``impacts`` one row per body that struck the pedestal.
"""
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import colormaps
from matplotlib.colors import Normalize
from matplotlib.ticker import LogLocator, MaxNLocator, NullFormatter, ScalarFormatter

from pipeline import files
from pipeline.constants import MODEL_GRAVITY
from pipeline.figures.style import COLUMN_COLOURS, COLUMN_LABELS, COLUMN_MARKERS, figure
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.stats.circular import (COLUMN_TYPES, REFERENCE_AZIMUTHS, angle_difference_deg,
                                     checked_runs, circular_summary)

REFERENCE_LABELS = {
    "back_azimuth": "back azimuth",
    "max_acc": "azimuth of largest horizontal acceleration",
    "max_vel": "azimuth of largest horizontal velocity",
    "max_disp": "azimuth of largest horizontal displacement",
}
PARAMETER_LABELS = {"hd": "h/d", "mu_s": "μs"}


def _checked_impacts(impacts, columns):
    if impacts is None:
        return pd.DataFrame(columns=columns)
    if not isinstance(impacts, pd.DataFrame):
        raise InputError(f"impacts table must be a pandas DataFrame, got {type(impacts).__name__}")
    missing = [c for c in columns if c not in impacts.columns]
    if missing and not impacts.empty:
        raise InputError(f"impacts table lacks column(s): {', '.join(missing)}")
    if impacts.empty:
        return pd.DataFrame(columns=columns)
    if not np.isfinite(impacts[["x_m", "y_m"]].to_numpy(float)).all():
        raise InputError("impacts table has non-finite impact coordinates")
    return impacts


def horizontal_displacement(motion):
    """Horizontal displacement (n, 2) m and meta of a Motion or a processed-motion path."""
    if isinstance(motion, (str, Path)):
        motion = Motion.load(motion)
    return motion.disp[:, :2], motion.meta


# ---------------------------------------------------------------- figures

def _plain_log_ticks(axis):
    """Log axis labelled with plain numbers at 1, 2, 5 x 10^k (no 2x10^0 clutter)."""
    axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(ScalarFormatter())
    axis.set_minor_formatter(NullFormatter())


def _north_arrow(ax, x=0.08, y=0.80):
    ax.annotate("N", xy=(x, y + 0.12), xytext=(x, y), xycoords="axes fraction",
                ha="center", va="top", fontsize=11, fontweight="bold",
                arrowprops=dict(arrowstyle="-|>", color="k", lw=1.5))


def _size_scale(values):
    """Map parameter values to marker areas (pt^2), 20..220."""
    values = np.asarray(values, dtype=float)
    lo, hi = np.nanmin(values), np.nanmax(values)
    span = hi - lo if hi > lo else 1.0

    def size(v):
        return 20.0 + 200.0 * (np.asarray(v, dtype=float) - lo) / span

    return size


def _legend_values(values, limit=7):
    values = np.unique(np.asarray(values, dtype=float))
    if len(values) <= limit:
        return values
    return values[np.unique(np.round(np.linspace(0, len(values) - 1, limit)).astype(int))]


def plot_impact_map(runs, impacts, motion, path, size_by="hd", title=None):
    """Bird's-eye impact map like Hinzen (2009) Figs 9/10 for one record.

    Left panel multi-drum column (impact points of every drum's centre of
    mass), right panel monolithic column; symbol size and colour by
    ``size_by`` ('hd' or 'mu_s'); dashed ray towards the epicentre (back
    azimuth); grey hodogram of the horizontal ground displacement, scaled,
    with its dx/dy axes (cm) on top/right; North arrow.  ``runs`` and
    ``impacts`` must hold one record only; ``motion`` is that record's
    processed-motion npz (path or mapping).  Writes a PNG to ``path``.
    """
    runs, impacts, record, disp, meta = _impact_map_inputs(runs, impacts, motion, size_by)

    label = PARAMETER_LABELS[size_by]
    size = _size_scale(runs[size_by])
    norm = Normalize(runs[size_by].min(), runs[size_by].max())
    cmap = colormaps["viridis"]
    reach = float(np.max(np.abs(impacts[["x_m", "y_m"]].to_numpy(float)), initial=0.0))
    limit = max(4.0, 1.1 * reach)
    peak_disp = float(np.max(np.hypot(disp[:, 0], disp[:, 1])))
    scale = 0.8 * limit / peak_disp if peak_disp > 0 else 1.0  # plot m per ground m
    baz = meta.get("back_azimuth_deg")

    fig = figure(figsize=(12.5, 8.0))
    axes = fig.subplots(1, 2)
    for ax, column in zip(axes, COLUMN_TYPES):
        col_runs = runs[runs["column"] == column]
        ax.plot(disp[:, 0] * scale, disp[:, 1] * scale, color="0.6", lw=0.8,
                label="ground displacement hodogram", zorder=1)
        if baz is not None and np.isfinite(baz):
            ray = np.array([0.0, 1.5 * limit])
            ax.plot(ray * np.sin(np.deg2rad(baz)), ray * np.cos(np.deg2rad(baz)), "k--",
                    lw=1.2, label=f"back azimuth {baz:.0f}° (to epicentre)", zorder=2)
        ax.plot(0, 0, "k+", ms=12, mew=1.5, zorder=4, label="initial column axis")
        pts = impacts[impacts["column"] == column]
        ax.scatter(pts["x_m"], pts["y_m"], s=size(pts[size_by]),
                   color=cmap(norm(pts[size_by].to_numpy(float))), edgecolors="k",
                   linewidths=0.5, alpha=0.85, zorder=3)
        for value in _legend_values(col_runs[size_by]):
            ax.scatter([], [], s=size(value), color=cmap(norm(value)), edgecolors="k",
                       linewidths=0.5, label=f"{label} = {value:g}")
        standing = col_runs[~col_runs["toppled"]][size_by]
        note = (f"not toppled: {label} = " + ", ".join(f"{v:g}" for v in sorted(set(standing)))
                if len(standing) else "all toppled")
        if pts.empty:
            note = "no impact on the pedestal\n" + note
        ax.text(0.02, 0.02, note, transform=ax.transAxes, fontsize=8, va="bottom",
                bbox=dict(fc="white", ec="0.8", alpha=0.9))
        _map_axes(ax, limit, scale)
        ax.set_title(f"{COLUMN_LABELS[column]}: centre-of-mass impact points", fontsize=10, pad=28)
        _north_arrow(ax)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3)
    fig.suptitle(title or f"Impact points for record {record}, swept {label}")
    fig.tight_layout()
    files.save_figure(fig, path, dpi=120)
    return Path(path)


def _impact_map_inputs(runs, impacts, motion, size_by):
    """The impact map's tables checked (one record, finite ``size_by``), the record's id and
    its horizontal ground displacement (m, E/N) with the motion's metadata."""
    if size_by not in PARAMETER_LABELS:
        raise InputError(f"size_by must be one of {sorted(PARAMETER_LABELS)}, got {size_by!r}")
    runs = checked_runs(runs, ["record_id", "column", "toppled", size_by])
    records = sorted(set(runs["record_id"].astype(str)))
    if len(records) != 1:
        raise InputError(f"impact map needs the runs of one record, got {len(records)}: "
                         f"{', '.join(records[:5])}")
    impacts = _checked_impacts(impacts, ["column", "x_m", "y_m", size_by])
    if not impacts.empty:
        if "record_id" in impacts.columns:
            impacts = impacts[impacts["record_id"].astype(str) == records[0]]
        if not np.isfinite(impacts[size_by].to_numpy(float)).all():
            raise InputError(f"impacts table has non-finite '{size_by}' values")
    disp, meta = horizontal_displacement(motion)
    if not np.isfinite(runs[size_by].to_numpy(float)).all():
        raise InputError(f"runs table has non-finite '{size_by}' values")
    return runs, impacts, records[0], disp, meta


def _map_axes(ax, limit, scale):
    """Square East/North axes of half-width ``limit`` (m) with the hodogram's dx/dy axes (cm;
    ``scale`` plot m per ground m) on top and right."""
    ax.set_xlim(-limit, limit)
    ax.set_ylim(-limit, limit)
    ax.set_aspect("equal")
    ax.set_xlabel("East (m)")
    ax.set_ylabel("North (m)")
    ax.grid(True, lw=0.3)
    top = ax.secondary_xaxis("top", functions=(lambda x: 100 * x / scale,
                                               lambda d: d * scale / 100))
    top.set_xlabel("hodogram dx (cm)", fontsize=8, color="0.4")
    top.tick_params(labelsize=7, colors="0.4")
    right = ax.secondary_yaxis("right", functions=(lambda y: 100 * y / scale,
                                                   lambda d: d * scale / 100))
    right.set_ylabel("hodogram dy (cm)", fontsize=8, color="0.4")
    right.tick_params(labelsize=7, colors="0.4")


def _polar_axes(fig, position):
    ax = fig.add_subplot(*position, projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    return ax


def _rose(ax, angles_deg, colour, label, bin_deg=15.0, bottom=None):
    edges = np.arange(0.0, 360.0 + bin_deg, bin_deg)
    counts, _ = np.histogram(np.mod(angles_deg, 360.0), bins=edges)
    centres = np.deg2rad(edges[:-1] + bin_deg / 2)
    ax.bar(centres, counts, width=np.deg2rad(bin_deg), bottom=bottom, color=colour,
           edgecolor="k", linewidth=0.4, alpha=0.8, label=label)
    return counts


def plot_rose(runs, path):
    """Rose diagrams (North up, clockwise): downfall azimuths of each column
    type with back-azimuth marks, and downfall minus back azimuth.  PNG."""
    runs = checked_runs(runs, ["column", "toppled", "downfall_azimuth_deg", "back_azimuth_deg"])
    toppled = runs[runs["toppled"] & np.isfinite(runs["downfall_azimuth_deg"].astype(float))]
    fig = figure(figsize=(15, 5.6))
    for k, column in enumerate(COLUMN_TYPES):
        ax = _polar_axes(fig, (1, 3, k + 1))
        sub = toppled[toppled["column"] == column]
        counts = _rose(ax, sub["downfall_azimuth_deg"].to_numpy(float), COLUMN_COLOURS[column],
                       "downfall azimuth")
        rmax = max(1, int(counts.max(initial=0)))
        bazs = np.unique(sub["back_azimuth_deg"].dropna())      # of the toppled runs only
        for j, baz in enumerate(bazs):
            ax.plot([np.deg2rad(baz)] * 2, [0, rmax], "--", color="0.35", lw=0.7,
                    label="back azimuth of a toppled run" if j == 0 else None)
        ax.set_rmax(rmax)
        ax.yaxis.set_major_locator(MaxNLocator(integer=True, nbins=4))
        stats = circular_summary(sub["downfall_azimuth_deg"])
        ax.set_title(f"{COLUMN_LABELS[column]}: downfall azimuth\n"
                     f"n = {stats['n']}, mean = {stats['mean_deg']:.0f}°, "
                     f"R = {stats['resultant_length']:.2f}", fontsize=10)
        ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.15, -0.15))
    ax = _polar_axes(fig, (1, 3, 3))
    bottom = None
    for column in COLUMN_TYPES:
        sub = toppled[toppled["column"] == column]
        diff = angle_difference_deg(sub["downfall_azimuth_deg"].to_numpy(float),
                                    sub["back_azimuth_deg"].to_numpy(float))
        counts = _rose(ax, diff[np.isfinite(diff)], COLUMN_COLOURS[column],
                       COLUMN_LABELS[column], bottom=bottom)
        bottom = counts if bottom is None else bottom + counts
    ax.set_title("downfall minus back azimuth\n(0° = falls towards the epicentre)", fontsize=10)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True, nbins=4))
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.15, -0.15))
    fig.suptitle(f"Downfall directions ({len(toppled)} toppled of {len(runs)} column runs; "
                 "counts per 15° bin)")
    fig.tight_layout()
    files.save_figure(fig, path, dpi=120)
    return Path(path)


def plot_toppling_vs_parameters(runs, path):
    """Toppled or not against PGA, PGV, PGD and PGV/PGA per column type, and a
    PGA vs PGV/PGA scatter (Purvance et al. 2008).  PNG."""
    params = [("pga_h", "PGA (m/s²)"), ("pgv_h", "PGV (m/s)"), ("pgd_h", "PGD (m)"),
              ("pgv_pga_h", "PGV/PGA (s)")]
    runs = checked_runs(runs, ["column", "toppled", *[p for p, _ in params]])
    values = runs[[p for p, _ in params]].to_numpy(float)
    if not np.isfinite(values).all() or (values <= 0).any():
        raise InputError("runs table has non-positive or non-finite ground-motion parameters")
    fig = figure(figsize=(14, 8))
    grid = fig.add_gridspec(2, 4)
    rows = {column: k for k, column in enumerate(COLUMN_TYPES)}
    for j, (param, label) in enumerate(params):
        ax = fig.add_subplot(grid[0, j])
        for column, row in rows.items():
            sub = runs[runs["column"] == column]
            for toppled, offset, face in ((True, 0.12, COLUMN_COLOURS[column]), (False, -0.12, "none")):
                pick = sub[sub["toppled"] == toppled]
                ax.scatter(pick[param], np.full(len(pick), row + offset), marker="o", s=30,
                           facecolors=face, edgecolors=COLUMN_COLOURS[column],
                           label=(f"{column}, {'toppled' if toppled else 'standing'}"
                                  if j == 0 else None))
        ax.set_xscale("log")
        _plain_log_ticks(ax.xaxis)
        ax.set_yticks(list(rows.values()), [COLUMN_LABELS[c].replace(" column", "") for c in rows])
        ax.set_ylim(-0.6, len(rows) - 0.4)
        ax.set_xlabel(label)
        ax.set_title(f"toppling vs {label.split(' ')[0]}", fontsize=10)
        ax.grid(True, axis="x", lw=0.3)
    fig.legend(loc="upper center", ncol=4, fontsize=8, bbox_to_anchor=(0.5, 0.955))
    ax = fig.add_subplot(grid[1, 1:3])
    markers = COLUMN_MARKERS
    for column in COLUMN_TYPES:
        sub = runs[runs["column"] == column]
        for toppled, face in ((True, COLUMN_COLOURS[column]), (False, "none")):
            pick = sub[sub["toppled"] == toppled]
            ax.scatter(pick["pgv_pga_h"], pick["pga_h"], marker=markers[column], s=45,
                       facecolors=face, edgecolors=COLUMN_COLOURS[column],
                       label=f"{COLUMN_LABELS[column]}, {'toppled' if toppled else 'standing'}")
    if "hd" in runs.columns and runs["hd"].nunique() == 1 and np.isfinite(runs["hd"].iloc[0]):
        hd = float(runs["hd"].iloc[0])
        ax.axhline(MODEL_GRAVITY / hd, color="k", ls=":", lw=1,
                   label=f"g·d/h = {MODEL_GRAVITY / hd:.2f} m/s² (static uplift, h/d = {hd:g})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.xaxis)
    _plain_log_ticks(ax.yaxis)
    ax.set_xlabel("PGV/PGA (s)")
    ax.set_ylabel("PGA (m/s²)")
    ax.set_title("PGA and PGV/PGA together govern overturning (Purvance et al. 2008)",
                 fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.suptitle("Toppling against ground-motion parameters (horizontal vector peaks)", y=0.995)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    files.save_figure(fig, path, dpi=120)
    return Path(path)


def _wrapped_line(ax, offset, **kwargs):
    """Draw downfall = reference + offset (mod 360) over 0..360 deg."""
    x = np.linspace(0.0, 360.0, 721)
    y = np.mod(x + offset, 360.0)
    y[np.r_[False, np.diff(y) < 0]] = np.nan  # break at the wrap
    ax.plot(x, y, **kwargs)


def plot_downfall_vs_directions(runs, path):
    """Downfall azimuth against back azimuth and against the azimuths of the
    largest horizontal acceleration, velocity and displacement: 4 scatter
    panels with 1:1, +-90 and 180 deg guide lines.  PNG."""
    runs = checked_runs(runs, ["column", "toppled", "downfall_azimuth_deg",
                                *REFERENCE_AZIMUTHS.values()])
    toppled = runs[runs["toppled"]]
    fig = figure(figsize=(11, 10))
    axes = fig.subplots(2, 2).ravel()
    markers = COLUMN_MARKERS
    for ax, (reference, ref_column) in zip(axes, REFERENCE_AZIMUTHS.items()):
        _wrapped_line(ax, 0.0, color="k", lw=1.0, label="1:1 (same direction)")
        _wrapped_line(ax, 90.0, color="0.5", ls="--", lw=0.8, label="±90°")
        _wrapped_line(ax, -90.0, color="0.5", ls="--", lw=0.8)
        _wrapped_line(ax, 180.0, color="0.5", ls=":", lw=1.0, label="180° (opposite)")
        notes = []
        for column in COLUMN_TYPES:
            sub = toppled[toppled["column"] == column]
            stats = circular_summary(angle_difference_deg(sub["downfall_azimuth_deg"].to_numpy(float),
                                                          sub[ref_column].to_numpy(float)))
            ax.scatter(sub[ref_column], sub["downfall_azimuth_deg"], marker=markers[column], s=35,
                       color=COLUMN_COLOURS[column], edgecolors="k", linewidths=0.4,
                       label=COLUMN_LABELS[column])
            notes.append(f"{column}: n = {stats['n']}, mean difference = "
                         f"{angle_difference_deg(stats['mean_deg'], 0.0):.0f}°, "
                         f"R = {stats['resultant_length']:.2f}")
        ax.set_xlim(0, 360)
        ax.set_ylim(0, 360)
        ax.set_xticks(range(0, 361, 90))
        ax.set_yticks(range(0, 361, 90))
        ax.set_aspect("equal")
        ax.set_xlabel(f"{REFERENCE_LABELS[reference]} (°)")
        ax.set_ylabel("downfall azimuth (°)")
        ax.set_title(f"downfall vs {REFERENCE_LABELS[reference]}", fontsize=10)
        ax.grid(True, lw=0.3)
        ax.text(0.02, 0.98, "\n".join(notes), transform=ax.transAxes, fontsize=7, va="top",
                bbox=dict(fc="white", ec="0.8", alpha=0.9))
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8)
    fig.suptitle(f"Downfall directions of {len(toppled)} toppled column runs "
                 "against ground-motion directions")
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    files.save_figure(fig, path, dpi=120)
    return Path(path)
