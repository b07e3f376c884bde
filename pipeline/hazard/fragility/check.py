"""The checks of ``campaign fragility``'s ``fragility.json`` as a user passes it around:
:func:`check_fragility` checks every value a reader of it uses before any of them
allocates or computes (the fits check themselves on construction too,
:mod:`pipeline.hazard.fragility.fits`, with :class:`Checker`): types (object, list,
number, string), finite numbers within their ranges, sizes (a 3 x 3 covariance; axes,
cells, members and runs within bounds, counts as integers) and what would contradict
itself (a duplicated cell, overturned outside 0..n, a P outside 0-1, an interval that
does not hold its estimate, a covariance that is not symmetric positive semi-definite).
Each refusal is one InputError naming the file and the key path, e.g.
``fragility.json: columns.monolithic.logistic.cov must be a 3x3 list of numbers``.  The
file's one reader (:func:`pipeline.hazard.fragility.file.read_fragility_file`) runs them.

Two layouts, as the campaign writes them: a column campaign (``columns``: per column type
its lognormal PGA fit and logistic surface; ``records``, ``members``, ``block2d``) and a
pulse grid (``pulse_grid``: axes ``pga_g`` x ``pgv_pga_s``, ``members``, ``models`` with
their ``cells`` and logistic surface, ``block2d``).  Older files load: a covariance
absent or written as nulls (a singular information matrix), cells without ``sets``, a
2D block without ``uplift_g_smallest``.  Keys that no reader uses are not checked.
"""
import math

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.curves import MIN_PGA_M_S2
from pipeline.hazard.fragility.checker import (MAX_MEMBERS, MAX_TEXT, TOLERANCE, Checker,
                                               counts, key_text, kind_of, leaf)
from pipeline.hazard.fragility.rows import GridCell
from pipeline.userfiles import nesting

MAX_AXIS = 1_000               # values on one axis of a pulse grid
MAX_SET_VALUES = 10_000_000    # members x cells: the per-set array a grid allocates
MAX_ENTRIES = 64               # column types or models in one file
MAX_RECORDS = 10_000
MAX_DEPTH = 32                 # the campaign's files nest about 8 deep
MAX_PGA_G = 20.0               # as the hazard curves' levels
MIN_PGA_G = MIN_PGA_M_S2 / STANDARD_GRAVITY   # the lowest PGA a grid may hold (g), a curve's
MAX_RATIO_S = 10.0             # PGV/PGA (s)
MIN_RATIO_S = 0.001            # the lowest, as --pgv-pga-median
MAX_HEADINGS = 360             # directions per parameter set (campaign fragility --headings)


def check_fragility(data, name="fragility.json"):
    """``data`` (a parsed fragility.json) when every value its readers use is of the
    right type, size and range (see the module); else InputError naming ``name`` and the
    key path."""
    c = Checker(name)
    if not isinstance(data, dict):
        c.fail("the file", f"must hold a JSON object (campaign fragility's fragility.json), "
                           f"got {kind_of(data)}")
    if nesting(data, MAX_DEPTH) > MAX_DEPTH:
        c.fail("the file", f"is nested deeper than {MAX_DEPTH} levels")
    c.text(data.get("specimen"), "specimen")
    if "pulse_grid" in data:
        _check_pulse_grid(c, data["pulse_grid"])
    elif "columns" in data:
        _check_columns(c, data)
    else:
        raise InputError(f"{name}: not a fragility.json of campaign fragility (no 'columns')")
    return data


# ---------------------------------------------------------------- the parts
def _check_columns(c, data):
    columns = c.obj(data["columns"], "columns", MAX_ENTRIES)
    if not columns:
        c.fail("columns", "is empty: not a fragility.json of campaign fragility (no 'columns')")
    for column, entry in columns.items():
        where = f"columns.{key_text(column)}"
        c.obj(entry, where)
        c.text(entry.get("description"), f"{where}.description")
        counts(c, entry, where, "runs", "toppled")
        if entry.get("PGA") is not None:           # survival reads it: bounded further
            _check_lognormal(c, entry["PGA"], f"{where}.PGA")
        if entry.get("logistic") is not None:      # its values: LogisticSurface
            c.obj(entry["logistic"], f"{where}.logistic")
    if data.get("records") is not None:
        for k, record in enumerate(c.lst(data["records"], "records", MAX_RECORDS)):
            if not isinstance(record, str) or not record or len(record) > MAX_TEXT:
                c.fail(f"records[{k}]", f"must be a record id (a text), got {kind_of(record)}")
    c.integer(data.get("members"), "members", 1, MAX_MEMBERS, optional=True)
    if data.get("block2d") is not None:
        block = c.obj(data["block2d"], "block2d")
        c.num(block.get("alpha_rad"), "block2d.alpha_rad", 0, math.pi / 2, True, True)
        c.num(block.get("p_per_s"), "block2d.p_per_s", 0, 1e4, True, True)


def _check_lognormal(c, fit, where):
    """The lognormal fit of the PGA, as survival reads it: {unit, median, beta (at most
    100), median_ci95, beta_ci95 (both bounds given), n, toppled, note}, its intervals
    holding their estimates (any fit's checks: :class:`~pipeline.hazard.fragility.fits.
    LognormalFit`)."""
    c.obj(fit, where)
    c.text(fit.get("unit"), f"{where}.unit")
    c.text(fit.get("note"), f"{where}.note")
    median = c.num(fit.get("median"), f"{where}.median", 0, None, True, True)
    beta = c.num(fit.get("beta"), f"{where}.beta", 0, 100, True, True)
    c.pair(fit.get("median_ci95"), f"{where}.median_ci95", 0, None, median, True)
    c.pair(fit.get("beta_ci95"), f"{where}.beta_ci95", 0, None, beta, True)
    counts(c, fit, where, "n", "toppled")


def _check_pulse_grid(c, section):
    c.obj(section, "pulse_grid")
    pga = _axis(c, section.get("pga_g"), "pulse_grid.pga_g", MIN_PGA_G, MAX_PGA_G)
    ratio = _axis(c, section.get("pgv_pga_s"), "pulse_grid.pgv_pga_s", MIN_RATIO_S,
                  MAX_RATIO_S)
    members = c.integer(section.get("members"), "pulse_grid.members", 1, MAX_MEMBERS)
    headings = c.integer(section.get("headings"), "pulse_grid.headings", 1, MAX_HEADINGS,
                         optional=True)
    if members * len(pga) * len(ratio) > MAX_SET_VALUES:
        c.fail("pulse_grid", f"of {members} members x {len(pga)} x {len(ratio)} cells is "
                             f"beyond {MAX_SET_VALUES:.0e} values per set and cell")
    models = section.get("models")
    if models is None or models == {}:
        c.fail("pulse_grid", "has no 'models'")
    c.obj(models, "pulse_grid.models", MAX_ENTRIES)
    for model, entry in models.items():
        where = f"pulse_grid.models.{key_text(model)}"
        c.obj(entry, where)
        counts(c, entry, where, "runs", "overturned")
        if entry.get("logistic") is not None:      # its values: LogisticSurface
            c.obj(entry["logistic"], f"{where}.logistic")
        _check_cells(c, entry.get("cells"), f"{where}.cells", pga, ratio, members, headings)
    if section.get("block2d") is not None:
        block = c.obj(section["block2d"], "pulse_grid.block2d")
        for key in ("uplift_g_smallest", "uplift_g"):
            c.num(block.get(key), f"pulse_grid.block2d.{key}", 0, MAX_PGA_G, True, True)
        c.num(block.get("alpha_rad"), "pulse_grid.block2d.alpha_rad", 0, math.atan(MAX_PGA_G),
              True, True)


def _axis(c, values, where, low, high):
    """An axis of the grid: 1 to MAX_AXIS increasing numbers from ``low`` to ``high``,
    distinct to 9 digits (the cells are found by them)."""
    if values is None:
        c.fail(where, "is missing: the grid's axes are pga_g and pgv_pga_s")
    values = [c.num(v, where, low, high) for v in c.lst(values, where, MAX_AXIS)]
    if not values:
        c.fail(where, "is empty")
    for a, b in zip(values, values[1:]):
        if round(a, 9) >= round(b, 9):
            c.fail(where, f"must increase (distinct to 9 digits): {a!r} then {b!r}")
    return {round(v, 9): k for k, v in enumerate(values)}


def _check_cells(c, cells, where, pga, ratio, members, headings=None):
    """The cells of one model: each a :class:`~pipeline.hazard.fragility.rows.GridCell`
    (its own values checked), on the grid once, its ``sets`` below ``members`` and its
    runs within them (:func:`_check_set_counts`)."""
    if cells is None:
        c.fail(where, "is missing: a model holds its cells")
    seen = set()
    for k, data in enumerate(c.lst(cells, where, len(pga) * len(ratio))):
        at = f"{where}[{k}]"
        _check_sets(c, data, at, members)
        cell = leaf(GridCell, data, c.name, at)
        a, r = cell.pga_g, cell.pgv_pga_s
        key = (pga.get(round(a, 9)), ratio.get(round(r, 9)))
        if None in key:
            c.fail(at, f"is a cell off the grid: pga_g {a:g}, pgv_pga_s {r:g}")
        if key in seen:
            c.fail(at, f"duplicates the cell at pga_g {a:g}, pgv_pga_s {r:g}")
        seen.add(key)
        _check_set_counts(c, cell, at, headings)


def _check_sets(c, cell, at, members):
    """A cell's ``P_per_set`` and ``sets`` within the grid's ``members`` (what the cell
    cannot know alone)."""
    if not isinstance(cell, dict):
        return                                  # refused by the cell's type
    if cell.get("P_per_set") is not None:
        c.lst(cell["P_per_set"], f"{at}.P_per_set", members)
    if cell.get("sets") is not None:
        for s in c.lst(cell["sets"], f"{at}.sets", members):
            c.integer(s, f"{at}.sets", 0, members - 1)


def _check_set_counts(c: Checker, cell: GridCell, at: str, headings: int | None) -> None:
    """``P_per_set`` of a checked ``cell`` against ``headings`` (a set's runs in a cell,
    at most): n at most sets x headings, and a cell where every set ran every heading
    has overturned = headings x the sum of the sets' P."""
    given = cell.P_per_set or ()
    values = [p for p in given if p is not None]
    if not values or headings is None or len(values) != len(given):
        return
    n, overturned = cell.n, cell.overturned
    if n > len(given) * headings:
        c.fail(f"{at}.n", f"{n} is more than {len(given)} sets x {headings} headings")
    counted = sum(values) * headings
    if n == len(given) * headings and abs(counted - overturned) > TOLERANCE * max(1, n):
        c.fail(f"{at}.P_per_set", f"gives {counted:g} overturned runs ({headings} headings "
                                  f"per set), the cell {overturned}")
