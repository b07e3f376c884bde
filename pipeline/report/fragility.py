"""Report sections of fragility: lognormal fits per column model (campaign fragility)
and a specimen's fragility over the pulse grid (PGA in g, PGV/PGA in s)."""
import math

import pandas as pd

from pipeline.hazard.fragility.file import read_fragility_file
from pipeline.report.common import _figure, _fmt, _table


def fragility_section(results):
    """Lognormal fragility medians per column model and intensity measure (campaign
    fragility), when it has run."""
    path = results / "fragility" / "fragility.json"
    if not path.exists():
        return ("## Fragility\n\nNot run yet (`python -m pipeline campaign fragility`: "
                "P(toppled) against PGA, PGV and PGV/PGA from scaled records, beside a 2D "
                "rigid block).\n")
    summary = read_fragility_file(path)
    if summary.pulse_grid is not None:
        return rock_fragility_section(results, "fragility")
    rows = []
    for name, entry in summary.columns.items():
        row = {"model": name if entry.description is None else entry.description,
               "runs (toppled)": f"{entry.runs} ({entry.toppled})"}
        for im, fit in entry.fits.items():
            lo_hi = fit.median_ci95 or [None, None]
            row[f"{im} median [95 %] {fit.unit or ''}".strip()] = (
                "-" if fit.median is None else
                f"{fit.median:.3g} [{_fmt(lo_hi[0], 2)}, {_fmt(lo_hi[1], 2)}], "
                f"beta {_fmt(fit.beta, 2)}")
        rows.append(row)
    lines = ["## Fragility (campaign fragility)\n",
             f"Records {', '.join(map(str, summary.records))}; "
             f"{summary.members} members per record and level; lognormal "
             "maximum-likelihood fits P(toppled | IM) = Phi(ln(IM / median) / beta).\n",
             _table(pd.DataFrame(rows)) + "\n"]
    lines += damage_state_lines(summary)
    for fig in ("fragility_curves.png", "fragility_2d_vs_3d.png", "fragility_surface.png",
                "fragility_damage_states.png"):
        lines.append(_figure(results, results / "fragility" / fig, fig[:-4].replace("_", " ")))
    return "\n".join(lines)


def damage_state_lines(summary):
    """The damage-state fragilities of a campaign's ``fragility.json`` (a
    :class:`~pipeline.hazard.fragility.file.FragilityFile`): per 3D column type and
    state, the runs that reached it and the lognormal fit in PGA; [] without them."""
    if not summary.damage_states:
        return []
    rows = []
    for name, entry in summary.damage_states.items():
        for state in entry.states:
            fit = state.fits["PGA"]
            lo, hi = fit.median_ci95 or (None, None)
            rows.append({"column": name if entry.description is None else entry.description,
                         "damage state or worse": state.state,
                         "runs reached": f"{state.reached} of {state.runs}",
                         "PGA median [95 %] m/s^2": "-" if fit.median is None else
                         f"{fit.median:.3g} [{_fmt(lo, 2)}, {_fmt(hi, 2)}]",
                         "beta": _fmt(fit.beta, 2), "note": fit.note or ""})
    return ["Damage states (docs/damage.md): P(the state or a worse one | IM), fitted per "
            "state as P(toppled) is (lognormal in PGA here; PGV, PGV/PGA and the logistic "
            "surface in fragility.json, `damage_states`); the Monte Carlo error is the "
            "fits' 95 % intervals and the binned fractions' Wilson intervals there. A fit "
            "is missing where every run, or none, reached the state.\n",
            _table(pd.DataFrame(rows)) + "\n"]


ROCK_FRAGILITY = {
    "rock-fragility": ("Scanned rock fragility (pulse grid)",
                       "SP1's P(overturn) over the pulse grid vsr, from directions sampled "
                       "over 360 deg"),
    "rock-fragility-table": ("Scanned rock fragility along the table",
                             "SP1's P(overturn) over pulses in the range of its shake-table "
                             "tests, along the table's axis, against the tests")}


def _contour_rows(section):
    """Rows of the P-level contours of a pulse grid's models: PGA (g) per PGV/PGA with the
    Monte Carlo band in brackets."""
    rows = []
    for model, entry in section.models.items():
        for level, contour in entry.contours.items():
            row = {"model": model, "P": level}
            for r in contour:
                lo, hi = r.pga_g_band
                row[f"PGV/PGA {r.pgv_pga_s:g} s"] = (
                    f"{_fmt(r.pga_g, 2)} [{_fmt(lo, 2)}, {_fmt(hi, 2)}]")
            rows.append(row)
    return rows


def _experiment_lines(check):
    """The check against the shake-table experiments: the baselines' and each model's
    scores as a table."""
    def score_row(label, score):
        return {"prediction": label,
                "log-likelihood per test": _fmt(score.log_likelihood_per_test, 3),
                "Brier": _fmt(score.brier, 3), "tests": score.n}

    rows = [score_row(label, s) for label, s in check.baselines.items()]
    for model, result in check.models.items():
        rows.append(score_row(f"{model}: pulse fragility (grid; {result.grid.outside_grid}"
                              " tests outside it, nearest edge)", result.grid))
        if result.logistic is not None:
            rows.append(score_row(f"{model}: its logistic surface", result.logistic))
    return [f"Against the {check.tests} shake-table tests ({check.overturned} "
            f"overturned; {check.note}):\n", _table(pd.DataFrame(rows)) + "\n"]


def rock_fragility_section(results, name="rock-fragility"):
    """A specimen's fragility over the pulse grid (campaign fragility --pulses; ``make
    rock-fragility`` writes results/rock-fragility and results/rock-fragility-table):
    contours, logistic surface, the 2D block and the check against experiments, when it
    has run."""
    heading, what = ROCK_FRAGILITY.get(name, (f"Fragility over a pulse grid ({name})", ""))
    path = results / name / "fragility.json"
    summary = read_fragility_file(path) if path.exists() else None
    section = None if summary is None else summary.pulse_grid
    if section is None:
        return f"## {heading}\n\nNot run yet (`make rock-fragility`: {what}).\n"
    block = section.block2d
    lines = [f"## {heading}\n",
             f"{summary.specimen}: one-cosine displacement pulses over PGA "
             f"{min(section.pga_g):g}-{max(section.pga_g):g} g x PGV/PGA "
             f"{min(section.pgv_pga_s):g}-{max(section.pgv_pga_s):g} s "
             f"({len(section.pga_g)} x {len(section.pgv_pga_s)} cells); "
             f"{section.members} parameter sets drawn from `{section.ranges}` x "
             f"{section.headings} direction(s); direction: {section.direction}. "
             f"{section.runs_finished} of {section.runs} runs finished. The 2D rigid "
             f"block (the toolkit's Housner integrator) has the specimen's critical angle "
             f"({math.degrees(block.alpha_rad):.1f} deg, median over the runs) and pivot "
             f"distance ({block.R_m:.3f} m).\n",
             "PGA (g) where P(overturn) crosses each level, per PGV/PGA (linear between "
             "cells; in brackets where the Wilson 95 % bounds cross it, the Monte Carlo "
             "band; - beyond the grid):\n"]
    lines.append(_table(pd.DataFrame(_contour_rows(section))) + "\n")
    lines += [f"Warning: {w}.\n" for w in section.warnings]
    for model, entry in section.models.items():
        per_set = [r for r in entry.contour(0.5) if r.pga_g_per_set]
        shown = [f"{r.pgv_pga_s:g} s: " + ", ".join(_fmt(v, 2) for v in
                                                    r.pga_g_per_set.values())
                 for r in per_set]
        if shown:
            lines.append(f"P = 0.5 of each parameter set ({model}; the members' spread): "
                         + "; ".join(shown) + ".\n")
    spread = [c.set_sd for e in section.models.values() for c in e.cells
              if c.set_sd is not None]
    if spread:
        lines.append(f"Spread of P across the parameter sets (sd per cell): up to "
                     f"{max(spread):.2f}, mean {sum(spread) / len(spread):.2f}.\n")
    for model, entry in section.models.items():
        d = None if entry.logistic is None else entry.logistic.dimensionless
        if d:
            lines.append(f"Logistic surface ({model}): logit P = {d['c0']:.2f} + "
                         f"{d['b1']:.2f} ln(PGA / (g tan alpha)) + {d['b2']:.2f} ln(p PGV/PGA)"
                         + (" (Firth-penalised: separable outcomes)"
                            if entry.logistic.separated else "") + ".\n")
    if section.experiments:
        lines += _experiment_lines(section.experiments)
    lines.append(_figure(results, results / name / "fragility_pulse_grid.png",
                         "P(overturn) over the pulse grid, contours, 2D block, observed rates"))
    return "\n".join(lines)
