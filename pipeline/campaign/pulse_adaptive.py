"""The adaptive sampling of the pulse grid (:mod:`pipeline.campaign.pulse_grid`): stages
that run more runs only in the cells (PGA in g x PGV/PGA in s) that decide where the
P = 0.5 contour lies, guided by the 2D block's P, until a stage changes nothing.
"""
import numpy as np

from pipeline.stats.ensemble import wilson_interval


MAX_STAGES = 12
ADAPTIVE_LEVEL = 0.5        # the contour whose side every cell is decided on
# a cell near a change runs this many first: all alike, its Wilson interval excludes
# ADAPTIVE_LEVEL (0 of 4 overturned: upper bound 0.49)
ADAPTIVE_FIRST_RUNS = 4


def cell_key(spec):
    return spec.tags.cell


def run_order(member, heading, headings):
    """Sort key of a cell's runs: its first runs are distinct parameter sets shaken from
    distinct direction sectors (the diagonals of the members x headings square)."""
    return ((heading - member) % headings, member)


def guide_cells(guide_p, margin=1):
    """Cells (i ratio, j PGA) near the guide's threshold: where the guide's P (a dict
    cell -> P, e.g. the 2D block over the same members and directions) is strictly
    between 0 and 1, and ``margin`` cells either side in PGA (the specimen's threshold
    may lie beside the guide's); a step of the guide between two cells counts as
    uncertain on both sides."""
    chosen = set()
    for (i, j), p in guide_p.items():
        step = any(guide_p.get((i, j + d), p) != p for d in (-1, 1))
        if 0.0 < p < 1.0 or step:
            chosen.update((i, j + d) for d in range(-margin, margin + 1)
                          if (i, j + d) in guide_p)
    return chosen


def first_crossings(p_by_cell, level=ADAPTIVE_LEVEL):
    """Per row i (a PGV/PGA): the first cell j (lowest PGA) whose P reaches ``level``,
    where :func:`~pipeline.campaign.pulse_summary.contours` finds the ``level`` contour
    (P made non-decreasing in PGA)."""
    crossing = {}
    for (i, j), p in sorted(p_by_cell.items()):
        if i not in crossing and p >= level:
            crossing[i] = j
    return crossing


def first_targets(guide_p, per_cell, first=ADAPTIVE_FIRST_RUNS, margin=1):
    """Runs per cell of the first stage: ``first`` near the guide's threshold
    (:func:`guide_cells`) up to ``margin`` cells above the first cell where the guide's P
    reaches 0.5 (the cells above do not move the 0.5 contour), one probe run elsewhere
    (at most ``per_cell``)."""
    near = guide_cells(guide_p, margin)
    top = first_crossings(guide_p)
    return {(i, j): min(per_cell, first if (i, j) in near and j <= top.get(i, j) + margin
                        else 1)
            for (i, j) in guide_p}


def next_targets(guide_p, outcomes, targets, per_cell, first=ADAPTIVE_FIRST_RUNS,
                 level=ADAPTIVE_LEVEL):
    """Runs per cell of the next stage (never fewer than ``targets``), from the outcomes so far
    (cell -> overturned per finished run, in :func:`run_order`), row by row (a PGV/PGA) as
    :func:`~pipeline.campaign.pulse_summary.contours` reads them: the ``level`` contour lies
    below the first cell whose P reaches ``level``. That cell and the one below it run all
    ``per_cell`` runs, the full grid's count: the contour's position rests on them. The
    cells above them do not move it and stop. A cell below them whose Wilson 95 % interval
    excludes ``level`` is decided and stops; otherwise, with mixed outcomes or ``first``
    runs or more, it doubles (up to ``per_cell``); with fewer runs all alike (a probe) it
    goes to ``first`` only next to a change: a neighbour in PGA with another outcome, or its
    outcome against the guide's (P >= 0.5); elsewhere it stays a probe."""
    new = dict(targets)
    crossing = first_crossings({cell: np.mean(fell) for cell, fell in outcomes.items() if fell},
                               level)
    for (i, j), fell in outcomes.items():
        m, k = len(fell), int(sum(fell))
        lo, hi = wilson_interval(k, m)
        top = crossing.get(i)
        if top is not None and top > 0 and j in (top - 1, top):
            want = per_cell if m >= first else first
        elif top is not None and j > top or m == 0 or not lo <= level <= hi:
            continue
        elif 0 < k < m or m >= first:
            want = max(first, 2 * m)
        else:
            alike = k == m
            beside = [outcomes.get((i, j + d)) or [] for d in (-1, 1)]
            if not (any(v != alike for row in beside for v in row)
                    or (guide_p[(i, j)] >= 0.5) != alike):
                continue
            want = first
        new[(i, j)] = max(new[(i, j)], min(per_cell, want))
    return new


def adaptive_sampling(guide_p, per_cell, run_stage, max_stages=MAX_STAGES):
    """The stages of the adaptive pulse grid: ``run_stage(stage, targets)`` runs the first
    ``targets[cell]`` runs of every cell (in :func:`run_order`) and returns their outcomes
    (cell -> overturned per finished run); from :func:`first_targets` until
    :func:`next_targets` changes nothing. Returns (targets, settled: False when
    ``max_stages`` ran out first)."""
    targets = first_targets(guide_p, per_cell)
    for stage in range(1, max_stages + 1):
        new = next_targets(guide_p, run_stage(stage, targets), targets, per_cell)
        if new == targets:
            return targets, True
        targets = new
    return targets, False

