"""Ensemble figures: a rose of downfall azimuths with their circular density, the back
azimuth and the nominal run marked; the distribution of impact times."""
from pathlib import Path

import numpy as np

from pipeline.figures.style import COLUMN_COLOURS, COLUMN_LABELS, COLUMN_MARKERS, new_figure
from pipeline.files import save_figure
from pipeline.motion import RECORD_CLOCK
from pipeline.stats.ensemble import circular_density, wilson_interval
from pipeline.stats.circular import angle_difference_deg

BIN_DEG = 10.0


def plot_ensemble(members, summary, out_dir):
    """``rose.png`` and ``impact_times.png`` in ``out_dir`` from a members table (rows of
    runs.csv with a ``member`` column; member -1 is the nominal run)."""
    out_dir = Path(out_dir)
    columns = summary["columns"]
    fig, axes = new_figure(1, len(columns), figsize=(6 * len(columns), 6),
                           subplot_kw={"projection": "polar"}, squeeze=False)
    grid = np.arange(0.0, 360.0, 1.0)
    for ax, col in zip(axes[0], columns):
        colour = COLUMN_COLOURS.get(col["column"], "C2")
        group = members[(members["column"] == col["column"]) & (members["member"] >= 0)]
        az = group.loc[group["toppled"].astype(bool), "downfall_azimuth_deg"].to_numpy(float)
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        edges = np.arange(0.0, 360.0 + BIN_DEG, BIN_DEG)
        counts, _ = np.histogram(az % 360.0, bins=edges)
        fraction = counts / max(len(group), 1)
        ax.bar(np.radians(edges[:-1] + BIN_DEG / 2), fraction, width=np.radians(BIN_DEG),
               color=colour, alpha=0.45, edgecolor="k", linewidth=0.3,
               label=f"members per {BIN_DEG:g}° (fraction)")
        if az.size:
            density = circular_density(az, grid) * BIN_DEG * az.size / max(len(group), 1)
            ax.plot(np.radians(np.r_[grid, grid[:1]]), np.r_[density, density[:1]], color=colour,
                    lw=2, label="circular density (von Mises kernel)")
        top = max(fraction.max(initial=0.0), 0.05) * 1.15
        if summary["back_azimuth_deg"] is not None:
            ax.plot([np.radians(summary["back_azimuth_deg"])] * 2, [0, top], "k--", lw=1.2,
                    label=f"back azimuth {summary['back_azimuth_deg']:.0f}°")
        if col["nominal_downfall_azimuth_deg"] is not None:
            ax.plot([np.radians(col["nominal_downfall_azimuth_deg"])] * 2, [0, top], color="0.3",
                    lw=2.5, label=f"nominal run {col['nominal_downfall_azimuth_deg']:.0f}°")
        ax.set_rmax(top)
        lo, hi = col["p_toppled_ci95"]
        ax.set_title(f"{COLUMN_LABELS.get(col['column'], col['column'])}\nP(toppled) = "
                     f"{col['p_toppled']:.2f} [{lo:.2f}, {hi:.2f}], n = {col['members']}",
                     fontsize=10)
        ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.15, -0.22))
    fig.suptitle(f"Ensemble downfall directions: {summary['record']} (seed {summary['seed']})")
    fig.tight_layout()
    rose = out_dir / "rose.png"
    save_figure(fig, rose, dpi=120)

    fig, ax = new_figure(figsize=(7, 4))
    for col in columns:
        group = members[(members["column"] == col["column"]) & (members["member"] >= 0)]
        times = group["impact_time_s"].dropna().to_numpy(float)
        if times.size:
            ax.hist(times, bins=20, alpha=0.5, color=COLUMN_COLOURS.get(col["column"], "C2"),
                    label=f"{COLUMN_LABELS.get(col['column'], col['column'])} ({times.size} falls)")
    ax.set_xlabel(f"time of the first impact ({RECORD_CLOCK})")
    ax.set_ylabel("members")
    ax.set_title(f"Impact times: {summary['record']}")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    times_path = out_dir / "impact_times.png"
    save_figure(fig, times_path, dpi=120)
    return [rose, times_path]


def plot_pooled(members, pooled, out_dir):
    """``pooled.png`` in ``out_dir``: (left) every record's P(toppled) with its Wilson
    interval per column, records by their mean; (right) the falls' downfall minus back
    azimuth, every record weighing alike, against what falls that ignore the epicentre
    give (a flat histogram), with the pooled answer in the titles."""
    out_dir = Path(out_dir)
    rows = members[(members["member"] >= 0) & members["back_azimuth_deg"].notna()]
    records = pooled["record_ids"]
    fig, (left, right) = new_figure(1, 2, figsize=(13, max(4.5, 0.16 * len(records) + 2)))
    order = sorted(records, key=lambda r: -rows.loc[rows["record_id"] == r, "toppled"]
                   .astype(bool).mean())
    y = np.arange(len(order))
    edges = np.arange(-180.0, 181.0, 20.0)
    for k, col in enumerate(pooled["columns"]):
        name, colour = col["column"], COLUMN_COLOURS.get(col["column"], "C2")
        group = rows[rows["column"] == name]
        p, lo, hi, weights, diffs = [], [], [], [], []
        for record_id in order:
            sub = group[group["record_id"] == record_id]
            t = sub["toppled"].astype(bool).to_numpy()
            ci = wilson_interval(int(t.sum()), t.size)
            p.append(t.mean() if t.size else np.nan)
            lo.append(ci[0])
            hi.append(ci[1])
            d = angle_difference_deg(sub.loc[t, "downfall_azimuth_deg"].to_numpy(float),
                                     sub.loc[t, "back_azimuth_deg"].to_numpy(float))
            d = np.atleast_1d(d)
            if d.size:                                  # a record's falls share its weight
                diffs += list(d)
                weights += [1.0 / d.size] * d.size
        p = np.asarray(p)
        left.errorbar(p, y + 0.2 * (k - 0.5), xerr=[p - np.asarray(lo), np.asarray(hi) - p],
                      fmt=COLUMN_MARKERS.get(name, "o"), color=colour, ms=4, lw=0.8,
                      label=COLUMN_LABELS.get(name, name))
        with_falls = max(col["records_with_falls"], 1)
        right.hist(diffs, bins=edges, weights=np.asarray(weights) / with_falls, histtype="step",
                   lw=2, color=colour,
                   label=f"{COLUMN_LABELS.get(name, name)}: {col['falls']} falls, "
                   f"{col['records_with_falls']} records")
    left.set_yticks(y, order, fontsize=7)
    left.invert_yaxis()
    left.set_xlim(-0.02, 1.02)
    left.set_xlabel("P(toppled) per record, 95 % Wilson interval")
    left.grid(alpha=0.3)
    left.legend(fontsize=8, loc="lower right")
    flat = (edges[1] - edges[0]) / 360.0
    right.axhline(flat, color="k", ls="--", lw=1, label="falls that ignore the epicentre")
    for x in (-135, -45, 45, 135):
        right.axvline(x, color="0.6", lw=0.8, ls=":")
    right.set_xticks(np.arange(-180, 181, 45))
    right.set_xlabel("downfall azimuth minus back azimuth (deg; 0: toward the epicentre)")
    right.set_ylabel("fraction of a record's falls (mean over records)")
    right.grid(alpha=0.3)
    right.legend(fontsize=8)
    right.set_title("\n".join(f"{COLUMN_LABELS.get(c['column'], c['column'])}: polarity "
                              f"{c['statistics']['polarity']['estimate'] or 0:+.2f}, radial "
                              f"alignment {c['statistics']['radial_alignment']['estimate'] or 0:+.2f}"
                              for c in pooled["columns"]), fontsize=9)
    left.set_title(f"{pooled['records']} records, members per record: "
                   f"{min(pooled['members_per_record'].values())}-"
                   f"{max(pooled['members_per_record'].values())}", fontsize=9)
    fig.suptitle("The paper's question from ensembles: where do the columns fall?")
    fig.tight_layout()
    path = out_dir / "pooled.png"
    save_figure(fig, path, dpi=120)
    return path


def plot_convergence(members, result, out_dir):
    """``convergence.png``: per record (rows) and column (columns) the empirical
    distribution of the fall directions of every numerical variant, about the defaults'
    mean direction, with P(toppled) and the tests' p-values in the legend."""
    rows = result["rows"]
    records = list(dict.fromkeys(r["record"] for r in rows))
    columns = list(dict.fromkeys(r["column"] for r in rows))
    fig, axes = new_figure(len(records), len(columns), figsize=(6.5 * len(columns),
                                                                3.6 * len(records)),
                           squeeze=False)
    styles = ["-", "--", "-.", ":", (0, (5, 1))]
    for i, record in enumerate(records):
        for j, column in enumerate(columns):
            ax = axes[i][j]
            mine = [r for r in rows if r["record"] == record and r["column"] == column]
            centre = next((r["mean_downfall_azimuth_deg"] for r in mine
                           if r["variant"] == result["reference"]), None) or 0.0
            for k, r in enumerate(mine):
                sub = members[(members["record_id"] == record) & (members["column"] == column)
                              & (members["variant"] == r["variant"])]
                az = sub.loc[sub["toppled"].astype(bool), "downfall_azimuth_deg"].to_numpy(float)
                d = np.sort(np.atleast_1d(angle_difference_deg(az, centre)))
                tests = ("" if "fisher_p" not in r else
                         f"; Fisher p {r['fisher_p']:.2f}" + (
                             "" if r.get("kuiper_p") is None else f", Kuiper p {r['kuiper_p']:.2f}"))
                label = (f"{r['variant']}: P {r['p_toppled']:.2f} [{r['p_toppled_ci95'][0]:.2f}, "
                         f"{r['p_toppled_ci95'][1]:.2f}]{tests}")
                if d.size:
                    ax.step(np.r_[-180.0, d, 180.0], np.r_[0.0, np.arange(1, d.size + 1),
                                                        d.size] / r["members"],
                            where="post", ls=styles[k % len(styles)], lw=1.6, label=label)
                else:
                    ax.plot([], [], ls=styles[k % len(styles)], label=label)
            ax.set_xlim(-180, 180)
            ax.set_xticks(np.arange(-180, 181, 60))
            ax.set_ylim(0, 1.02)
            ax.grid(alpha=0.3)
            ax.set_title(f"{record}: {COLUMN_LABELS.get(column, column)}", fontsize=10)
            ax.set_xlabel(f"downfall azimuth minus {centre:.0f}° (deg)")
            ax.set_ylabel("fraction of members fallen")
            ax.legend(fontsize=6.5, loc="upper left")
    fig.suptitle("Convergence on distributions: fall directions and P(toppled) per numerical "
                 "setting", fontsize=11)
    fig.tight_layout()
    path = Path(out_dir) / "convergence.png"
    save_figure(fig, path, dpi=110)
    return path
