"""``fragility.json``'s ``damage_states``: per 3D column type and damage state, the
fragility of reaching that state or a worse one (P(DS >= state | IM)), fitted as P(toppled)
is: a lognormal fit per intensity measure with its binned fractions (Wilson intervals:
the Monte Carlo error) and the logistic surface in PGA and PGV/PGA.  The states are those
of :class:`pipeline.outcome.damage.DamageState` above ``none`` (docs/damage.md); in a fit
of a state, ``toppled`` counts the runs that reached it.

    "damage_states": {"drums": {"description": str, "runs": n,
                                "states": {"slight": {"runs", "reached", "PGA": fit,
                                                      "PGV": fit, "PGV/PGA": fit,
                                                      "logistic": surface}, ...}}}
"""
from dataclasses import dataclass, field

from pipeline.files import InputError
from pipeline.hazard.fragility.checker import MAX_TOTAL, Checker, key_text, leaf
from pipeline.hazard.fragility.fits import LognormalFit, LogisticSurface

STATES = ("slight", "moderate", "severe", "collapse")   # mildest first; "none" has no curve
IMS = ("PGA", "PGV", "PGV/PGA")


@dataclass(frozen=True, kw_only=True)
class StateFits:
    """One damage state of one column type: of ``runs`` runs (those with damage
    measures), ``reached`` reached the state or a worse one; ``fits`` (intensity measure
    -> :class:`LognormalFit`) and ``logistic`` (:class:`LogisticSurface` or None)."""
    state: str
    runs: int
    reached: int
    fits: dict = field(default_factory=dict)
    logistic: LogisticSurface = None

    def __post_init__(self):
        c = Checker("")
        if self.state not in STATES:
            c.fail("state", f"must be one of {', '.join(STATES)}, got {self.state!r}")
        runs = c.integer(self.runs, "runs", 0, MAX_TOTAL)
        c.integer(self.reached, "reached", 0, runs)
        for im, fit in self.fits.items():
            if im not in IMS or not isinstance(fit, LognormalFit):
                c.fail(key_text(im), "must be a lognormal fit of PGA, "
                       "PGV or PGV/PGA")
            if (fit.n or 0) > runs or (fit.toppled or 0) > self.reached:
                c.fail(key_text(im), f"counts {fit.toppled} of {fit.n} runs, more than "
                       f"the state's {self.reached} of {runs}")
        if self.logistic is not None and not isinstance(self.logistic, LogisticSurface):
            c.fail("logistic", "must be a logistic surface")

    @property
    def fraction(self):
        """The fraction of runs that reached the state (None without runs)."""
        return self.reached / self.runs if self.runs else None

    def to_json(self):
        return {"runs": self.runs, "reached": self.reached,
                **{im: fit.to_json() for im, fit in self.fits.items()},
                "logistic": None if self.logistic is None else self.logistic.to_json()}

    @classmethod
    def of(cls, state, data, name, where):
        """The fits of ``state`` from the dict the file holds at key path ``where``."""
        if not isinstance(data, dict):
            raise InputError(f"{name}: {where} must be an object")
        fits = {im: leaf(LognormalFit, data[im], name, f"{where}.{key_text(im)}")
                for im in IMS if im in data}
        unknown = set(data) - set(IMS) - {"runs", "reached", "logistic"}
        if unknown:
            raise InputError(f"{name}: {where} holds unknown keys "
                             f"{', '.join(sorted(unknown))}")
        logistic = data.get("logistic")
        try:
            return cls(state=state, runs=data.get("runs"), reached=data.get("reached"),
                       fits=fits, logistic=None if logistic is None else
                       leaf(LogisticSurface, logistic, name, f"{where}.logistic"))
        except InputError as exc:
            raise InputError(f"{name}: {where}.{exc}") from None


@dataclass(frozen=True, kw_only=True)
class ColumnStates:
    """The damage-state fragilities of one column type: its ``description``, ``runs``
    (with damage measures) and ``states`` (a :class:`StateFits` per state, mildest
    first, each at most once; a worse state reached by no more runs than a milder one)."""
    description: str
    runs: int
    states: tuple

    def __post_init__(self):
        c = Checker("")
        c.text(self.description, "description")
        c.integer(self.runs, "runs", 0, MAX_TOTAL)
        names = [s.state for s in self.states]
        if names != [s for s in STATES if s in names]:
            c.fail("states", f"must be given once each, mildest first, got {names}")
        for s in self.states:
            if s.runs != self.runs:
                c.fail(f"states.{s.state}.runs", f"{s.runs}, the column's {self.runs}")
        reached = [s.reached for s in self.states]
        if any(b > a for a, b in zip(reached, reached[1:])):
            c.fail("states", f"reached {reached}: a worse state by more runs than a milder")

    def state(self, name):
        """The :class:`StateFits` of state ``name`` (KeyError when not fitted)."""
        for s in self.states:
            if s.state == name:
                return s
        raise KeyError(name)

    def to_json(self):
        return {"description": self.description, "runs": self.runs,
                "states": {s.state: s.to_json() for s in self.states}}

    @classmethod
    def of(cls, data, name, where):
        if not isinstance(data, dict) or not isinstance(data.get("states"), dict):
            raise InputError(f"{name}: {where} must be an object with 'states'")
        states = tuple(StateFits.of(k, v, name, f"{where}.states.{key_text(k)}")
                       for k, v in data["states"].items())
        try:
            return cls(description=data.get("description"), runs=data.get("runs"),
                       states=states)
        except InputError as exc:
            raise InputError(f"{name}: {where}.{exc}") from None


def damage_states_of(value, name):
    """``damage_states`` of the file ``name``: column type -> :class:`ColumnStates`."""
    if value is None:
        return None
    if not isinstance(value, dict):
        raise InputError(f"{name}: damage_states must be an object")
    return {k: ColumnStates.of(v, name, f"damage_states.{key_text(k)}")
            for k, v in value.items()}


def damage_states_json(value):
    return None if value is None else {k: v.to_json() for k, v in value.items()}
