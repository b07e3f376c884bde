"""Figure of what the shipped 200 Hz shake-table motions lose against the 800 Hz records,
per test, against the test's PGA and PGV/PGA."""
import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.ticker import FuncFormatter

from pipeline.figures.style import DPI, figure
from pipeline.files import save_figure


def _two_and_five(value, _):
    """A log axis's minor label at 2 and 5 times a power of ten, else none."""
    mantissa = round(value / 10 ** np.floor(np.log10(value)), 6)
    return f"{value:g}" if mantissa in (2.0, 5.0) else ""


def plot_table_motion(pga_g, pgv_pga_s, observed, pga_lost, run_pga_change, run_pgv_change,
                      path):
    """Three panels, one point per test (circles: overturned, triangles: stood): the share
    of the 800 Hz PGA the 200 Hz file lacks (``pga_lost``, fraction) against the test's PGA
    (g, coloured by PGV/PGA, s) and against PGV/PGA (s, coloured by PGA); the change of the
    peak acceleration and velocity a run is driven with (fractions, 200 Hz over 800 Hz
    less 1) against PGA.  Returns the path."""
    pga, ratio = np.asarray(pga_g, float), np.asarray(pgv_pga_s, float)
    fell = np.asarray(observed, bool)
    lost = 100 * np.asarray(pga_lost, float)
    fig = figure(figsize=(15, 4.6), layout="constrained")
    axes = fig.subplots(1, 3)
    for ax, x, c, label, clabel in ((axes[0], pga, ratio, "test PGA (g)", "PGV/PGA (s)"),
                                    (axes[1], ratio, pga, "test PGV/PGA (s)", "PGA (g)")):
        image = None
        for mask, marker, name in ((fell, "o", "overturned"), (~fell, "^", "stood")):
            image = ax.scatter(x[mask], lost[mask], c=c[mask], marker=marker, s=14,
                               cmap="viridis", norm=LogNorm(c.min(), c.max()), label=name)
        ax.set_xscale("log")
        ax.axhline(0, color="0.5", lw=0.8)
        ax.set_xlabel(label)
        ax.set_ylabel("800 Hz PGA missing from the 200 Hz file (%)")
        ax.legend(loc="upper right", fontsize=8)
        bar = fig.colorbar(image, ax=ax, label=clabel)
        bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        bar.ax.yaxis.set_minor_formatter(FuncFormatter(_two_and_five))
    axes[0].set_title("raw peak lost by the decimation")
    axes[1].set_title("against the motion's period")
    ax = axes[2]
    ax.scatter(pga, 100 * np.asarray(run_pga_change, float), s=10, marker="o",
               label="peak acceleration")
    ax.scatter(pga, 100 * np.asarray(run_pgv_change, float), s=10, marker="x",
               label="peak velocity")
    ax.axhline(0, color="0.5", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel("test PGA (g)")
    ax.set_ylabel("200 Hz over 800 Hz, less 1 (%)")
    ax.set_title("what a run is driven with (0.1-25 Hz)")
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=DPI)
    return path
