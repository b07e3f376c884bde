"""Loading a campaign's fragility (``campaign fragility``'s ``fragility.json``) as a
:class:`~pipeline.hazard.fragility.kinds.Fragility`: a column campaign's lognormal PGA
fit or logistic surface with its members' own fits (:func:`load_campaign_fragility`,
:func:`member_fits`), or a pulse grid (:func:`load_pulse_grid`)."""
import io
from dataclasses import replace

import numpy as np
import pandas as pd

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.fragility.components import on_hazard_measure
from pipeline.hazard.fragility.checker import key_text
from pipeline.hazard.fragility.file import MAX_MEMBERS, FragilityFile, read_fragility_file
from pipeline.hazard.fragility.grid import BELOW_GRID, PulseGrid
from pipeline.hazard.fragility.kinds import BETA_RANGE, MEDIAN_G_RANGE, Logistic, Lognormal
from pipeline.hazard.pulse_cells import lay_cells
from pipeline.stats.fragility import fragility_fit, logistic_surface
from pipeline.userfiles import DATA_FILE_BYTES, Unreadable, number, read_text, show

# what a fragility is read as: its PGA fit, its logistic surface, a pulse grid's cells, or
# auto (the surface of columns, the cells of a pulse grid)
FRAGILITY_FORMS = ("auto", "pga", "pga-pgv", "grid")
BLOCK_MODEL = "block2d"          # a pulse grid's 2D rigid block, beside the specimen


def load_campaign_fragility(path, column=None, form="auto", below="ramp", component=None,
                            magnitude=None, distance_km=None, record_fraction=None,
                            members=True):
    """The fragility of one column entry of ``campaign fragility``'s ``fragility.json``:
    ``form`` "pga" (its lognormal PGA fit), "pga-pgv" (its logistic surface) or "auto"
    (pga-pgv);
    ``column``: monolithic, drums, block2d or block2d_worst (default: the first 3D one).
    A pulse-grid file (``--pulses``): :func:`load_pulse_grid` (``form`` "auto": "grid";
    ``below``: P below the grid, :class:`PulseGrid`).  Each member's own fit of the same
    form (from ``fragility_runs.csv`` beside the file, when there) in ``member_fits``,
    refitted only when ``members`` asks for them (survival's members' spread).
    ``component`` (rotd50 or rotd100, the hazard curve's PGA): the fragility put on it
    (:func:`pipeline.hazard.fragility.components.on_hazard_measure`, ``record_fraction(record)``
    the RotD50 / vector peak of a record's motion); None: as in the file."""
    fragility, kind, records = _load_campaign_fragility(path, column, form, below, members)
    if component is None:
        return fragility
    return on_hazard_measure(fragility, kind, component, records, record_fraction,
                             magnitude, distance_km)


def _load_campaign_fragility(path, column, form, below, members):
    """(fragility, "line" | "records", record ids) of :func:`load_campaign_fragility`."""
    file = read_fragility_file(path)          # every value below checked
    path = file.path
    if file.pulse_grid is not None:
        return load_pulse_grid(file, column, "grid" if form == "auto" else form, below), \
            "line", ()
    form = "pga-pgv" if form == "auto" else form
    columns = file.columns
    if column is None:
        column = next((c for c in ("monolithic", "drums") if c in columns), next(iter(columns)))
    if column not in columns:
        raise InputError(f"{path}: no column {column!r} (has "
                         f"{', '.join(map(key_text, columns))})")
    entry = columns[column]
    named = key_text(column)                 # as a key path names it: one line
    label = f"{column} ({entry.description or ''}) from {path.name}"
    if form == "pga":
        fit = entry.fits.get("PGA")
        if fit is None:
            raise InputError(f"{path}: column {named}: no PGA fit in the file (give "
                             "--fragility-form pga-pgv for its logistic surface)")
        if fit.median is None:
            raise InputError(f"{path}: column {named}: PGA fragility not fitted "
                             f"({fit.note or 'no median'})")
        pooled = _pga_lognormal(fit, f"{path}: column {named}: PGA", label)
    elif form == "pga-pgv":
        pooled = _logistic(entry.logistic, f"{path}: column {named}", label)
    else:
        raise InputError(f"--fragility-form must be pga or pga-pgv, got {form!r}")
    if not members:
        return pooled, "records", file.records
    fits, note = member_fits(path.parent / "fragility_runs.csv", column, form, file.block2d)
    pooled = replace(pooled, member_fits=fits,
                     note="; ".join(filter(None, [pooled.note, note])) or None)
    return pooled, "records", file.records


def _pga_lognormal(fit, where, label):
    """The :class:`Lognormal` of a file's lognormal PGA fit (a
    :class:`~pipeline.hazard.fragility.fits.LognormalFit` with a median), its median and
    beta in the ranges a stated one takes."""
    if fit.unit != "m/s^2":
        raise InputError(f"{where}: fit in unknown unit {fit.unit!r} (expected m/s^2)")
    low, high = (g * STANDARD_GRAVITY for g in MEDIAN_G_RANGE)
    return Lognormal(number(fit.median, f"{where} median", low, high, "m/s^2"),
                     number(fit.beta, f"{where} beta", *BETA_RANGE),
                     _floats(fit.median_ci95), _floats(fit.beta_ci95), label=label,
                     note=fit.note)


def load_state_fragilities(path, column):
    """(fragilities, source): the fragility of each damage state below collapse (slight,
    moderate, severe), P(DS >= s | PGA) on the file's PGA, of ``column`` in a
    ``fragility.json``'s ``damage_states``: its lognormal PGA fit (None for a state no
    run, or every run, reached); ``source`` says where they came from.  A file without
    damage-state fits, or without the column's, gives (None, None, None) and a source
    saying so."""
    file = read_fragility_file(path)
    path = file.path
    entry = (file.damage_states or {}).get(column)
    if entry is None:
        held = ", ".join(map(key_text, file.damage_states or {}))
        return (None,) * 3, (f"{path} holds no damage-state fits" + (
            f" for column {key_text(column)}, only for {held}" if held else
            ": give --state-lognormal, or a fragility.json of campaign fragility with "
            "damage_states"))
    fitted, states = [], {s.state: s for s in entry.states}
    for state in ("slight", "moderate", "severe"):
        fit = states[state].fits.get("PGA") if state in states else None
        fitted.append(None if fit is None or fit.median is None else _pga_lognormal(
            fit, f"{path}: damage_states.{key_text(column)}.{state}: PGA",
            f"damage state {state} or worse of {column} from {path.name} (lognormal PGA "
            "fit)"))
    return tuple(fitted), (f"{path}: damage_states.{key_text(column)}, the lognormal PGA "
                           "fit of each state")


def member_fits(runs_path, column, form, block=None):
    """(one fragility per member of a column campaign fitted to its own runs, note): the
    lognormal PGA fit (form "pga") or the logistic surface ("pga-pgv") of
    :mod:`pipeline.stats.fragility`, as the campaign fits the pooled runs; (None, note)
    when the runs table is absent or no member's fit is determined.  ``block``: the
    file's :class:`~pipeline.hazard.fragility.file.Block2d` (the surface's alpha and p)
    or None."""
    if not runs_path.is_file():
        return None, f"no {runs_path.name} beside the file: the members' spread not available"
    try:
        table = pd.read_csv(io.StringIO(read_text(runs_path, DATA_FILE_BYTES)))
        sub = table[table["column"] == column]
        groups = sorted(sub.groupby("member"), key=lambda item: item[0])
    except (OSError, Unreadable, ValueError, KeyError, pd.errors.ParserError) as exc:
        raise InputError(f"{runs_path}: not a fragility_runs.csv of campaign fragility "
                         f"({exc})") from None
    if len(groups) > MAX_MEMBERS:
        raise InputError(f"{runs_path}: {len(groups)} members (at most {MAX_MEMBERS})")
    fits, skipped = [], []
    for member, rows in groups:
        try:
            y = rows["toppled"].astype(str).str.lower().isin(("true", "1")).to_numpy()
            pga = rows["pga_m_s2"].astype(float).to_numpy()
            ratio = rows["pgv_pga_s"].astype(float).to_numpy()
        except (KeyError, ValueError, TypeError):
            raise InputError(f"{runs_path}: member {show(member)}: no readable toppled, "
                             "pga_m_s2 and pgv_pga_s") from None
        if not (np.isfinite(pga).all() and np.isfinite(ratio).all() and (pga > 0).all()
                and (ratio > 0).all()):
            raise InputError(f"{runs_path}: member {show(member)}: pga_m_s2 and pgv_pga_s "
                             "must be positive finite numbers")
        label = f"member {show(member)}"
        if form == "pga":
            fit = fragility_fit(pga, y)
            if fit["median"] is None:
                skipped.append(f"{show(member)} ({fit['note']})")
                continue
            outside = _lognormal_outside(fit["median"], fit["beta"])
            if outside:
                skipped.append(f"{show(member)} ({outside})")
                continue
            fits.append(Lognormal(float(fit["median"]), float(fit["beta"]), label=label))
        else:
            fit = logistic_surface(pga, ratio, y, alpha=None if block is None else block.alpha_rad,
                                   p=None if block is None else block.p_per_s)
            b = fit["coefficients"]
            if b is None or not b["b1"] > 0:
                skipped.append(f"{show(member)} ({fit.get('note') or 'does not grow with PGA'})")
                continue
            fits.append(Logistic((b["b0"], b["b1"], b["b2"]), label=label))
    note = None if not skipped else (f"{len(skipped)} of {len(groups)} member(s) not fitted "
                                     f"alone, left out of the members' spread: "
                                     f"{'; '.join(skipped)}")
    return (tuple(fits) or None), note


def _lognormal_outside(median_m_s2: float, beta: float) -> str | None:
    """What of a fitted lognormal lies outside the ranges a stated one takes (text), or
    None."""
    low, high = MEDIAN_G_RANGE
    median_g = median_m_s2 / STANDARD_GRAVITY
    if not low <= median_g <= high:
        return f"median {median_g:.3g} g outside {low:g}-{high:g} g"
    if not BETA_RANGE[0] <= beta <= BETA_RANGE[1]:
        return f"beta {beta:.3g} outside {BETA_RANGE[0]:g}-{BETA_RANGE[1]:g}"
    return None


def _floats(pair):
    """An interval of a checked fit as floats (None stays None)."""
    return None if pair is None else tuple(float(v) for v in pair)


def _logistic(surface, where, label):
    """The :class:`Logistic` of a fragility.json's ``logistic`` surface (a
    :class:`~pipeline.hazard.fragility.fits.LogisticSurface`, checked, or None)."""
    if surface is None or surface.b is None:
        note = None if surface is None else surface.note
        raise InputError(f"{where}: logistic surface not fitted ({note or 'no coefficients'})")
    if not surface.b[1] > 0:
        raise InputError(f"{where}: the logistic surface does not grow with PGA "
                         f"(b1 = {surface.b[1]:g})")
    note = surface.note
    if surface.covariance is None:   # none given, or nulls (a singular information matrix)
        note = "; ".join(filter(None, [note, "no covariance in the file: coefficients drawn "
                                       "independently (their correlation ignored)"]))
    return Logistic(surface.b, surface.covariance, surface.se_b, label=label, note=note)


def load_pulse_grid(file, model=None, form="grid", below="ramp"):
    """One model of a pulse-grid :class:`~pipeline.hazard.fragility.file.FragilityFile`
    (``models``: monolithic, block2d; read and checked by its reader): ``form`` "grid"
    (:class:`PulseGrid`, ``below`` what P is below it; a grid of one row or column
    interpolated along the other axis) or "pga-pgv" (its logistic surface)."""
    if below not in BELOW_GRID:
        raise InputError(f"--below-grid must be one of {', '.join(BELOW_GRID)}, got {below!r}")
    path, section = file.path, file.pulse_grid
    models = section.models
    if model is None:
        model = _specimen_model(file)
    if model not in models:
        raise InputError(f"{path}: pulse_grid has no model {model!r} (has "
                         f"{', '.join(map(key_text, models))})")
    entry = models[model]
    where = f"{path}: pulse_grid model {key_text(model)}"
    label = f"{file.specimen or 'specimen'} {model} pulse grid from {path.name}"
    surface = entry.logistic
    logistic = None if surface is None or surface.b is None else \
        _logistic(surface, where, label)
    if form == "pga-pgv":
        if logistic is None:
            _logistic(surface, where, label)          # says why not
        return logistic
    if form != "grid":
        raise InputError(f"--fragility-form for a pulse grid must be grid or pga-pgv, got "
                         f"{form!r}")
    n, overturned, _, per_set = lay_cells(section.pga_g, section.pgv_pga_s, entry.cells,
                                          section.members)
    empty = int((n == 0).sum())
    if empty == n.size:
        raise InputError(f"{where}: no cell with runs (every n is 0)")
    note = None if not empty else (f"{empty} of {n.size} cells without runs: filled from the "
                                   "nearest cell along PGA")
    block = section.block2d
    uplift = None if block is None or block.uplift_g_smallest is None else \
        block.uplift_g_smallest * STANDARD_GRAVITY
    return PulseGrid(tuple(float(v) * STANDARD_GRAVITY for v in section.pga_g),
                     tuple(float(v) for v in section.pgv_pga_s), n, overturned, per_set,
                     logistic, label, note, uplift, below)


def _specimen_model(file: FragilityFile) -> str:
    """The name of a pulse grid's specimen model (monolithic, or the first that is not
    its 2D block); InputError when it holds only the 2D block's: the rigid block of the
    specimen's critical angle is not the rock."""
    section = file.pulse_grid
    block = {BLOCK_MODEL} | ({section.block2d.model} if section.block2d is not None
                             and section.block2d.model is not None else set())
    if "monolithic" in section.models:
        return "monolithic"
    specimen = [m for m in section.models if m not in block]
    if not specimen:
        raise InputError(f"{file.path}: pulse_grid holds only its 2D rigid block's model "
                         f"({', '.join(section.models)}), not the specimen's: give --column "
                         f"{next(iter(section.models))} to take the block for the rock")
    return specimen[0]
