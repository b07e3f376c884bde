"""Report sections of the colonnade campaigns: ``campaign records --column-file`` a
colonnade (``make run-all`` writes results/colonnade): per record what the colonnade did
as a whole (colonnades.csv), its runs as probabilities (colonnade_statistics.json) and
each column's damage state (runs.csv); ``campaign colonnade-directions``
(results/colonnade-directions): the falls per direction of shaking (directions.csv) and
P(k columns fall) per direction and pulse (direction_statistics.json)."""
import pandas as pd

from pipeline.campaign.run_dirs import finished_summary
from pipeline.report.common import _figure, _fmt, _read_csv, _table
from pipeline.stats.colonnade import FILE as STATISTICS_FILE, ColonnadeStatistics
from pipeline.stats.colonnade_directions import FILE as DIRECTIONS_FILE, DirectionStatistics

COLONNADE_DIR = "colonnade"


def colonnade_section(results, name=COLONNADE_DIR):
    """The colonnade campaign in ``results/name``, when it has run."""
    folder = results / name
    whole, runs = _read_csv(folder / "colonnades.csv"), _read_csv(folder / "runs.csv")
    title = "## A colonnade under records (campaign records with a colonnade)\n"
    if whole is None or runs is None:
        return (title + "\nNot run yet (`make run-all`, or `python -m pipeline campaign "
                "records --column-file parthenon-north-flank`: see docs/colonnades.md).\n")
    columns = runs[runs["damage_state"].notna() & (runs["damage_state"].astype(str) != "")]
    rows = []
    for _, row in whole.iterrows():
        states = columns[columns["run_id"] == row["run_id"]].sort_values("column")
        standing = states[~states["toppled"].astype(str).str.lower().eq("true")]
        rows.append({
            "record": row["record_id"],
            "columns fallen": f"{row['columns_fallen']} of {row['columns']}",
            "beams fallen": f"{row['beams_fallen']} of {row['beams']}",
            "azimuth mean, spread (deg)": "-" if pd.isna(row["fall_azimuth_spread_deg"])
            else f"{_fmt(row['fall_azimuth_mean_deg'])}, "
                 f"{_fmt(row['fall_azimuth_spread_deg'])}",
            "parallel": _yes_no(row["parallel"]),
            "fall order (in sequence)": "-" if pd.isna(row["fall_order"]) else
            f"{row['fall_order']} ({_yes_no(row['in_sequence'])})",
            "damage state per column": ", ".join(
                f"{c['column']} {c['damage_state']}" for _, c in states.iterrows()),
            "largest residual slide of a standing column (mm)": _fmt(
                1000 * standing["max_residual_slide_m"].astype(float).max(), 1)
            if len(standing) else "-"})
    walls = [s.wall_s for s in (finished_summary(folder, r) for r in whole["run_id"])
             if s is not None]
    simulated = runs.drop_duplicates("run_id")["simulated_s"].astype(float).sum()
    names = ", ".join(sorted(set(whole["colonnade"])))
    statistics = _statistics(results, folder)
    lines = [title,
             f"The colonnade `{names}` (docs/colonnades.md: its proportions, sources and "
             f"what was assumed) shaken by {len(whole)} record(s), one run each, every "
             "column and beam a YADE body as described, at the contact stiffness "
             f"{_kn(runs)} N/m per point (the campaigns' matched rule for its heaviest "
             "column, unless --stiffness paper). A single run is a sample: "
             "counts, not probabilities (an ensemble gives those: `campaign ensemble "
             "--column-file`). Fall azimuths in deg clockwise from North; parallel: their "
             "circular spread under 15 deg; in sequence: the fallen columns struck one "
             "after the other along the row. Damage states as defined in docs/damage.md.\n",
             _table(pd.DataFrame(rows)) + "\n",
             *statistics,
             _falls_figure(results, folder),
             f"Cost: {simulated:.0f} s simulated in {sum(walls) / 60:.1f} min of YADE wall "
             f"time over {len(walls)} run(s) (files: `{name}/colonnades.csv`, "
             f"`{name}/runs.csv`).\n"]
    return "\n".join(lines)


def _statistics(results, folder):
    """The colonnade's runs as probabilities (colonnade_statistics.json and its figure),
    as lines of the section; none when the campaign wrote no statistics."""
    if not (folder / STATISTICS_FILE).exists():
        return []
    groups = ColonnadeStatistics.load(folder / STATISTICS_FILE).groups
    rows = [{"record": g.group, "runs": g.runs,
             **{f"P({k} fell)": _proportion(f) for k, f in enumerate(g.fallen)},
             "P(parallel given >= 2 fell)": _proportion(g.parallel, True),
             "P(in sequence given >= 3 fell)": _proportion(g.in_sequence, True),
             "P(in sequence)": _proportion(g.in_sequence_of_all)} for g in groups]
    return ["The same runs as probabilities (`colonnade_statistics.json`): the fraction of "
            "runs in which k columns fell, the fallen columns parallel given two or more "
            "fell with azimuths, in sequence given three or more fell, and in sequence of "
            "all runs, each with its Wilson 95 % interval, the Monte Carlo error of that "
            "many runs (an interval from a few runs is wide: it says how little they "
            "tell). Over the records the runs are pooled: a probability over these "
            "records, not over a site's motions.\n",
            _table(pd.DataFrame(rows)) + "\n",
            _figure(results, folder / "colonnade_statistics.png",
                    "P(k columns fall), parallel and in sequence, with Wilson 95 % "
                    "intervals")]


def _runs_each(whole):
    """How many runs each pulse and direction had: one, or that many members."""
    if whole is None or "member" not in whole:
        return "one run per pulse and direction (the colonnade as described)"
    return (f"{whole['member'].nunique()} members per pulse and direction (the ensemble's "
            "sampled contact and tolerances)")


def _falls_figure(results, folder):
    """colonnade_falls.png, where the campaign drew it."""
    return _figure(results, folder / "colonnade_falls.png",
                   "Where the columns fell: fall azimuths, North up, clockwise; the row's "
                   "axis and the circular mean drawn")


def _per_pulse(results, folder):
    """P(k columns fall) per direction and pulse (direction_statistics.json), as lines
    of the section; none when the campaign wrote none."""
    if not (folder / DIRECTIONS_FILE).exists():
        return []
    cases = DirectionStatistics.load(folder / DIRECTIONS_FILE).cases
    rows = [{"direction": c.direction, "PGA (g)": _fmt(c.pga_g, 2),
             "PGV/PGA (s)": _fmt(c.pgv_pga_s, 2), "runs": c.runs,
             **{f"P({k} fell)": _proportion(f) for k, f in enumerate(c.fallen)}}
            for c in cases]
    return ["Per direction and pulse (`direction_statistics.json`): the fraction of its "
            "runs in which k columns fell, with its Wilson 95 % interval.\n",
            _table(pd.DataFrame(rows)) + "\n"]


def _proportion(q, counts=False):
    """A :class:`~pipeline.stats.colonnade_counts.Proportion` as "p [lo, hi]" (and its counts)."""
    if q.p is None:
        return "- (0 of 0)" if counts else "-"
    lo, hi = q.ci95
    return f"{q.p:.2f} [{lo:.2f}, {hi:.2f}]" + (f" ({q.count} of {q.of})" if counts else "")


def _yes_no(value):
    if pd.isna(value):
        return "-"
    return "yes" if str(value).lower() == "true" else "no"


def _kn(runs):
    """The runs' contact stiffness (N/m per point), or its range."""
    lo, hi = runs["kn"].astype(float).min(), runs["kn"].astype(float).max()
    return f"{lo:.2g}" if lo == hi else f"{lo:.2g} to {hi:.2g}"


DIRECTIONS_DIR = "colonnade-directions"


def directions_section(results, name=DIRECTIONS_DIR):
    """The colonnade shaken along its row, across it and at 45 deg
    (``campaign colonnade-directions``), when it has run: directions.csv and the
    statistics grouped by direction."""
    folder = results / name
    table = _read_csv(folder / "directions.csv")
    title = "## A colonnade shaken in-plane, out-of-plane and obliquely\n"
    if table is None:
        return (title + "\nNot run yet (`make run-all`, or `python -m pipeline campaign "
                "colonnade-directions`: see docs/colonnades.md).\n")
    groups = {g.group: g for g in ColonnadeStatistics.load(folder).groups} \
        if (folder / STATISTICS_FILE).exists() else {}
    rows = []
    for _, row in table.iterrows():
        group = groups.get(row["direction"])
        rows.append({
            "direction": row["direction"],
            "azimuth (deg)": _fmt(row["azimuth_deg"]),
            "runs (samples)": int(row["runs"]),
            "runs with a column fallen": f"{int(row['runs_with_a_fall'])} of "
                                         f"{int(row['runs'])}",
            "P(a column falls) [Wilson 95 %]": f"{row['p_fall']:.2f} "
                                               f"[{row['p_fall_lo']:.2f}, {row['p_fall_hi']:.2f}]",
            "columns fallen (all runs)": f"{int(row['columns_fallen'])} of "
                                         f"{int(row['columns_shaken'])}",
            "per pulse (PGA, PGV/PGA: columns fallen)": row["fallen_per_pulse"],
            "parallel given >= 2 fell": "-" if group is None else
            _proportion(group.parallel, True)})
    whole = _read_csv(folder / "colonnades.csv")
    run_ids = [] if whole is None else whole["run_id"]
    summaries = [s for s in (finished_summary(folder, r) for r in run_ids) if s is not None]
    return "\n".join([
        title,
        "The shipped colonnade shaken by the same one-cosine pulses (the fragility's pulse "
        "shape) along its row (in-plane), across it (out-of-plane) and at 45 deg to it, "
        f"{_runs_each(whole)}. Runs are samples: the counts and their "
        "Wilson intervals say how few there are, not a probability over a site's "
        "motions. The 3D discrete-element study of the Forum colonnade at Pompeii found "
        "the out-of-plane capacity lower than the in-plane one; the table gives what "
        "these runs show, whichever way it goes.\n",
        _table(pd.DataFrame(rows)) + "\n",
        *_per_pulse(results, folder),
        _falls_figure(results, folder),
        f"Cost: {sum(s.wall_s for s in summaries) / 60:.1f} min of YADE wall time over "
        f"{len(summaries)} run(s) (files: `{name}/directions.csv`, `{name}/colonnades.csv`, "
        f"`{name}/colonnade_statistics.json`, `{name}/direction_statistics.json`).\n"])
