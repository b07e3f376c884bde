"""Figure of the shake-table campaign: observed and predicted overturning rate per bin of
PGA and PGV/PGA."""
import numpy as np

from pipeline.figures.style import figure
from pipeline.files import save_figure
from pipeline.stats.classification import binned_rates


def plot_rates(table, path, result, pga_edges_g, pgv_pga_edges_s):
    """Three panels (bins: PGA edges g, PGV/PGA edges s; tests whose PGA is nominal,
    ``pga_nominal``, left out): observed rate (every test, with or without a motion), predicted rate
    and observed rate on the simulated tests; counts in each cell.  Returns the path."""
    PGA_EDGES_G, PGV_PGA_EDGES_S = np.asarray(pga_edges_g), np.asarray(pgv_pga_edges_s)
    if "pga_nominal" in table.columns:          # placeholder PGA values: no bin for them
        table = table[table["pga_nominal"].astype(int) == 0]
    simulated = table[[p is not None for p in table["predicted"]]]
    panels = [("observed, all tests", table, table["observed"]),
              ("observed, simulated tests", simulated, simulated["observed"]),
              ("predicted (YADE)", simulated, simulated["predicted"].astype(float))]
    fig = figure(figsize=(15, 4.8), layout="constrained")
    axes = fig.subplots(1, 3, sharey=True)
    for ax, (title, rows, outcome) in zip(axes, panels):
        rate, count = binned_rates(rows["pga_g"], rows["pgv_pga_s"],
                                   np.asarray(outcome, float), PGA_EDGES_G, PGV_PGA_EDGES_S)
        image = ax.imshow(rate.T, origin="lower", cmap="viridis", vmin=0, vmax=1,
                          aspect="auto", extent=(0, len(PGA_EDGES_G) - 1, 0,
                                                 len(PGV_PGA_EDGES_S) - 1))
        for i in range(rate.shape[0]):
            for j in range(rate.shape[1]):
                if count[i, j]:
                    ax.text(i + 0.5, j + 0.5, f"{rate[i, j]:.2f}\nn={count[i, j]}",
                            ha="center", va="center", fontsize=7,
                            color="white" if rate[i, j] < 0.6 else "black")
        ax.set_xticks(range(len(PGA_EDGES_G)), [f"{e:g}" for e in PGA_EDGES_G])
        ax.set_title(title)
        ax.set_xlabel("PGA (g)")
    axes[0].set_yticks(range(len(PGV_PGA_EDGES_S)), [f"{e:g}" for e in PGV_PGA_EDGES_S])
    axes[0].set_ylabel("PGV/PGA (s)")
    fig.colorbar(image, ax=axes, label="overturning rate", shrink=0.9)
    validation = result["splits"]["validation"]["model"]
    fig.suptitle(f"{result['specimen']['name']} on the shake table: overturning rate per bin "
                 f"(validation accuracy {validation['accuracy']:.2f}, n={validation['n']})"
                 if validation["n"] else f"{result['specimen']['name']} on the shake table")
    save_figure(fig, path, dpi=120)
    return path
