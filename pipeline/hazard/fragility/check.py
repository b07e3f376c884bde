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
from pipeline.userfiles import nesting, number, show

MAX_MEMBERS = 10_000           # parameter sets of a campaign
MAX_RUNS = 10_000_000          # runs of one cell
MAX_TOTAL = 10 ** 15           # runs of a column, model or fit (counts only, no allocation)
MAX_AXIS = 1_000               # values on one axis of a pulse grid
MAX_SET_VALUES = 10_000_000    # members x cells: the per-set array a grid allocates
MAX_ENTRIES = 64               # column types or models in one file
MAX_RECORDS = 10_000
MAX_TEXT = 10_000              # characters of a note, description or record id
MAX_DEPTH = 32                 # the campaign's files nest about 8 deep
MAX_PGA_G = 20.0               # as the hazard curves' levels
MIN_PGA_G = MIN_PGA_M_S2 / STANDARD_GRAVITY   # the lowest PGA a grid may hold (g), a curve's
MAX_RATIO_S = 10.0             # PGV/PGA (s)
MIN_RATIO_S = 0.001            # the lowest, as --pgv-pga-median
MAX_HEADINGS = 360             # directions per parameter set (campaign fragility --headings)
TOLERANCE = 1e-9               # an estimate "inside" its interval, P = overturned / n


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


class Checker:
    """Typed reads of one file's values; each failure one line naming the key path."""

    def __init__(self, name):
        self.name = name

    def fail(self, where, what):
        raise InputError(f"{self.name}: {where} {what}" if self.name else f"{where} {what}")

    def obj(self, value, where, most=None):
        if not isinstance(value, dict):
            self.fail(where, f"must be an object, got {kind_of(value)}")
        if most is not None and len(value) > most:
            self.fail(where, f"holds {len(value)} entries (at most {most})")
        return value

    def lst(self, value, where, most):
        if not isinstance(value, list):
            self.fail(where, f"must be a list, got {kind_of(value)}")
        if len(value) > most:
            self.fail(where, f"holds {len(value)} values (at most {most})")
        return value

    def num(self, value, where, low=None, high=None, low_open=False, optional=False):
        if value is None and optional:
            return None
        return number(value, f"{self.name}: {where}" if self.name else where, low, high, "",
                      low_open)

    def integer(self, value, where, low, high, optional=False):
        if value is None and optional:
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(where, f"must be an integer, got {show(value)}")
        if not low <= value <= high:
            self.fail(where, f"must be {low} to {high}, got {show(value)}")
        return value

    def text(self, value, where):
        if value is not None and not (isinstance(value, str) and len(value) <= MAX_TEXT):
            self.fail(where, f"must be a text of at most {MAX_TEXT} characters, got "
                             f"{kind_of(value)}")
        return value

    def pair(self, value, where, low=None, high=None, holds=None, low_open=False):
        """A 95 % interval [lo, hi] (or None) within [low, high] that holds ``holds``."""
        if value is None:
            return None
        if not (isinstance(value, list) and len(value) == 2):
            self.fail(where, f"must be a pair [lo, hi], got {show(value)}")
        lo, hi = (self.num(v, where, low, high, low_open) for v in value)
        if lo > hi:
            self.fail(where, f"is [{lo:g}, {hi:g}]: lo above hi")
        if holds is not None and not lo - _slack(lo, holds) <= holds <= hi + _slack(hi, holds):
            self.fail(where, f"[{lo:g}, {hi:g}] does not hold its estimate {holds:g}")
        return lo, hi


def _slack(a, b):
    return TOLERANCE * max(1.0, abs(a), abs(b))


def kind_of(value):
    """What a JSON value is, for messages."""
    names = {dict: "an object", list: "a list", str: "a text", bool: "true/false",
             type(None): "null", int: "a number", float: "a number"}
    return f"{names.get(type(value), type(value).__name__)} {show(value, 40)}"


def key_text(name):
    """A key of the file as it appears in a key path."""
    return name if name.isidentifier() and len(name) <= 40 else show(name, 40)


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


def counts(c, entry, where, total, part):
    """Two counts of runs (integers, or absent), ``part`` of ``total``."""
    at = f"{where}." if where else ""
    n = c.integer(entry.get(total), f"{at}{total}", 0, MAX_TOTAL, optional=True)
    c.integer(entry.get(part), f"{at}{part}", 0, MAX_TOTAL if n is None else n, optional=True)


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
    """The cells of one model: each on the grid once, overturned of n, P and its interval,
    P per parameter set (``sets`` indices below ``members``; agreeing with the cell's
    counts, :func:`_check_set_counts`)."""
    if cells is None:
        c.fail(where, "is missing: a model holds its cells")
    seen = set()
    for k, cell in enumerate(c.lst(cells, where, len(pga) * len(ratio))):
        at = f"{where}[{k}]"
        c.obj(cell, at)
        a = c.num(cell.get("pga_g"), f"{at}.pga_g", 0, None, True)
        r = c.num(cell.get("pgv_pga_s"), f"{at}.pgv_pga_s", 0, None, True)
        key = (pga.get(round(a, 9)), ratio.get(round(r, 9)))
        if None in key:
            c.fail(at, f"is a cell off the grid: pga_g {a:g}, pgv_pga_s {r:g}")
        if key in seen:
            c.fail(at, f"duplicates the cell at pga_g {a:g}, pgv_pga_s {r:g}")
        seen.add(key)
        n = c.integer(cell.get("n"), f"{at}.n", 0, MAX_RUNS)
        k_over = c.integer(cell.get("overturned"), f"{at}.overturned", 0, n)
        p = c.num(cell.get("P"), f"{at}.P", 0, 1, optional=True)
        if p is not None and n > 0 and abs(p - k_over / n) > TOLERANCE:
            c.fail(f"{at}.P", f"{p:g} is not overturned / n = {k_over}/{n}")
        c.pair(cell.get("ci95"), f"{at}.ci95", 0, 1, k_over / n if n > 0 else None)
        _check_sets(c, cell, at, members)
        _check_set_counts(c, cell, at, n, k_over, headings)


def _check_sets(c, cell, at, members):
    sets, p_sets = cell.get("sets"), cell.get("P_per_set")
    if p_sets is not None:
        for s, p in enumerate(c.lst(p_sets, f"{at}.P_per_set", members)):
            c.num(p, f"{at}.P_per_set[{s}]", 0, 1, optional=True)
    if sets is None:
        return
    indices = [c.integer(s, f"{at}.sets", 0, members - 1)
               for s in c.lst(sets, f"{at}.sets", members)]
    if len(set(indices)) != len(indices):
        c.fail(f"{at}.sets", "names a parameter set twice")
    if p_sets is not None and len(p_sets) != len(indices):
        c.fail(f"{at}.P_per_set", f"holds {len(p_sets)} values for {len(indices)} sets")


def _check_set_counts(c: "Checker", cell: dict, at: str, n: int, overturned: int,
                      headings: int | None) -> None:
    """``P_per_set`` against the cell's counts.  Each set listed ran at least once: at
    most n sets, and the pooled P (overturned / n, the sets' P weighted by their runs)
    lies between the smallest and the largest set's P (within half a run).  With
    ``headings`` (a set's runs in a cell, at most): n at most sets x headings, and a
    cell where every set ran every heading has overturned = headings x the sum of the
    sets' P."""
    given = cell.get("P_per_set") or ()
    values = [p for p in given if p is not None]
    if not values:
        return
    where = f"{at}.P_per_set"
    if len(values) > n:
        c.fail(where, f"holds {len(values)} sets' P for {n} runs (n)")
    pooled, slack = overturned / n, 0.5 / n + TOLERANCE       # within half a run
    if not min(values) - slack <= pooled <= max(values) + slack:
        c.fail(where, f"from {min(values):g} to {max(values):g} contradicts overturned / n "
                      f"= {overturned}/{n}")
    if headings is None or len(values) != len(given):
        return
    if n > len(given) * headings:
        c.fail(f"{at}.n", f"{n} is more than {len(given)} sets x {headings} headings")
    counted = sum(values) * headings
    if n == len(given) * headings and abs(counted - overturned) > TOLERANCE * max(1, n):
        c.fail(where, f"gives {counted:g} overturned runs ({headings} headings per set), "
                      f"the cell {overturned}")
