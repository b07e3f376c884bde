"""Figures of the verification campaign like the paper's Figs 4, 5 and 6, and the
one-cosine pulse's smallest overturning amplitude against Makris & Roussos (2000)."""
from pathlib import Path

import numpy as np
from matplotlib.colors import ListedColormap

from pipeline.rocking.housner import block_constants, housner_closed_form
from pipeline.rocking.pulse import MODE_NAMES, overturning_map
from pipeline.figures.style import new_figure
from pipeline.files import save_figure
from pipeline.verification import (CAMPAIGN_DAMPING, CAMPAIGN_THETA0, MARBLE_BLOCK,
                                   PULSE_BLOCK)


def plot_verification(results, out_dir, summary=None):
    """Figures like the paper's Figs 4 (Housner decay), 5 (one-sine pulse) and 6 (sliding);
    with ``summary`` (the summary's ``one_cosine``) the one-cosine figure too."""
    written = []
    # Fig. 4: amplitude decay, closed form (lines) and YADE (markers)
    fig, ax = new_figure(figsize=(7, 5), constrained_layout=True)
    for r0 in CAMPAIGN_THETA0:
        n = np.arange(0, 6)
        const = block_constants(MARBLE_BLOCK["height"], MARBLE_BLOCK["width"])
        ax.plot(n, housner_closed_form(r0, const["energy_ratio"], 5), "k-", lw=0.8)
        for z, marker in zip(CAMPAIGN_DAMPING, ("x", "o")):
            for s, r in results:
                if s.kind == "housner" and s["theta0_ratio"] == r0 and s["damping"] == z:
                    peaks = [r0] + r["yade"]["peaks_over_alpha"]
                    ax.plot(np.arange(len(peaks)), peaks, marker, ms=6, mfc="none",
                            color="C0" if z == CAMPAIGN_DAMPING[0] else "C3",
                            label=f"YADE, damping {z}" if r0 == CAMPAIGN_THETA0[0] else None)
    ax.plot([], [], "k-", lw=0.8, label="Housner (1963) eq. 6")
    ax.set(xlabel="number of impacts", ylabel="amplitude theta / alpha",
           title="Free rocking of the marble block (h/b = 5): amplitude decay")
    ax.legend()
    ax.grid(alpha=0.3)
    path = Path(out_dir) / "fig4_housner.png"
    save_figure(fig, path, dpi=120)
    written.append(path)
    # Fig. 5: overturning map (integration) with YADE outcomes
    amps = np.linspace(1.0, 12.0, 45)
    omegas = np.linspace(2.0, 10.0, 17)
    grid = overturning_map(PULSE_BLOCK["height"], PULSE_BLOCK["width"], amps, omegas)
    fig, ax = new_figure(figsize=(8, 5.5), constrained_layout=True)
    cmap = ListedColormap(["#e8f0e8", "#f6c9a0", "#b9d3ee"])
    ax.pcolormesh(amps, omegas, grid["mode"], cmap=cmap, vmin=-0.5, vmax=2.5, shading="nearest")
    codes = {v: k for k, v in MODE_NAMES.items()}
    markers = {0: "o", 1: "^", 2: "s"}
    for name, code in codes.items():
        pts = [(s["amplitude_ratio"], s["omega_ratio"]) for s, r in results
               if s.kind == "sine-pulse" and r["yade"]["mode"] == name]
        if pts:
            ax.scatter(*zip(*pts), marker=markers[code], c="k", s=40, label=f"YADE: {name}")
        ax.scatter([], [], marker="s", c=[cmap(code)], s=80, label=f"integration: {name}")
    ax.set(xlabel="pulse amplitude A / (alpha g)", ylabel="pulse frequency omega / p",
           title="One-sine pulse, block h 3.113 m, b 0.795 m (alpha 0.25, p 2.14 1/s)")
    ax.legend(fontsize=8, loc="upper left")
    path = Path(out_dir) / "fig5_sine_pulse.png"
    save_figure(fig, path, dpi=120)
    written.append(path)
    # Fig. 6: horizontal position of the base centre for each mu_s
    fig, ax = new_figure(figsize=(8, 5), constrained_layout=True)
    for s, r in sorted([x for x in results if x[0].kind == "sliding"],
                       key=lambda x: -x[0]["mu_s"]):
        run = r["runs"][0]
        ax.plot(run["t"], 1000 * np.asarray(run["base_x_m"]), lw=1,
                label=f"mu_s {run['mu_s']:g}" + ("" if run["pure_rocking"] else " (slides)"))
    mu_min = next((r["augusti_sinopoli_mu_min"] for s, r in results if s.kind == "sliding"), None)
    ax.set(xlabel="time (s)", ylabel="base centre, East (mm)",
           title=f"Rock-sliding test, marble block from 10 deg (eq. 8: mu_s > {mu_min:.3f})"
           if mu_min else "Rock-sliding test")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    path = Path(out_dir) / "fig6_sliding.png"
    save_figure(fig, path, dpi=120)
    written.append(path)
    return written + ([plot_one_cosine(summary, out_dir)] if summary else [])


def plot_one_cosine(summary, out_dir):
    """The smallest overturning amplitude under a one-cosine pulse over omega_p / p: the
    2D block (line), the YADE block (markers, its bracket as an error bar) and Makris &
    Roussos eq. 43 with its +-16 % (the verification summary's ``one_cosine``)."""
    fig, ax = new_figure(figsize=(7.5, 5), constrained_layout=True)
    w = np.linspace(0.5, 12.0, 100)
    eq43 = 1 + w / 4
    spread = summary["eq43"]["spread"]
    ax.plot(w, eq43, "k-", lw=1, label="Makris & Roussos eq. 43: 1 + omega_p / (4 p)")
    ax.fill_between(w, (1 - spread) * eq43, (1 + spread) * eq43, color="0.85",
                    label=f"eq. 43 +-{100 * spread:g} %")
    rows = [r for r in summary["curve_2d"] if r["over_alpha_g"] is not None]
    ax.plot([r["omega_ratio"] for r in rows], [r["over_alpha_g"] for r in rows], "C0.-",
            lw=1, ms=4, label="2D rigid block (Housner restitution)")
    alpha = summary["alpha_rad"]
    yade = [r for r in summary["curve_yade"] if r["threshold_g"] is not None]
    if yade:
        x = [r["omega_ratio"] for r in yade]
        y = np.array([r["threshold_g"] for r in yade]) / alpha
        err = np.array([[r["threshold_g"] - r["bracket_g"][0], r["bracket_g"][1] - r["threshold_g"]]
                        for r in yade]).T / alpha
        ax.errorbar(x, y, yerr=err, fmt="s", color="C3", mfc="none", ms=7,
                    label="YADE block (bisection)")
    f = summary["fig11"]
    ax.plot([2 * np.pi / summary["p_per_s"]], [np.mean(f["makris_roussos_g"]) / alpha], "k*",
            ms=11, label="Makris & Roussos Fig. 11 (T_p 1 s)")
    ax.set(xlabel="omega_p / p", ylabel="smallest overturning amplitude a_p / (alpha g)",
           yscale="log", xlim=(0.5, 12.0),
           title="One-cosine pulse, block b 0.5 m, h 1.5 m (alpha 18.4 deg, p 2.16 1/s)")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3, which="both")
    path = Path(out_dir) / "fig_one_cosine.png"
    save_figure(fig, path, dpi=120)
    return path
