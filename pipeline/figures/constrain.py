"""The constrained-hazard figure: the branches' curves (grey, darker with more posterior
weight), the prior and constrained mean and 5-95 % fractiles, the annual rates at which the
ground motion is stated, and the specimens' ages; beside it the weights before and after."""
import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard.ages import AgeKind
from pipeline.figures.style import DPI, figure
from pipeline.hazard.constrain_assess import BAND, fractile_key
from pipeline.files import save_figure

MAX_DRAWN_BRANCHES = 2000       # the fan of a larger tree: the branches of most weight


def plot_constrain(data, path):
    """Two panels from :func:`pipeline.hazard.constrain_assess.constrain_tree`'s figure
    data; writes ``path`` (PNG) atomically and returns it."""
    fig = figure(figsize=(12.5, 5.0))
    ax, ax_w = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.6, 1.0]})
    x = np.asarray(data["levels_m_s2"]) / STANDARD_GRAVITY
    rates = np.asarray(data["rates_per_yr"])
    after = data["posterior_weights"]
    shade = np.asarray(data["prior_weights"] if after is None else after, float)
    order = np.argsort(shade)[-MAX_DRAWN_BRANCHES:]
    top = shade.max() if shade.max() > 0 else 1.0
    for k in order:
        level = shade[k] / top
        ax.loglog(x, rates[k], color=str(0.85 - 0.6 * level), lw=0.6 + 1.2 * level,
                  zorder=1)
    ax.plot([], [], color="0.5", lw=1, label="branches (darker: more weight after)")
    _stats(ax, x, data["prior"], "k", "--", "prior")
    if data["posterior"] is not None:
        _stats(ax, x, data["posterior"], "tab:red", "-", f"constrained ({data['rule']})")
    for rate in data["target_rates"]:
        ax.axhline(rate, color="tab:blue", lw=0.6, ls=":", zorder=0)
        ax.annotate(f"{rate:g} /yr", (x[0], rate), fontsize=7, color="tab:blue",
                    va="bottom")
    ax.set_xlabel("PGA (g)")
    ax.set_ylabel("annual rate of exceedance (1/yr)")
    ax.grid(True, which="both", alpha=0.3)
    ages = ", ".join(_age(a) for a in data["ages"])
    ax.set_title(f"hazard constrained by specimens of age {ages} ka", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    _weights(ax_w, data)
    fig.tight_layout()
    save_figure(fig, path, dpi=DPI)
    return path


def _stats(ax, x, stats, colour, style, label):
    ax.loglog(x, stats.mean_rates_per_yr, color=colour, ls=style, lw=2.2,
              label=f"{label} mean", zorder=3)
    lo, hi = (stats.fractiles[fractile_key(q)] for q in BAND)
    ax.fill_between(x, lo, hi, color=colour, alpha=0.12, zorder=2,
                    label=f"{label} 5-95 % fractiles")
    ax.loglog(x, stats.fractiles[fractile_key(0.5)], color=colour, ls=style, lw=1.0, zorder=3,
              label=f"{label} median")


def _weights(ax, data):
    prior = np.asarray(data["prior_weights"], float)
    after = data["posterior_weights"]
    order = np.argsort(-prior, kind="stable")[:60]
    k = np.arange(len(order))
    ax.bar(k - 0.2, prior[order], width=0.4, color="0.6", label="prior")
    if after is not None:
        ax.bar(k + 0.2, np.asarray(after)[order], width=0.4, color="tab:red",
               label=f"after ({data['rule']})")
    if len(order) <= 30:
        ax.set_xticks(k, [str(data["branch_ids"][j]) for j in order], rotation=90, fontsize=7)
    ax.set_xlabel("branch (by prior weight" + (", first 60)" if len(prior) > 60 else ")"))
    ax.set_ylabel("weight")
    ax.set_title("branch weights", fontsize=10)
    ax.legend(fontsize=8)


def _age(age):
    """A specimen's age (an AgeModel, years) in ka as the title gives it."""
    if age.kind is AgeKind.NORMAL:
        return f"{age.mean_yr / 1000:g}" + (f" $\\pm$ {age.sd_yr / 1000:g}"
                                            if age.sd_yr > 0 else "")
    if age.kind is AgeKind.LOWER_BOUND:
        return f"> {age.min_yr / 1000:g}"
    if age.kind is AgeKind.INTERVAL:
        return f"{age.lo_yr / 1000:g}-{age.hi_yr / 1000:g}"
    return f"~{age.typical_yr / 1000:.3g}"
