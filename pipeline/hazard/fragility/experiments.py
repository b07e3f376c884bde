"""The shake-table check of a pulse grid in ``fragility.json`` (``pulse_grid.experiments``,
written by :func:`pipeline.campaign.pulse_check.experiments_check`), each part a type
that checks itself on construction: the scores of one prediction (:class:`Scores`), a
model's (:class:`ModelCheck`) and the check (:class:`Experiments`).  Keys a part does
not name are kept, in their order, in ``extra``."""
from dataclasses import dataclass, field

from pipeline.hazard.fragility.checker import MAX_TEXT, MAX_TOTAL, Checker, key_text, leaf
from pipeline.hazard.fragility.keyed import Keyed, build, join


@dataclass(frozen=True)
class Scores(Keyed):
    """Scores of 0/1 outcomes of ``n`` tests under a prediction: the log-likelihood per
    test (P clipped to [0.01, 0.99]: 0 down to ln 0.01), the Brier score (0-1); for
    the grid ``outside_grid`` (tests beyond it) and ``empty_cells_filled`` (cells
    without runs, filled as survival fills them)."""
    log_likelihood_per_test: float
    brier: float
    n: int
    outside_grid: int | None = None
    empty_cells_filled: int | None = None

    def __post_init__(self):
        c = Checker("")
        c.num(self.log_likelihood_per_test, "log_likelihood_per_test", None, 0)
        c.num(self.brier, "brier", 0, 1)
        n = c.integer(self.n, "n", 0, MAX_TOTAL)
        c.integer(self.outside_grid, "outside_grid", 0, n, optional=True)
        c.integer(self.empty_cells_filled, "empty_cells_filled", 0, MAX_TOTAL, optional=True)

    @classmethod
    def of(cls, data):
        return build(cls, data)

    def to_json(self):
        return join(self)


@dataclass(frozen=True)
class ModelCheck(Keyed):
    """One model against the tests: its ``grid`` (the cells) and ``logistic`` (its
    surface, or None) :class:`Scores`, and ``bins``: observed rate and mean predicted P
    per PGA x PGV/PGA bin of the shake-table figure."""
    grid: Scores
    logistic: Scores | None = None
    bins: tuple = ()

    def __post_init__(self):
        Checker("").lst(list(self.bins), "bins", MAX_TOTAL)

    @classmethod
    def of(cls, data):
        return build(cls, data, {"grid": lambda v: _scores(v, "grid"),
                                 "logistic": lambda v: None if v is None else
                                 _scores(v, "logistic"),
                                 "bins": lambda v: tuple(v) if isinstance(v, list) else v})

    def to_json(self):
        return join(self, {"grid": Scores.to_json,
                           "logistic": lambda v: None if v is None else v.to_json(),
                           "bins": list})


@dataclass(frozen=True)
class Experiments(Keyed):
    """The check of a pulse grid against ``tests`` shake-table tests of which
    ``overturned`` overturned (``outcome``: whose; ``direction`` and ``note`` text):
    ``baselines`` (label -> :class:`Scores`) and ``models`` (name -> :class:`ModelCheck`)."""
    tests: int
    overturned: int
    outcome: str | None = None
    direction: str | None = None
    note: str | None = None
    baselines: dict = field(default_factory=dict)
    models: dict = field(default_factory=dict)

    def __post_init__(self):
        c = Checker("")
        tests = c.integer(self.tests, "tests", 0, MAX_TOTAL)
        c.integer(self.overturned, "overturned", 0, tests)
        for name in ("outcome", "direction", "note"):
            c.text(getattr(self, name), name)
        c.obj(self.baselines, "baselines", MAX_TEXT)
        c.obj(self.models, "models", MAX_TEXT)

    @classmethod
    def of(cls, data):
        return build(cls, data, {
            "baselines": lambda v: {k: _scores(s, f"baselines.{key_text(k)}")
                                    for k, s in _items(v, "baselines")},
            "models": lambda v: {k: _part(ModelCheck, m, f"models.{key_text(k)}")
                                 for k, m in _items(v, "models")}})

    def to_json(self):
        return join(self, {"baselines": lambda v: {k: s.to_json() for k, s in v.items()},
                           "models": lambda v: {k: m.to_json() for k, m in v.items()}})


def _items(value, where):
    return Checker("").obj(value, where, MAX_TEXT).items()


def _scores(data, where):
    return _part(Scores, data, where)


def _part(cls, data, where):
    """``cls`` of ``data`` at ``where`` (relative to the check), its refusals named so."""
    return leaf(cls, data, "", where)
