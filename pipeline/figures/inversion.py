"""Figures of the source inversion: the posterior map of the epicentre with its credible
contours, the sites and the observed falls; the marginals of back azimuth, distance and
mechanism; the demo's interval widths against the number of fallen columns."""
import math

import numpy as np
from matplotlib.lines import Line2D

from pipeline import paper
from pipeline.figures.style import colour, new_figure
from pipeline.files import save_figure

LEVEL_STYLES = {0.68: "-", 0.95: "--"}


def _grid_image(post):
    """The epicentre marginal on a full square grid (NaN outside the lattice)."""
    step = post.step_km
    ie = np.round(post.east_km / step - 0.5).astype(int)
    jn = np.round(post.north_km / step - 0.5).astype(int)
    e0, n0 = ie.min(), jn.min()
    image = np.full((jn.max() - n0 + 1, ie.max() - e0 + 1), np.nan)
    image[jn - n0, ie - e0] = post.epicentre / step ** 2
    east_edges = (np.arange(ie.min(), ie.max() + 2)) * step
    north_edges = (np.arange(jn.min(), jn.max() + 2)) * step
    return east_edges, north_edges, image


def plot_posterior_map(post, observations, path, truth_km=None, title=None, arrow_km=None):
    """Map of the epicentre's posterior density (per km^2), its 68 % and 95 % HPD contours,
    the sites (triangles), the observed falls (arrows from each site, one colour per column
    type; open circles: standing columns), the MAP epicentre (star) and, for synthetic
    tests, the true epicentre (cross)."""
    east_edges, north_edges, image = _grid_image(post)
    fig, ax = new_figure(figsize=(8, 7.5))
    mesh = ax.pcolormesh(east_edges, north_edges, np.ma.masked_invalid(image), cmap="viridis",
                         shading="flat")
    fig.colorbar(mesh, ax=ax, shrink=0.8, label="posterior density of the epicentre (1/km²)")
    centres_e = 0.5 * (east_edges[:-1] + east_edges[1:])
    centres_n = 0.5 * (north_edges[:-1] + north_edges[1:])
    filled = np.nan_to_num(image) * post.step_km ** 2
    handles = []
    for level, style in LEVEL_STYLES.items():
        _, threshold = post.epicentre_region(level)
        if filled.max() > threshold:
            ax.contour(centres_e, centres_n, filled, levels=[threshold], colors="w",
                       linestyles=style, linewidths=1.5)
        handles.append(Line2D([], [], color="0.3", ls=style,
                              label=f"{int(level * 100)} % credible region"))
    span = max(east_edges[-1] - east_edges[0], north_edges[-1] - north_edges[0])
    arrow_km = arrow_km or 0.06 * span
    types = sorted({c.column for s in observations.sites for c in s.columns})
    _draw_sites(ax, observations, arrow_km, types)
    for k, column in enumerate(types):
        handles.append(Line2D([], [], color=colour(column, k), lw=2,
                              label=f"{column}: observed downfall (circle: standing)"))
    best = post.summary()["map_epicentre_km"]
    ax.plot(*best, "*", color="orange", mec="k", ms=16, zorder=7)
    handles.append(Line2D([], [], marker="*", color="orange", mec="k", ls="none", ms=12,
                          label="most probable epicentre"))
    if truth_km is not None:
        ax.plot(*truth_km, "X", color="red", mec="w", ms=12, zorder=7)
        handles.append(Line2D([], [], marker="X", color="red", ls="none", ms=10,
                              label="true epicentre"))
    handles.append(Line2D([], [], marker="^", color="w", mec="k", ls="none", ms=9,
                          label="site"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
              fontsize=8, frameon=False)
    _set_view(ax, post, observations, truth_km, arrow_km, east_edges, north_edges)
    ax.set_aspect("equal")
    ax.set_xlabel(f"East of site {observations.sites[0].name} (km)")
    ax.set_ylabel(f"North of site {observations.sites[0].name} (km)")
    ax.set_title(_map_title(post, title))
    save_figure(fig, path, dpi=130, bbox_inches="tight")
    return path


def _draw_sites(ax, observations, arrow_km, types):
    """The sites (triangles, named when few), their standing columns (open circles) and
    their observed falls (arrows ``arrow_km`` long, one colour per column type)."""
    for site in observations.sites:
        ax.plot(site.east_km, site.north_km, "^", color="w", mec="k", ms=10, zorder=5)
        if len(observations.sites) <= 8:
            ax.annotate(site.name, (site.east_km, site.north_km), xytext=(6, 6),
                        textcoords="offset points", color="w", fontsize=9, zorder=6)
        standing = [c for c in site.columns if not c.fallen]
        for k, c in enumerate(standing[:12]):
            angle = math.radians(k * 360.0 / max(len(standing), 1))
            ax.plot(site.east_km + 0.25 * arrow_km * math.sin(angle),
                    site.north_km + 0.25 * arrow_km * math.cos(angle), "o", mfc="none",
                    mec=colour(c.column, types.index(c.column)), ms=6, zorder=6)
        for c in site.columns:
            if c.fallen:
                a = math.radians(c.downfall_azimuth_deg)
                ax.annotate("", xy=(site.east_km + arrow_km * math.sin(a),
                                    site.north_km + arrow_km * math.cos(a)),
                            xytext=(site.east_km, site.north_km), zorder=6,
                            arrowprops={"arrowstyle": "-|>", "lw": 1.6,
                                        "color": colour(c.column, types.index(c.column))})


def _set_view(ax, post, observations, truth_km, arrow_km, east_edges, north_edges):
    """The view: the sites and the 99 % region, with a margin, inside the lattice."""
    region, _ = post.epicentre_region(0.99)
    xs = np.r_[[s.east_km for s in observations.sites], post.east_km[region]]
    ys = np.r_[[s.north_km for s in observations.sites], post.north_km[region]]
    if truth_km is not None:
        xs, ys = np.r_[xs, truth_km[0]], np.r_[ys, truth_km[1]]
    pad = max(0.15 * max(np.ptp(xs), np.ptp(ys)), 3.0 * post.step_km) + arrow_km
    step = post.step_km                 # the lattice's bounds, or a true epicentre beyond
    ax.set_xlim(max(xs.min() - pad, min(east_edges[0], xs.min() - step)),
                min(xs.max() + pad, max(east_edges[-1], xs.max() + step)))
    ax.set_ylim(max(ys.min() - pad, min(north_edges[0], ys.min() - step)),
                min(ys.max() + pad, max(north_edges[-1], ys.max() + step)))


def _map_title(post, title):
    """The title, with where the candidates end when they end short of the sites' reach."""
    reach = post.reach_summary()
    if reach["reach_km"] is not None:      # the coloured cells are the candidates
        title = (title or "Posterior of the epicentre") + (
            f"\ncandidates end {reach['reach_km']:g} km from the sites ({reach['reach_limit']});"
            f"\n{reach['reach_edge_fraction']:.0%} of the posterior in their outermost cells"
            + (": the source may lie farther" if reach["reach_warning"] else ""))
    return title or "Posterior of the epicentre"


def plot_marginals(post, path, truth=None):
    """Back azimuth from the first site (polar, with the 68/95 % arcs), distance and
    mechanism marginals.  ``truth``: optional dict back_azimuth_deg, distance_km,
    mechanism."""
    summary = post.summary()
    fig, (first, ax1, ax2) = new_figure(1, 3, figsize=(13, 4.2))
    first.remove()
    ax0 = fig.add_subplot(1, 3, 1, projection="polar")
    centres, mass = post.back_azimuth_marginal()
    ax0.set_theta_zero_location("N")
    ax0.set_theta_direction(-1)
    width = math.radians(centres[1] - centres[0])
    ax0.bar(np.radians(centres), mass, width=width, color="tab:purple", alpha=0.7)
    top = mass.max() * 1.15
    for level, style, radius in ((95, "--", 1.08), (68, "-", 1.02)):
        lo, hi = summary[f"back_azimuth_ci{level}_deg"]
        span = (hi - lo) % 360.0 or (360.0 if [lo, hi] == [0.0, 360.0] else 0.0)
        theta = np.radians(lo + np.linspace(0, span, 100))
        ax0.plot(theta, np.full(theta.shape, top * radius / 1.15), ls=style, color="k",
                 label=f"{level} % arc [{lo:.0f}, {hi:.0f}]")
    if truth and truth.get("back_azimuth_deg") is not None:
        ax0.plot([math.radians(truth["back_azimuth_deg"])] * 2, [0, top], color="red", lw=2,
                 label=f"true {truth['back_azimuth_deg']:.0f}°")
    ax0.set_rmax(top * 1.1)
    ax0.set_yticklabels([])
    ax0.set_title("back azimuth from the first site", fontsize=10)
    ax0.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.2, -0.25))

    d, pd_ = post.distance_marginal()
    ax1.bar(d, pd_, width=d[1] - d[0] if len(d) > 1 else 1.0, color="tab:green", alpha=0.7)
    lo, hi = summary["distance_ci95_km"]
    ax1.axvspan(lo, d[-1] if hi is None else hi, color="0.85", zorder=0,
                label=f"95 %: {lo:.1f} km to " + ("unbounded (beyond the reach)" if hi is None
                                                  else f"{hi:.1f} km"))
    if truth and truth.get("distance_km") is not None:
        ax1.axvline(truth["distance_km"], color="red", lw=2, label="true")
    ax1.set_xlabel("epicentral distance from the first site (km)")
    ax1.set_ylabel("probability per bin")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)

    names = list(summary["mechanism_posterior"])
    values = [summary["mechanism_posterior"][n] for n in names]
    bars = ax2.bar(names, values, color=["tab:red" if truth and truth.get("mechanism") == n
                                         else "tab:gray" for n in names])
    for bar, v in zip(bars, values):
        ax2.annotate(f"{v:.2f}", (bar.get_x() + bar.get_width() / 2, v), ha="center",
                     va="bottom", fontsize=9)
    ax2.set_ylim(0, 1.1)
    ax2.set_ylabel("posterior probability")
    ax2.set_title("mechanism" + (" (red: true)" if truth and truth.get("mechanism") else ""),
                  fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path


def plot_interval_widths(table, path):
    """Median 95 % back-azimuth arc width (and its quartiles) against fallen columns per
    site, one line per (mechanism, number of sites), one panel per likelihood; ``table``:
    rows of the demo's narrowing table (likelihood, mechanism, sites, fallen_per_site,
    width_median_deg, width_q25_deg, width_q75_deg, coverage_back_azimuth_95)."""
    kinds = list(dict.fromkeys(table["likelihood"]))
    fig, axes = new_figure(1, len(kinds), figsize=(6.5 * len(kinds), 4.8), squeeze=False)
    ticks = sorted(table["fallen_per_site"].unique())
    for ax, kind in zip(axes[0], kinds):
        part = table[table["likelihood"] == kind]
        for k, ((mech, sites), group) in enumerate(part.groupby(["mechanism", "sites"])):
            group = group.sort_values("fallen_per_site")
            ax.errorbar(group["fallen_per_site"], group["width_median_deg"],
                        yerr=[group["width_median_deg"] - group["width_q25_deg"],
                              group["width_q75_deg"] - group["width_median_deg"]],
                        marker="os"[sites > 1], color=f"C{k}", capsize=3,
                        ls="-" if sites > 1 else "--", label=f"{mech}, {sites} site(s)")
            for x, y, c in zip(group["fallen_per_site"], group["width_median_deg"],
                               group["coverage_back_azimuth_95"]):
                ax.annotate(f"{100 * c:.0f}%", (x, y), xytext=(4, 4), fontsize=7,
                            textcoords="offset points", color=f"C{k}")
        bound = paper.BACK_AZIMUTH_BOUND_DEG
        ax.axhline(2 * bound, color="k", lw=1, ls=":", label=f"±{bound:g}°")
        ax.set_xscale("log")
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{v:g}" for v in ticks])
        ax.set_ylim(0, 370)
        ax.set_xlabel("fallen columns per site")
        ax.set_ylabel("95 % back-azimuth arc (deg)")
        ax.set_title(f"{kind} likelihood (labels: truth inside the arc)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("How the back azimuth narrows with the evidence (synthetic truth tests)")
    fig.tight_layout()
    save_figure(fig, path, dpi=120, bbox_inches="tight")
    return path


def plot_member_study(summary, path, bound_deg):
    """The member study: per likelihood (rows) the median 95 % back-azimuth arc and its
    coverage (with Wilson intervals) against the likelihood members per node, the arc
    width ``bound_deg`` (deg) that counts as bounded marked; colour: fallen columns per
    site, line style: sites."""
    panels = [("width_median_deg", None, "median width of the 95 % back-azimuth arc (deg)",
               "arc width", (0, 365), bound_deg, f"+-{bound_deg / 2:g} deg"),
              ("coverage_back_azimuth_95", "coverage_ci95",
               "coverage of the 95 % arc (Wilson 95 %)", "coverage", (0, 1.02), 0.95, "95 %")]
    _plot_study_panels(summary, path, panels, "How many fallen columns bound the back "
                       "azimuth? (truth tests, observed columns from members no likelihood "
                       "uses)")
    return path


def plot_member_study_source(summary, path):
    """The member study for the epicentre, the distance and the magnitude: per likelihood
    (rows) the median 95 % credible area of the epicentre, and the coverage of the
    epicentre's 95 % region, of the distance's 95 % interval and of the 95 % set of
    magnitudes (Wilson intervals), against the likelihood members per node."""
    panels = [("credible_area_95_km2_median", None, "median 95 % credible area (km^2)",
               "epicentre: area", None, None, None),
              ("coverage_epicentre_95", "coverage_epicentre_ci95",
               "coverage of the 95 % region (Wilson 95 %)", "epicentre: coverage", (0, 1.02),
               0.95, "95 %"),
              ("coverage_distance_95", "coverage_distance_ci95",
               "coverage of the 95 % interval (Wilson 95 %)", "distance: coverage",
               (0, 1.02), 0.95, "95 %"),
              ("coverage_mw_95", "coverage_mw_ci95", "true Mw in the 95 % set (Wilson 95 %)",
               "magnitude: coverage", (0, 1.02), 0.95, "95 %")]
    panels = [panel for panel in panels if panel[0] in summary.columns]
    _plot_study_panels(summary, path, panels, "What the columns tell of the epicentre, the "
                       "distance and the magnitude (the same truth tests)")
    return path


def _plot_study_panels(summary, path, panels, title):
    """One row per likelihood, one panel per (column, interval column, y label, title,
    y limits, reference line, its label) of ``summary`` against the likelihood members."""
    kinds = sorted(summary["likelihood"].unique())
    fig, axes = new_figure(len(kinds), len(panels), figsize=(6 * len(panels), 4.2 * len(kinds)),
                           squeeze=False)
    fallen = sorted(summary["fallen_per_site"].unique())
    styles = {1: "-", 3: "--"}
    for row, kind in zip(axes, kinds):
        g = summary[summary["likelihood"] == kind]
        sizes = sorted(g["likelihood_members"].unique())
        for ax, (column, interval, ylabel, name, ylim, line, line_label) in zip(row, panels):
            for (sites, k), h in g.groupby(["sites", "fallen_per_site"]):
                h = h.sort_values("likelihood_members")
                style = dict(color=f"C{fallen.index(k)}", ls=styles.get(sites, ":"),
                             marker="o", ms=4, label=f"{sites} site(s) x {k} fallen")
                ax.plot(h["likelihood_members"], h[column], **style)
                if interval is not None:
                    ax.fill_between(h["likelihood_members"], [c[0] for c in h[interval]],
                                    [c[1] for c in h[interval]], color=style["color"],
                                    alpha=0.08)
            if line is not None:
                ax.axhline(line, color="k", lw=1, ls=":", label=line_label)
            ax.set_xscale("log", base=2)
            ax.set_xticks(sizes, [str(v) for v in sizes])
            ax.set_xlabel("likelihood members per node")
            ax.set_ylabel(ylabel)
            if ylim is None:
                ax.set_yscale("log")
            else:
                ax.set_ylim(*ylim)
            ax.set_title(f"{kind} likelihood: {name}", fontsize=10)
            ax.grid(alpha=0.3)
        row[-1].legend(fontsize=7, ncol=2, loc="lower left")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
