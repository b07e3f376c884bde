"""Record figure like the paper's Fig. 8: acceleration traces and displacement hodogram."""
import numpy as np

from pipeline.figures.style import figure
from pipeline.files import save_figure
from pipeline.motion import RECORD_CLOCK


def plot_motion(motion, path):
    """Figure like the paper's Fig. 8: E, N, Up acceleration traces and the 3D
    displacement hodogram with its projections on the three coordinate planes."""
    meta, dt = motion.meta, motion.dt
    acc, disp = motion.acc, motion.disp * 100.0  # cm
    time = np.arange(len(acc)) * dt + motion.start_in_file_s       # the record's clock
    fig = figure(figsize=(12, 6.5))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.1, 1.0])
    limit = max(np.max(np.abs(acc)), 1e-9) * 1.05
    for i, name in enumerate(("East", "North", "Up")):
        ax = fig.add_subplot(grid[i, 0])
        ax.plot(time, acc[:, i], lw=0.6, color="k")
        ax.set_ylim(-limit, limit)
        ax.set_ylabel(f"{name}\n(m/s$^2$)")
        ax.grid(alpha=0.3)
        if i < 2:
            ax.tick_params(labelbottom=False)
    ax.set_xlabel(f"time ({RECORD_CLOCK})")
    ax3 = fig.add_subplot(grid[:, 1], projection="3d")
    e, n, u = disp[:, 0], disp[:, 1], disp[:, 2]
    span = max(np.max(np.abs(disp)), 1e-9) * 1.1
    ax3.plot(e, n, u, color="C3", lw=1.0, label="displacement")
    shadow = {"color": "0.55", "lw": 0.6}
    ax3.plot(e, n, np.full_like(u, -span), **shadow)
    ax3.plot(e, np.full_like(n, span), u, **shadow)
    ax3.plot(np.full_like(e, -span), n, u, **shadow)
    ax3.set_xlim(-span, span)
    ax3.set_ylim(-span, span)
    ax3.set_zlim(-span, span)
    ax3.set_xlabel("East (cm)")
    ax3.set_ylabel("North (cm)")
    ax3.set_zlabel("Up (cm)")
    ax3.set_box_aspect((1, 1, 1), zoom=0.85)
    baz = meta.get("back_azimuth_deg")
    note = f"back azimuth {baz:.0f}°" if baz is not None else "back azimuth unknown"
    ax3.set_title(f"displacement hodogram ({note})", fontsize=10)
    title = f"{meta['record_id']}: {meta.get('event') or ''}, {meta.get('station') or ''}"
    if not meta.get("has_vertical"):
        title += " (no vertical in source)"
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
