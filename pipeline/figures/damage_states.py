"""The fragility of each damage state against PGA: per 3D column, P(the state or worse)
observed per level (Wilson 95 % intervals) and its lognormal fit."""
from pathlib import Path

import numpy as np
from scipy import stats

from pipeline.figures.style import COLUMN_LABELS, figure
from pipeline.files import save_figure

STATE_COLOURS = {"slight": "#4daf4a", "moderate": "#ff7f00", "severe": "#e41a1c",
                 "collapse": "#377eb8"}


def plot_damage_states(summary, path):
    """``fragility_damage_states.png`` of a
    :class:`~pipeline.hazard.fragility.file.FragilityFile` with ``damage_states``: one
    panel per 3D column, one curve per state (PGA in m/s^2)."""
    entries = summary.damage_states
    fig = figure(figsize=(5.5 * len(entries), 3.8))
    axes = fig.subplots(1, len(entries), squeeze=False)[0]
    for ax, (name, entry) in zip(axes, entries.items()):
        levels = [b["im"] for s in entry.states for b in (s.fits["PGA"].bins or ())]
        grid = np.geomspace(min(levels) / 1.5, max(levels) * 1.5, 200) if levels else None
        for k, state in enumerate(entry.states):
            fit, colour = state.fits["PGA"], STATE_COLOURS[state.state]
            bins = fit.bins or ()
            if bins:
                x = np.array([b["im"] for b in bins]) * (1.0 + 0.02 * (k - 1.5))
                y = np.array([b["fraction"] for b in bins])
                err = np.array([[b["fraction"] - b["ci95"][0], b["ci95"][1] - b["fraction"]]
                                for b in bins]).T
                ax.errorbar(x, y, yerr=err, fmt="o", color=colour, ms=4, capsize=2, lw=0.8)
            label = f"{state.state}: {state.reached}/{state.runs}"
            if fit.median is not None and grid is not None:
                ax.plot(grid, stats.norm.cdf(np.log(grid / fit.median) / fit.beta),
                        color=colour, lw=1.8)
                label += f", median {fit.median:.3g} m/s$^2$"
            ax.plot([], [], color=colour, marker="o", label=label)
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.03)
        ax.set_xlabel("PGA (m/s$^2$)")
        ax.set_ylabel("P(damage state or worse)")
        ax.set_title(f"3D {COLUMN_LABELS.get(name, name)}")
        ax.legend(fontsize=7, loc="upper left")
    save_figure(fig, Path(path))
    return Path(path)
