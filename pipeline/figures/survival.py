"""The survival figure: the site's hazard curve with the fragility, the fragility-weighted
rate density by PGA, and survival against age."""
import numpy as np

from pipeline.figures.style import DPI, new_figure
from pipeline.files import save_figure


def plot_survival(data, path):
    """Three panels from :func:`pipeline.hazard.assess.assess`'s figure data; writes
    ``path`` (PNG) atomically and returns it."""
    fig, (ax_h, ax_d, ax_s) = new_figure(1, 3, figsize=(13.5, 4.2))
    levels, rates = data["levels_m_s2"], data["rates_per_yr"]
    ax_h.loglog(levels, rates, "o-", color="k", ms=3, label="hazard curve (file levels)")
    ax_h.set_xlabel("PGA (m/s$^2$)")
    ax_h.set_ylabel("annual rate of exceedance (1/yr)")
    ax_h.grid(True, which="both", alpha=0.3)
    ax_p = ax_h.twinx()
    what = "P(any overturns | PGA)" if data["set"] else "P(overturn | PGA)"
    if data["pgv_pga_used"]:
        what += ", over PGV/PGA"
    ax_p.semilogx(data["probability_x"], data["probability"], color="tab:red", label=what)
    ax_p.set_ylim(0, 1)
    ax_p.set_ylabel(what, color="tab:red")
    ax_h.set_title("hazard and fragility")
    ax_h.legend(loc="lower left", fontsize=8)

    ax_d.semilogx(data["density_x"], data["density"], color="tab:blue")
    ax_d.fill_between(data["density_x"], data["density"], color="tab:blue", alpha=0.2)
    ax_d.set_xlabel("PGA (m/s$^2$)")
    ax_d.set_ylabel("P(overturn) |d$\\lambda$/d ln PGA| (1/yr)")
    top = data["top_share"]
    ax_d.set_title(f"rate density; at/above the last level: {100 * (top or 0):.0f} %",
                   fontsize=10)
    ax_d.grid(True, which="both", alpha=0.3)

    ages_ka = data["ages_yr"] / 1000.0
    ax_s.plot(ages_ka, data["survival"], color="k", label="survival at a known age")
    age_ka, band = data["age_yr"] / 1000.0, data["age_band"]
    if band is not None:
        ax_s.axvspan(band[0] / 1000.0, band[1] / 1000.0, color="0.85", label=band[2])
    p = data["survival_probability"]
    interval = data["survival_interval"]
    err = None if interval is None else np.array([[p - max(interval[0], p * 1e-6)],
                                                   [interval[1] - p]]).clip(0)
    ax_s.errorbar([age_ka], [p], yerr=err, fmt="o", color="tab:red", capsize=3,
                  label="over the age" + (", 95 % fragility interval" if err is not None else ""))
    ax_s.axhline(0.05, color="0.5", ls=":", label="5 %")
    ax_s.set_xlabel("age (ka)")
    ax_s.set_ylabel("P(survived)")
    if p < 0.05:                       # a small survival: a log axis shows where it lies
        low = max(min(p, float(np.min(data["survival"]))) / 3.0, 1e-15)
        ax_s.set_yscale("log")
        ax_s.set_ylim(low, 1.5)
    else:
        ax_s.set_ylim(0, 1.02)
    ax_s.set_xlim(0, ages_ka[-1])
    ax_s.legend(fontsize=8)
    ax_s.set_title("survival against age")
    fig.tight_layout()
    save_figure(fig, path, dpi=DPI)
    return path
