"""Where a colonnade's columns fell (``colonnade_falls.png``): one rose per group of runs
(a record, or a direction of shaking), North up and azimuths clockwise, the fallen
columns per 10 deg, the row's axis drawn through the centre, the shaking direction where
the runs have one, and the circular mean (its length the mean resultant length)."""
from pathlib import Path

import numpy as np
from matplotlib.ticker import MaxNLocator

from pipeline.figures.style import new_figure
from pipeline.files import save_figure

BIN_DEG = 10.0
MAX_PANELS = 8          # more roses side by side would not be read


def panel_title(falls):
    """What a panel states of a :class:`~pipeline.stats.colonnade_falls.FallDirections`:
    the columns fallen of those shaken, their circular mean and spread (deg)."""
    head = f"{falls.group}: {falls.fallen} of {falls.shaken} columns fell ({falls.runs} run{'' if falls.runs == 1 else 's'})"
    if falls.mean_deg is None:
        return head + ("\nno mean direction" if falls.fallen else "")
    return head + f"\nmean {falls.mean_deg:.0f}°, spread {falls.spread_deg:.0f}°"


def _axis_line(ax, azimuth_deg, top, **style):
    """A line through the centre along ``azimuth_deg`` (deg) and its opposite."""
    theta = np.radians([azimuth_deg, azimuth_deg + 180.0])
    ax.plot([theta[0], 0.0, theta[1]], [top, 0.0, top], **style)


def plot_fall_directions(groups, row_azimuth_deg, path, shaking_deg=None, title=""):
    """Draw the roses of ``groups`` (FallDirections, the first :data:`MAX_PANELS`) to
    ``path``; ``row_azimuth_deg`` the row's axis (deg clockwise from North),
    ``shaking_deg`` {group: azimuth (deg)} of the shaking where the runs have one."""
    groups, heading = list(groups)[:MAX_PANELS], title
    fig, axes = new_figure(1, max(len(groups), 1), figsize=(4.2 * max(len(groups), 1), 4.9),
                           subplot_kw={"projection": "polar"}, squeeze=False)
    edges = np.arange(0.0, 360.0 + BIN_DEG, BIN_DEG)
    top = max([1] + [int(np.histogram(g.azimuths_deg, bins=edges)[0].max(initial=0))
                     for g in groups]) * 1.15
    for ax, falls in zip(axes[0], groups):
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        counts, _ = np.histogram(falls.azimuths_deg, bins=edges)
        ax.bar(np.radians(edges[:-1] + BIN_DEG / 2), counts, width=np.radians(BIN_DEG),
               color="C0", alpha=0.6, edgecolor="k", linewidth=0.3,
               label=f"columns fallen per {BIN_DEG:g}°")
        _axis_line(ax, row_azimuth_deg, top, color="0.35", lw=2.5, alpha=0.6,
                   label=f"the row's axis ({row_azimuth_deg % 180:.0f}°)")
        title = panel_title(falls)
        if shaking_deg is not None and falls.group in shaking_deg:
            _axis_line(ax, shaking_deg[falls.group], top, color="C3", lw=1.2, ls="--",
                       label="the shaking's direction")
            title += f"; shaking {shaking_deg[falls.group]:.0f}°"
        if falls.mean_deg is not None:
            ax.annotate("", xy=(np.radians(falls.mean_deg), falls.resultant_length * top),
                        xytext=(0.0, 0.0),
                        arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.5})
        ax.set_rmax(top)
        ax.yaxis.set_major_locator(MaxNLocator(integer=True, nbins=4))
        ax.set_title(title, fontsize=9)
    if groups:
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    else:
        axes[0][0].set_title("no colonnade runs")
    fig.suptitle(heading or "Where the columns fell (arrow: circular mean, its length R)",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    save_figure(fig, Path(path), dpi=120)
    return Path(path)
