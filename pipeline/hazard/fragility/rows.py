"""The rows of a pulse grid's model in ``fragility.json``, each a type that checks itself
on construction: a cell (:class:`GridCell`) and a contour's row (:class:`ContourRow`).
What a row cannot know alone (a cell on the grid once, its sets below the grid's
``members``, its runs within the sets' headings) the file's checks say
(:mod:`pipeline.hazard.fragility.check`).  Keys a row does not name are kept, in their
order, in ``extra``."""
from dataclasses import dataclass

from pipeline.hazard.fragility.checker import MAX_MEMBERS, MAX_RUNS, TOLERANCE, Checker
from pipeline.hazard.fragility.keyed import Keyed, build, join

OUTSIDE = ("below", "above")      # where a contour's crossing lies beyond the grid


@dataclass(frozen=True)
class GridCell(Keyed):
    """One cell of a pulse grid's model: at ``pga_g`` (g) and ``pgv_pga_s`` (s), ``n``
    runs of which ``overturned`` overturned, ``P`` their fraction with its Wilson 95 %
    interval ``ci95`` (holding it); ``sets`` (indices of the parameter sets run there,
    each once), ``P_per_set`` (each set's P over its headings, None where it has no run;
    the pooled P within half a run of their range), ``set_sd`` (their standard
    deviation) and ``set_spread_sd`` (with each set's binomial variance removed)."""
    pga_g: float
    pgv_pga_s: float
    n: int = 0
    overturned: int = 0
    P: float | None = None
    ci95: tuple | None = None
    sets: tuple | None = None
    P_per_set: tuple | None = None
    set_sd: float | None = None
    set_spread_sd: float | None = None

    def __post_init__(self):
        c = Checker("")
        c.num(self.pga_g, "pga_g", 0, None, True)
        c.num(self.pgv_pga_s, "pgv_pga_s", 0, None, True)
        n = c.integer(self.n, "n", 0, MAX_RUNS)
        k = c.integer(self.overturned, "overturned", 0, n)
        p = c.num(self.P, "P", 0, 1, optional=True)
        if p is not None and n > 0 and abs(p - k / n) > TOLERANCE:
            c.fail("P", f"{p:g} is not overturned / n = {k}/{n}")
        c.pair(_listed(self.ci95), "ci95", 0, 1, k / n if n > 0 else None)
        p_sets = _listed(self.P_per_set)
        if p_sets is not None:
            for s, value in enumerate(c.lst(p_sets, "P_per_set", MAX_MEMBERS)):
                c.num(value, f"P_per_set[{s}]", 0, 1, optional=True)
        if self.sets is not None:
            indices = [c.integer(s, "sets", 0, MAX_MEMBERS - 1)
                       for s in c.lst(_listed(self.sets), "sets", MAX_MEMBERS)]
            if len(set(indices)) != len(indices):
                c.fail("sets", "names a parameter set twice")
            if p_sets is not None and len(p_sets) != len(indices):
                c.fail("P_per_set", f"holds {len(p_sets)} values for {len(indices)} sets")
        self._check_pooled(c)

    def _check_pooled(self, c):
        """Each set listed ran at least once: at most n sets' P, and the pooled P
        (overturned / n, the sets' P weighted by their runs) between the smallest and the
        largest set's P (within half a run)."""
        values = [p for p in self.P_per_set or () if p is not None]
        if not values:
            return
        n, overturned = self.n, self.overturned
        if len(values) > n:
            c.fail("P_per_set", f"holds {len(values)} sets' P for {n} runs (n)")
        pooled, slack = overturned / n, 0.5 / n + TOLERANCE       # within half a run
        if not min(values) - slack <= pooled <= max(values) + slack:
            c.fail("P_per_set", f"from {min(values):g} to {max(values):g} contradicts "
                                f"overturned / n = {overturned}/{n}")

    @classmethod
    def of(cls, data):
        """The cell of a dict as the campaign writes it."""
        return build(cls, data, _TUPLES)

    def to_json(self):
        return join(self, _LISTS)


@dataclass(frozen=True)
class ContourRow(Keyed):
    """Where one PGV/PGA row (``pgv_pga_s``, s) of a model's cells crosses a contour's
    level: ``pga_g`` (g; None where the row does not cross), ``pga_g_band`` (where the
    cells' Wilson bounds cross it, g; an open side None), ``outside_grid``
    (:data:`OUTSIDE` where the crossing lies beyond the grid, else None) and
    ``pga_g_per_set`` (parameter set index, as text, -> its own crossing, g, or None)."""
    pgv_pga_s: float
    pga_g: float | None = None
    pga_g_band: tuple | None = None
    outside_grid: str | None = None
    pga_g_per_set: dict | None = None

    def __post_init__(self):
        c = Checker("")
        c.num(self.pgv_pga_s, "pgv_pga_s", 0, None, True)
        c.num(self.pga_g, "pga_g", optional=True)
        band = _listed(self.pga_g_band)
        if band is not None and not (isinstance(band, list) and len(band) == 2):
            c.fail("pga_g_band", f"must be a pair [lo, hi], got {band!r:.60}")
        for value in band or ():
            c.num(value, "pga_g_band", optional=True)
        if self.outside_grid is not None and self.outside_grid not in OUTSIDE:
            c.fail("outside_grid", f"must be one of {', '.join(OUTSIDE)} or null, got "
                                   f"{self.outside_grid!r:.60}")
        if self.pga_g_per_set is not None:
            for s, value in c.obj(self.pga_g_per_set, "pga_g_per_set",
                                  MAX_MEMBERS).items():
                c.num(value, f"pga_g_per_set.{s}", optional=True)

    @classmethod
    def of(cls, data):
        """The row of a dict as the campaign writes it."""
        return build(cls, data, _TUPLES)

    def to_json(self):
        return join(self, _LISTS)


_ROW_LISTS = ("ci95", "sets", "P_per_set", "pga_g_band")   # tuples in a row's type
_TUPLES = dict.fromkeys(_ROW_LISTS, lambda v: tuple(v) if isinstance(v, list) else v)
_LISTS = dict.fromkeys(_ROW_LISTS, lambda v: list(v) if isinstance(v, tuple) else v)


def _listed(value):
    """A tuple (as a row holds it) as the list the file holds, for the checks."""
    return list(value) if isinstance(value, tuple) else value
