"""A colonnade's runs as probabilities (``colonnade_statistics.png``): P(k of its columns
fell) per record with Wilson 95 % intervals, and P(parallel | two or more fell) and
P(in sequence | three or more fell) beside it."""
from pathlib import Path

import numpy as np

from pipeline.figures.style import figure
from pipeline.files import save_figure
from pipeline.stats.colonnade import ALL_RECORDS

MAX_GROUPS = 8          # the pooled group and the first records; more would not be read


def _shown(statistics):
    """The groups drawn: the pooled ones first, then records up to MAX_GROUPS."""
    pooled = [g for g in statistics.groups if g.group == ALL_RECORDS]
    rest = [g for g in statistics.groups if g.group != ALL_RECORDS]
    return (pooled + rest)[:MAX_GROUPS]


def _errors(proportions):
    """(p, [below, above]) of Proportions (NaN without runs) for errorbar."""
    p = np.array([np.nan if q.p is None else q.p for q in proportions])
    ci = np.array([q.ci95 for q in proportions])
    return p, np.array([np.where(np.isnan(p), 0, p - ci[:, 0]),
                        np.where(np.isnan(p), 0, ci[:, 1] - p)])


def plot_colonnade_statistics(statistics, path):
    """Draw a :class:`~pipeline.stats.colonnade.ColonnadeStatistics` to ``path``."""
    groups = _shown(statistics)
    fig = figure(figsize=(10.0, 3.8))
    left, right = fig.subplots(1, 2, gridspec_kw={"width_ratios": [2.2, 1]})
    width = 0.8 / len(groups)
    for j, g in enumerate(groups):
        k = np.arange(g.columns + 1)
        p, err = _errors(g.fallen)
        x = k + (j - (len(groups) - 1) / 2) * width
        left.bar(x, p, width, yerr=err, capsize=2, label=f"{g.group} ({g.runs} runs)",
                 color=f"C{j}", alpha=0.8, error_kw={"lw": 0.8, "ecolor": f"C{j}"})
        for m, q in enumerate((g.parallel, g.in_sequence)):
            pp, ee = _errors([q])
            right.errorbar([m + (j - (len(groups) - 1) / 2) * width], pp, yerr=ee,
                           fmt="o", color=f"C{j}", capsize=3, ms=5)
            right.annotate(f"{q.count}/{q.of}", (m + (j - (len(groups) - 1) / 2) * width,
                                                 0.0 if q.p is None else q.p),
                           xytext=(4, 2), textcoords="offset points", fontsize=7)
    name = groups[0].colonnade if groups else ""
    left.set_xticks(np.arange(max((g.columns for g in groups), default=0) + 1))
    left.set_xlabel("columns fallen, k")
    left.set_ylabel("P(k columns fall)")
    left.set_ylim(0, 1.3)
    left.set_yticks(np.linspace(0, 1, 6))
    left.set_title(f"{name}: columns fallen per run (Wilson 95 %)")
    left.legend(fontsize=7, loc="upper center", ncol=min(len(groups), 4), frameon=False)
    right.set_xticks([0, 1], ["parallel\n| >= 2 fell", "in sequence\n| >= 3 fell"])
    right.set_xlim(-0.6, 1.6)
    right.set_ylim(-0.05, 1.05)
    right.set_ylabel("probability")
    right.set_title("how they fell")
    save_figure(fig, Path(path))
    return Path(path)
