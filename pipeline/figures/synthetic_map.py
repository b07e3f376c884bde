"""Map of a synthetic source: rupture, mechanism and each site's downfall arrows."""
import math

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Circle
from obspy.imaging.beachball import beach

from pipeline.figures.style import COLUMN_COLOURS, colour, new_figure
from pipeline.files import InputError, save_figure
from pipeline.motion.synthetics import source_parameters, subevents

RUN_COLUMNS = ("site_id", "column", "toppled", "downfall_azimuth_deg", "back_azimuth_deg",
               "x_km", "y_km")


def plot_downfall_map(runs, source_name, path, arrow_km=3.0):
    """Map of one source: rupture and mechanism, each site's downfall arrows.

    Solid line: surface projection of the modelled rupture (sub-event line);
    dashed line for a dipping fault: where its plane would reach the surface.
    Arrows (length ``arrow_km`` on the map) point in the downfall azimuth,
    one colour per column type; an open circle marks a column not toppled.
    ``runs``: columns of RUN_COLUMNS (rows of other sources are ignored when a
    ``source`` column is present).
    """
    src = source_parameters(source_name)
    missing = [c for c in RUN_COLUMNS if c not in runs.columns]
    if missing:
        raise InputError(f"synthetic runs table lacks columns: {', '.join(missing)}")
    frame = runs
    if "source" in frame.columns:
        frame = frame[frame["source"] == source_name]
    subs = subevents(source_name)
    reach = max(float(np.hypot(frame["x_km"], frame["y_km"]).max()) if len(frame) else 0.0,
                float(np.hypot(subs["x_km"], subs["y_km"]).max())) + arrow_km + 4.0

    fig, ax = new_figure(figsize=(8, 8))
    for ring in sorted(set(np.round(np.hypot(frame["x_km"], frame["y_km"]), 6))):
        ax.add_patch(Circle((0, 0), ring, fill=False, color="0.85", lw=0.8))
    _draw_source(ax, src, subs, reach)
    columns = sorted(frame["column"].unique(), key=lambda c: (c not in COLUMN_COLOURS, c))
    for k, column in enumerate(columns):
        col = colour(column, k)
        group = frame[frame["column"] == column]
        fell = group["toppled"].astype(bool) & group["downfall_azimuth_deg"].notna()
        az = np.radians(group.loc[fell, "downfall_azimuth_deg"].to_numpy(float))
        ax.quiver(group.loc[fell, "x_km"], group.loc[fell, "y_km"], arrow_km * np.sin(az),
                  arrow_km * np.cos(az), color=col, angles="xy", scale_units="xy", scale=1,
                  width=0.004, zorder=4)
        offset = 0.6 * (k - (len(columns) - 1) / 2)
        ax.plot(group.loc[~fell, "x_km"] + offset, group.loc[~fell, "y_km"], "o", mfc="none",
                mec=col, ms=7, zorder=4)
    ax.plot(frame["x_km"], frame["y_km"], ".", color="0.4", ms=3, zorder=3)

    handles = [Line2D([], [], color="darkred", lw=3, label="rupture (surface projection)"),
               Line2D([], [], marker="*", color="k", ls="none", ms=12, label="epicentre")]
    if src["dip_deg"] < 90:
        handles.append(Line2D([], [], color="darkred", ls="--", label="fault plane at surface"))
    for k, column in enumerate(columns):
        col = colour(column, k)
        handles += [Line2D([], [], color=col, lw=2, label=f"{column}: downfall direction"),
                    Line2D([], [], marker="o", mfc="none", mec=col, ls="none",
                           label=f"{column}: not toppled")]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3,
              fontsize=8, frameon=False)
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_aspect("equal")
    ax.set_xlabel("East of epicentre (km)")
    ax.set_ylabel("North of epicentre (km)")
    ax.set_title(f"{source_name}: Mw {src['mw']:g} {src['mechanism']} (strike "
                 f"{src['strike_deg']:g}, dip {src['dip_deg']:g}, rake {src['rake_deg']:g}), "
                 f"depth {src['depth_km']:g} km")
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=150, bbox_inches="tight")


def _draw_source(ax, src, subs, reach):
    """The rupture's sub-event line, a dipping fault's surface trace (dashed), the
    epicentre and the mechanism's beach ball in the upper left corner (km)."""
    ax.plot(subs["x_km"], subs["y_km"], "-", color="darkred", lw=3, solid_capstyle="butt")
    ax.plot(subs["x_km"], subs["y_km"], "o", color="darkred", ms=4)
    if src["dip_deg"] < 90:
        up_dip = math.radians(src["strike_deg"] - 90.0)
        shift = src["depth_km"] / math.tan(math.radians(src["dip_deg"]))
        ax.plot(subs["x_km"] + shift * math.sin(up_dip), subs["y_km"] + shift * math.cos(up_dip),
                "--", color="darkred", lw=1.5)
    ax.plot(0, 0, "*", color="k", ms=14, zorder=5)
    ax.add_collection(beach([src["strike_deg"], src["dip_deg"], src["rake_deg"]],
                            xy=(-reach + 4.5, reach - 4.5), width=7.0, facecolor="darkred",
                            linewidth=1, zorder=6))
