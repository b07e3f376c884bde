"""Figure of where the shake-table members and the laboratory disagree: the tests in the
PGA x PGV/PGA plane, right or wrong by kind, the split marked; and the error rate of the
members' majority per region with its Wilson 95 % interval."""
import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from pipeline.figures.style import figure
from pipeline.files import save_figure

KINDS = {"right": ("o", "0.6", "right"),
         "missed overturn": ("^", "tab:red", "missed overturn (overturned, P <= 0.5)"),
         "false overturn": ("v", "tab:blue", "false overturn (stood, P > 0.5)")}


def plot_disagreements(tests, regions, path, title):
    """``tests``: (PGA g, PGV/PGA s, verdict, split) per test, verdict one of
    :data:`KINDS`, split "calibration" (filled) or "validation" (open); ``regions``:
    (label, wrong, tests, ci95 low, ci95 high) per region, in order.  Returns the path."""
    fig = figure(figsize=(13, max(5.0, 0.28 * len(regions) + 1.5)), layout="constrained")
    left, right = fig.subplots(1, 2, width_ratios=(1.2, 1))
    for verdict, (marker, colour, label) in KINDS.items():
        for split, filled in (("calibration", True), ("validation", False)):
            rows = [t for t in tests if t[2] == verdict and t[3] == split]
            if not rows:
                continue
            pga, ratio = np.array([(r[0], r[1]) for r in rows], float).T
            left.scatter(pga, ratio, marker=marker, s=42 if verdict == "right" else 70,
                         facecolors=colour if filled else "none", edgecolors=colour,
                         linewidths=1.3, label=f"{label}, {split}", zorder=3)
    positive = [t for t in tests if t[0] > 0 and t[1] > 0]
    if len(positive) == len(tests) and tests:
        left.set_xscale("log")
        left.set_yscale("log")
        for axis in (left.xaxis, left.yaxis):
            axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(NullFormatter())
    left.set_xlabel("PGA (g)")
    left.set_ylabel("PGV/PGA (s)")
    left.set_title("tests: the members' majority against the laboratory")
    left.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    y = np.arange(len(regions))[::-1]
    for k, (label, wrong, n, lo, hi) in enumerate(regions):
        rate = wrong / n
        right.errorbar(rate, y[k], xerr=[[rate - lo], [hi - rate]], fmt="o",
                       color="tab:red" if wrong else "0.4", capsize=3)
        right.text(1.02, y[k], f"{wrong}/{n}", va="center", fontsize=8,
                   transform=right.get_yaxis_transform())
    right.set_yticks(y, [r[0] for r in regions], fontsize=8)
    right.set_xlim(0.0, 1.0)
    right.set_xlabel("error rate of the members' majority (fraction of tests), "
                     "Wilson 95 % interval")
    right.set_title("errors by region (wrong/tests at right)")
    right.grid(True, axis="x", alpha=0.3)
    fig.suptitle(title)
    save_figure(fig, path, dpi=120)
    return path
