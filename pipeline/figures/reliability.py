"""Reliability diagram: observed rate against mean forecast probability per bin, with
the observed rate's Wilson 95 % interval (rows of
:func:`pipeline.stats.forecast.reliability_table`)."""
from pipeline.figures.style import figure
from pipeline.files import save_figure


def plot_reliability(panels, path, title=""):
    """One panel per entry of ``panels`` ({name: reliability rows}); the diagonal is
    perfect calibration, each point labelled with its number of tests.  Returns the
    path."""
    fig = figure(figsize=(4.6 * len(panels), 4.6), layout="constrained")
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    for ax, (name, rows) in zip(axes, panels.items()):
        ax.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="calibrated")
        for row in rows:
            lo, hi = row["observed_ci95"]
            ax.errorbar(row["mean_forecast"], row["observed_rate"],
                        yerr=[[row["observed_rate"] - lo], [hi - row["observed_rate"]]],
                        fmt="o", color="C0", ms=4 + min(row["n"], 100) ** 0.5, capsize=3)
            ax.annotate(f"{row['n']}", (row["mean_forecast"], row["observed_rate"]),
                        textcoords="offset points", xytext=(6, -10), fontsize=7)
        n = sum(r["n"] for r in rows)
        ax.set_title(f"{name} ({n} tests)")
        ax.set_xlim(-0.03, 1.03)
        ax.set_ylim(-0.03, 1.03)
        ax.set_aspect("equal")
        ax.set_xlabel("predicted P (mean in bin)")
    axes[0].set_ylabel("observed overturning rate (Wilson 95 %)")
    if title:
        fig.suptitle(title)
    save_figure(fig, path, dpi=120)
    return path
