"""Fragility figures: lognormal curves with binned observations (Wilson intervals) per
intensity measure, the 3D columns against the 2D rigid block per record and level,
and the logistic (PGA, PGV/PGA) surface."""
import textwrap
from pathlib import Path

import numpy as np
from scipy import stats

from pipeline.figures.style import COLUMN_COLOURS, COLUMN_LABELS, COLUMN_MARKERS, figure
from pipeline.files import save_figure
from pipeline.hazard.pulse_cells import CONTOUR_LEVELS, lay_cells
from pipeline.stats.ensemble import wilson_interval
from pipeline.stats.fragility import logistic_probability
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

BLOCK_STYLE = {"block2d": {"color": "0.35", "ls": "--", "marker": "D",
                           "label": "2D block, strongest azimuth"},
               "block2d_worst": {"color": "k", "ls": ":", "marker": "v",
                                 "label": "2D block, worst azimuth"}}
IMS = (("PGA", "pga_m_s2", "PGA (m/s$^2$)"), ("PGV", "pgv_m_s", "PGV (m/s)"),
       ("PGV/PGA", "pgv_pga_s", "PGV/PGA (s)"))


def _style(name):
    if name in BLOCK_STYLE:
        return BLOCK_STYLE[name]
    return {"color": COLUMN_COLOURS.get(name, "C2"), "ls": "-",
            "marker": COLUMN_MARKERS.get(name, "o"), "label": f"3D {COLUMN_LABELS.get(name, name)}"}


def _plain_log_ticks(axis):
    """Decimal labels on a log axis (0.5, 1, 2, 5 ...), no crowded minor labels."""
    axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def plot_fragility(table, summary, out_dir):
    """``fragility_curves.png``, ``fragility_2d_vs_3d.png``, ``fragility_surface.png`` of
    a column campaign's runs ``table`` and its
    :class:`~pipeline.hazard.fragility.file.FragilityFile` ``summary``."""
    out_dir = Path(out_dir)
    return [plot_curves(table, summary, out_dir / "fragility_curves.png"),
            plot_levels(table, out_dir / "fragility_2d_vs_3d.png"),
            plot_surface(table, summary, out_dir / "fragility_surface.png")]


def plot_curves(table, summary, path):
    """One row per IM, one panel per 3D column: its observations and lognormal fit beside
    those of the 2D block."""
    columns3d = [c for c, e in summary.columns.items() if e.model == "3D"]
    blocks = [c for c, e in summary.columns.items() if e.model == "2D"]
    ncol = max(len(columns3d), 1)
    fig = figure(figsize=(5.5 * ncol, 3.6 * len(IMS)))
    axes = fig.subplots(len(IMS), ncol, squeeze=False)
    for r, (im, key, label) in enumerate(IMS):
        values = table[key].astype(float)
        values = values[np.isfinite(values) & (values > 0)]
        if values.empty:
            continue
        lo, hi = values.min(), values.max()
        grid = np.geomspace(lo / 1.5, hi * 1.5, 200)
        for c, column in enumerate(columns3d or [None]):
            ax = axes[r, c]
            for k, name in enumerate(([column] if column else []) + blocks):
                entry = summary.columns[name].fits[im]
                st = _style(name)
                bins = entry.bins
                if bins:
                    x = np.array([b["im"] for b in bins]) * (1.0 + 0.025 * (k - 1))
                    y = np.array([b["fraction"] for b in bins])
                    err = np.array([[b["fraction"] - b["ci95"][0], b["ci95"][1] - b["fraction"]]
                                    for b in bins]).T
                    ax.errorbar(x, y, yerr=err, fmt=st["marker"], color=st["color"], ms=5,
                                capsize=2, lw=0.8, alpha=0.85)
                if entry.median is not None:
                    curve = stats.norm.cdf(np.log(grid / entry.median) / entry.beta)
                    ax.plot(grid, curve, color=st["color"], ls=st["ls"], lw=1.8,
                            label=f"{st['label']}: median {entry.median:.3g}, "
                                  f"β {entry.beta:.2f}")
                else:
                    ax.plot([], [], color=st["color"], ls=st["ls"], marker=st["marker"],
                            label=f"{st['label']}: not fitted")
            ax.set_xscale("log")
            ax.set_xlim(grid[0], grid[-1])
            _plain_log_ticks(ax.xaxis)
            ax.set_ylim(-0.05, 1.05)
            ax.set_xlabel(label)
            ax.set_ylabel("P(toppled)")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7, loc="upper left")
            if r == 0 and column:
                ax.set_title(f"{COLUMN_LABELS.get(column, column)} vs the 2D block")
    fig.suptitle(f"Fragility (incremental dynamic analysis): {', '.join(summary.records)}\n"
                 f"{summary.members} members per level; bars: Wilson 95 %", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path


def plot_levels(table, path):
    """Fraction toppled per PGA level, one panel per record and one for all records; the 3D
    columns (with Wilson bands) against the 2D block."""
    records = list(dict.fromkeys(table["record_id"]))
    panels = records + (["all records"] if len(records) > 1 else [])
    fig = figure(figsize=(5 * len(panels), 4))
    axes = fig.subplots(1, len(panels), squeeze=False)
    for ax, record in zip(axes[0], panels):
        sub = table if record == "all records" else table[table["record_id"] == record]
        for name in list(dict.fromkeys(sub["column"])):
            st = _style(name)
            g = sub[sub["column"] == name].groupby("level_m_s2")["toppled"]
            k, n = g.sum().astype(int), g.count()
            ax.plot(k.index, k / n, color=st["color"], ls=st["ls"], marker=st["marker"],
                    label=st["label"])
            if name not in BLOCK_STYLE:
                ci = np.array([wilson_interval(a, b) for a, b in zip(k, n)])
                ax.fill_between(k.index, ci[:, 0], ci[:, 1], color=st["color"], alpha=0.15)
        ax.set_xscale("log")
        _plain_log_ticks(ax.xaxis)
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel("PGA of the scaled record (m/s$^2$)")
        ax.set_ylabel("fraction toppled")
        ax.set_title(record)
        ax.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    fig.suptitle("3D columns vs the 2D rigid block of the same size and slenderness",
                 fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path


def plot_surface(table, summary, path):
    """Runs in the (PGA, PGV/PGA) plane (filled: toppled) with the contours of each
    model's logistic surface at the P of :data:`~pipeline.hazard.pulse_cells.CONTOUR_LEVELS`."""
    names = list(summary.columns)
    fig = figure(figsize=(4.5 * len(names), 4))
    axes = fig.subplots(1, len(names), squeeze=False)
    pga = table["pga_m_s2"].astype(float)
    ratio = table["pgv_pga_s"].astype(float)
    x = np.geomspace(pga.min() / 1.3, pga.max() * 1.3, 120)
    y = np.geomspace(ratio.min() / 1.5, ratio.max() * 1.5, 100)
    X, Y = np.meshgrid(x, y)
    for ax, name in zip(axes[0], names):
        st = _style(name)
        sub = table[table["column"] == name]
        fell = sub["toppled"].astype(bool)
        jitter = 1.0 + 0.03 * (sub["member"].astype(float) - sub["member"].astype(float).mean())
        ax.scatter(sub.loc[~fell, "pga_m_s2"] * jitter[~fell], sub.loc[~fell, "pgv_pga_s"],
                   facecolors="none", edgecolors=st["color"], s=18, label="stood")
        ax.scatter(sub.loc[fell, "pga_m_s2"] * jitter[fell], sub.loc[fell, "pgv_pga_s"],
                   color=st["color"], s=18, label="toppled")
        surface = summary.columns[name].logistic
        if surface.coefficients is not None:
            P = logistic_probability(surface.coefficients, X, Y)
            cs = ax.contour(X, Y, P, levels=list(CONTOUR_LEVELS), colors=[st["color"]],
                            linestyles=[":", "-", "--"], linewidths=1.2)
            ax.clabel(cs, fmt="%.2f", fontsize=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        _plain_log_ticks(ax.xaxis)
        _plain_log_ticks(ax.yaxis)
        ax.set_xlabel("PGA (m/s$^2$)")
        ax.set_ylabel("PGV/PGA (s)")
        title = st["label"]
        if surface.coefficients is not None:
            b = surface.coefficients
            title += (f"\nlogit P = {b['b0']:.2f} + {b['b1']:.2f} ln PGA + {b['b2']:.2f} "
                      f"ln(PGV/PGA)" + (" (Firth)" if surface.separated else ""))
        ax.set_title(title, fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="lower right")
    fig.suptitle("Logistic fragility surface (after Purvance et al. 2008)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path


def plot_pulse_grid(summary, path):
    """The pulse-grid fragility (a :class:`~pipeline.hazard.fragility.file.FragilityFile`)
    of each 3D specimen model: P per cell (colour), its contours at the P of
    :data:`~pipeline.hazard.pulse_cells.CONTOUR_LEVELS` (lines; the Monte Carlo band of
    the 0.5 contour shaded), the 2D rigid block's (same critical angle and pivot distance; the toolkit's
    Housner integrator) and, where experiments exist, the observed rate per bin."""
    section = summary.pulse_grid
    block = section.block2d.model
    names = [m for m in section.models if m != block] or [block]
    fig = figure(figsize=(5.2 * len(names), 4.4))
    axes = fig.subplots(1, len(names), squeeze=False)[0]
    ratios, pgas = np.array(section.pgv_pga_s), np.array(section.pga_g)
    for ax, name in zip(axes, names):
        cells = section.models[name].cells
        _, _, P, _ = lay_cells(pgas, ratios, cells)             # NaN: no run, left blank
        image = ax.pcolormesh(_edges(ratios), _edges(pgas), P, cmap="Greys", vmin=0, vmax=1,
                              shading="flat")
        for model, colour in ((name, "C3"), (block, "C0")):
            entry = section.models.get(model)
            for level, ls in zip(CONTOUR_LEVELS, (":", "-", "--")):
                rows = [r for r in (entry.contour(level) if entry else ()) if r.pga_g is not None]
                if rows:
                    who = "2D rigid block (Housner integrator)" if model == block else name
                    ax.plot([r.pgv_pga_s for r in rows], [r.pga_g for r in rows],
                            color=colour, ls=ls, lw=1.6, label=f"{who} P = {level:g}")
            band = [r for r in (entry.contour(0.5) if entry else ())
                    if None not in r.pga_g_band]
            if band and model == name:
                ax.fill_between([r.pgv_pga_s for r in band],
                                [r.pga_g_band[0] for r in band],
                                [r.pga_g_band[1] for r in band], color=colour, alpha=0.2,
                                lw=0, label="P = 0.5, Monte Carlo 95 %")
        _mark_outside(ax, section, name, ratios, pgas)
        check = None if section.experiments is None else section.experiments.models.get(name)
        observed = None if check is None else check.bins
        if observed:
            x = [np.mean(b["pgv_pga_s"]) for b in observed]
            y = [np.mean(b["pga_g"]) for b in observed]
            ax.scatter(x, y, c=[b["observed_rate"] for b in observed], cmap="Greys",
                              vmin=0, vmax=1, s=[12 + 3 * b["n"] ** 0.5 * 4 for b in observed],
                              edgecolors="C1", linewidths=1.2, label="observed rate (tests)",
                              zorder=5)
        ax.set_xlim(0.0, max(_edges(ratios)[-1], 1.0 if observed else 0.0))
        ax.set_ylim(0.0, max(_edges(pgas)[-1], 1.2 if observed else 0.0))
        ax.set_xlabel("PGV/PGA (s)")
        ax.set_ylabel("PGA (g)")
        ax.set_title(f"{summary.specimen} ({name}): P(overturn), one-cosine pulses\n"
                     f"direction: {section.direction.split(' (')[0]}", fontsize=8)
        ax.legend(fontsize=6, loc="upper right")
        fig.colorbar(image, ax=ax, label="P(overturn)")
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return [Path(path)]


def _mark_outside(ax, section, name, ratios, pgas):
    """Where the specimen's contours leave the grid (``outside_grid`` of fragility.json):
    a red arrow per PGV/PGA at the edge the P = 0.5 contour leaves by, and one red line per
    level and side under the axes."""
    edges = _edges(pgas)
    said = []
    for level, rows in section.models[name].contours.items():
        for side, y, marker, edge in (("below", edges[0], "v", min(pgas)),
                                      ("above", edges[-1], "^", max(pgas))):
            out = [r.pgv_pga_s for r in rows if r.outside_grid == side]
            if not out:
                continue
            said.append(f"P = {level} {side} the grid ({edge:g} g) at PGV/PGA "
                        f"{', '.join(f'{v:g}' for v in out)} s")
            if level == "0.5":
                ax.plot(out, [y] * len(out), ls="none", marker=marker, color="C3", ms=7,
                        clip_on=False, zorder=6, label=f"P = 0.5 {side} the grid")
    if said:
        text = "\n".join(textwrap.fill(line, 70) for line in said)
        ax.text(0.5, -0.16, "warning: contours leave the grid\n" + text,
                transform=ax.transAxes, ha="center", va="top", fontsize=6, color="C3")


def _edges(centres):
    """Cell edges around grid centres (a single centre: +-10 %)."""
    c = np.asarray(centres, float)
    if c.size == 1:
        return np.array([c[0] * 0.9, c[0] * 1.1])
    mid = (c[1:] + c[:-1]) / 2
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
