"""Ensemble figures: a rose of downfall azimuths with their circular density, the back
azimuth and the nominal run marked; the distribution of impact times."""
from pathlib import Path

import numpy as np

from pipeline.figures.style import COLUMN_COLOURS, COLUMN_LABELS, new_figure
from pipeline.files import save_figure
from pipeline.stats.ensemble import circular_density

BIN_DEG = 10.0


def plot_ensemble(members, summary, out_dir):
    """``rose.png`` and ``impact_times.png`` in ``out_dir`` from a members table (rows of
    runs.csv with a ``member`` column; member -1 is the nominal run)."""
    out_dir = Path(out_dir)
    columns = summary["columns"]
    fig, axes = new_figure(1, len(columns), figsize=(6 * len(columns), 6),
                           subplot_kw={"projection": "polar"}, squeeze=False)
    grid = np.arange(0.0, 360.0, 1.0)
    for ax, col in zip(axes[0], columns):
        colour = COLUMN_COLOURS.get(col["column"], "C2")
        group = members[(members["column"] == col["column"]) & (members["member"] >= 0)]
        az = group.loc[group["toppled"].astype(bool), "downfall_azimuth_deg"].to_numpy(float)
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        edges = np.arange(0.0, 360.0 + BIN_DEG, BIN_DEG)
        counts, _ = np.histogram(az % 360.0, bins=edges)
        fraction = counts / max(len(group), 1)
        ax.bar(np.radians(edges[:-1] + BIN_DEG / 2), fraction, width=np.radians(BIN_DEG),
               color=colour, alpha=0.45, edgecolor="k", linewidth=0.3,
               label=f"members per {BIN_DEG:g}° (fraction)")
        if az.size:
            density = circular_density(az, grid) * BIN_DEG * az.size / max(len(group), 1)
            ax.plot(np.radians(np.r_[grid, grid[:1]]), np.r_[density, density[:1]], color=colour,
                    lw=2, label="circular density (von Mises kernel)")
        top = max(fraction.max(initial=0.0), 0.05) * 1.15
        if summary["back_azimuth_deg"] is not None:
            ax.plot([np.radians(summary["back_azimuth_deg"])] * 2, [0, top], "k--", lw=1.2,
                    label=f"back azimuth {summary['back_azimuth_deg']:.0f}°")
        if col["nominal_downfall_azimuth_deg"] is not None:
            ax.plot([np.radians(col["nominal_downfall_azimuth_deg"])] * 2, [0, top], color="0.3",
                    lw=2.5, label=f"nominal run {col['nominal_downfall_azimuth_deg']:.0f}°")
        ax.set_rmax(top)
        lo, hi = col["p_toppled_ci95"]
        ax.set_title(f"{COLUMN_LABELS.get(col['column'], col['column'])}\nP(toppled) = "
                     f"{col['p_toppled']:.2f} [{lo:.2f}, {hi:.2f}], n = {col['members']}",
                     fontsize=10)
        ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.15, -0.22))
    fig.suptitle(f"Ensemble downfall directions: {summary['record']} (seed {summary['seed']})")
    fig.tight_layout()
    rose = out_dir / "rose.png"
    save_figure(fig, rose, dpi=120)

    fig, ax = new_figure(figsize=(7, 4))
    for col in columns:
        group = members[(members["column"] == col["column"]) & (members["member"] >= 0)]
        times = group["impact_time_s"].dropna().to_numpy(float)
        if times.size:
            ax.hist(times, bins=20, alpha=0.5, color=COLUMN_COLOURS.get(col["column"], "C2"),
                    label=f"{COLUMN_LABELS.get(col['column'], col['column'])} ({times.size} falls)")
    ax.set_xlabel("time of the first impact (s)")
    ax.set_ylabel("members")
    ax.set_title(f"Impact times: {summary['record']}")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    times_path = out_dir / "impact_times.png"
    save_figure(fig, times_path, dpi=120)
    return [rose, times_path]
