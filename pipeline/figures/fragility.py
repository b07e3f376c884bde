"""Fragility figures: lognormal curves with binned observations (Wilson intervals) per
intensity measure, the 3D columns against the 2D rigid block per record and level,
and the logistic (PGA, PGV/PGA) surface."""
from pathlib import Path

import numpy as np
from scipy import stats

from pipeline.figures.style import COLUMN_COLOURS, COLUMN_LABELS, COLUMN_MARKERS, figure
from pipeline.files import save_figure
from pipeline.stats.ensemble import logistic_probability, wilson_interval

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
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def plot_fragility(table, summary, out_dir):
    """``fragility_curves.png``, ``fragility_2d_vs_3d.png``, ``fragility_surface.png``."""
    out_dir = Path(out_dir)
    return [plot_curves(table, summary, out_dir / "fragility_curves.png"),
            plot_levels(table, out_dir / "fragility_2d_vs_3d.png"),
            plot_surface(table, summary, out_dir / "fragility_surface.png")]


def plot_curves(table, summary, path):
    """One row per IM, one panel per 3D column: its observations and lognormal fit beside
    those of the 2D block."""
    columns3d = [c for c, e in summary["columns"].items() if e["model"] == "3D"]
    blocks = [c for c, e in summary["columns"].items() if e["model"] == "2D"]
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
                entry = summary["columns"][name][im]
                st = _style(name)
                bins = entry["bins"]
                if bins:
                    x = np.array([b["im"] for b in bins]) * (1.0 + 0.025 * (k - 1))
                    y = np.array([b["fraction"] for b in bins])
                    err = np.array([[b["fraction"] - b["ci95"][0], b["ci95"][1] - b["fraction"]]
                                    for b in bins]).T
                    ax.errorbar(x, y, yerr=err, fmt=st["marker"], color=st["color"], ms=5,
                                capsize=2, lw=0.8, alpha=0.85)
                if entry["median"] is not None:
                    curve = stats.norm.cdf(np.log(grid / entry["median"]) / entry["beta"])
                    ax.plot(grid, curve, color=st["color"], ls=st["ls"], lw=1.8,
                            label=f"{st['label']}: median {entry['median']:.3g}, "
                                  f"β {entry['beta']:.2f}")
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
    fig.suptitle(f"Fragility (incremental dynamic analysis): {', '.join(summary['records'])}\n"
                 f"{summary['members']} members per level; bars: Wilson 95 %", fontsize=10)
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
    """Runs in the (PGA, PGV/PGA) plane (filled: toppled) with the P = 0.16, 0.5, 0.84
    contours of each model's logistic surface."""
    names = list(summary["columns"])
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
        surface = summary["columns"][name]["logistic"]
        if surface["coefficients"] is not None:
            P = logistic_probability(surface["coefficients"], X, Y)
            cs = ax.contour(X, Y, P, levels=[0.16, 0.5, 0.84], colors=[st["color"]],
                            linestyles=[":", "-", "--"], linewidths=1.2)
            ax.clabel(cs, fmt="%.2f", fontsize=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        _plain_log_ticks(ax.xaxis)
        _plain_log_ticks(ax.yaxis)
        ax.set_xlabel("PGA (m/s$^2$)")
        ax.set_ylabel("PGV/PGA (s)")
        title = st["label"]
        if surface["coefficients"] is not None:
            b = surface["coefficients"]
            title += (f"\nlogit P = {b['b0']:.2f} + {b['b1']:.2f} ln PGA + {b['b2']:.2f} "
                      f"ln(PGV/PGA)" + (" (Firth)" if surface["separated"] else ""))
        ax.set_title(title, fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="lower right")
    fig.suptitle("Logistic fragility surface (after Purvance et al. 2008)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    return path
