"""Figures: one style (:mod:`.style`), object-oriented matplotlib, one module per kind.

:func:`campaign_figures` draws what a column campaign shows.
"""
from pathlib import Path

from pipeline.motion import Motion


def campaign_figures(name, runs, impacts, campaign_dir, size_by=None, animations=1):
    """A column campaign's figures: impact maps per record for sweeps (``size_by`` the
    swept parameter), a rose, toppling vs parameters and downfall vs directions for
    record sets, and GIF animations of the first ``animations`` toppled runs."""
    from pipeline.figures import campaign as cf  # lazy: matplotlib, not imported by a run or after Ctrl-C
    campaign_dir = Path(campaign_dir)
    written = []
    if size_by:
        for record_id, group in runs.groupby("record_id"):
            path = campaign_dir / f"impact_map_{record_id}.png"
            cf.plot_impact_map(group, impacts[impacts["run_id"].isin(group["run_id"])],
                               Motion.load(group["motion_file"].iloc[0]), path, size_by=size_by,
                               title=f"{name}: {record_id}")
            written.append(path)
    if runs["toppled"].astype(bool).any():
        written.append(cf.plot_rose(runs, campaign_dir / "rose.png"))
    if not size_by:
        written.append(cf.plot_toppling_vs_parameters(runs, campaign_dir /
                                                      "toppling_vs_parameters.png"))
        written.append(cf.plot_downfall_vs_directions(runs, campaign_dir /
                                                      "downfall_vs_directions.png"))
    if animations:
        written += animate_examples(runs, campaign_dir, animations)
    return written


def animate_examples(runs, campaign_dir, count=1):
    """GIF animations of the first toppled runs (the paper's online movies)."""
    from pipeline.figures.animation import animate_run  # lazy: matplotlib, not imported by a run or after Ctrl-C
    written = []
    toppled = runs[runs["toppled"].astype(bool)].drop_duplicates("run_id").head(count)
    for _, row in toppled.iterrows():
        path = Path(campaign_dir) / f"animation_{row['record_id']}_{row['run_id']}.gif"
        if not path.exists():
            animate_run(Path(campaign_dir) / row["run_dir"], path, fps=10, max_frames=250)
        written.append(path)
    return written
