"""A column's fragility per damage state: P(DS >= s | PGA[, PGV/PGA]) for the states of
docs/damage.md, and the probability that a column ends in a range of states.

The states, in order, are those of :class:`pipeline.outcome.damage.DamageState` (a test
checks that they agree): none, slight, moderate, severe, collapse (the column fell).
P(DS >= none) = 1; P(DS >= collapse) is P(topple), the fragility of the toppling
campaigns.  Fragilities fitted state by state may cross (a lognormal of a wider beta
runs above a higher state's at small PGA): P(DS >= s) is taken as the largest of the
given P(DS >= k) for k >= s, so that no state's probability is negative.
"""
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError

STATES = ("none", "slight", "moderate", "severe", "collapse")
COLLAPSE = len(STATES) - 1


def state_index(name, where="damage state"):
    """The index (0 none ... 4 collapse) of a state's name; InputError (one line)."""
    if name not in STATES:
        raise InputError(f"{where}: {name!r} is no damage state (one of "
                         f"{', '.join(STATES)})")
    return STATES.index(name)


@dataclass(frozen=True)
class StateFragility:
    """``exceedance``: per state slight, moderate, severe, collapse (in that order) a
    fragility of P(DS >= s) (an object with ``probability(pga[, pgv_pga])``,
    ``uses_ratio`` and ``describe()``: :mod:`pipeline.hazard.fragility`), or None where
    it is not known; collapse (P(topple)) is always given.  ``source``: where the states
    below collapse come from, in words (None: not said)."""
    exceedance: tuple
    source: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "exceedance", tuple(self.exceedance))
        if len(self.exceedance) != COLLAPSE:
            raise InputError(f"a fragility per damage state needs {COLLAPSE} entries "
                             f"({', '.join(STATES[1:])}), got {len(self.exceedance)}")
        if self.exceedance[-1] is None:
            raise InputError("a fragility per damage state needs the collapse one, "
                             "P(topple)")

    @classmethod
    def toppling(cls, fragility):
        """P(topple) alone: the lower states not known."""
        return cls((None,) * (COLLAPSE - 1) + (fragility,))

    @property
    def uses_ratio(self):
        return any(f is not None and f.uses_ratio for f in self.exceedance)

    def given(self, state):
        """Whether P(DS >= ``state``) is known (always for none)."""
        return state == 0 or self.exceedance[state - 1] is not None

    def missing(self, lowest, highest):
        """The states whose P(DS >= s) P(lowest <= DS <= highest) needs and that are not
        given (indices)."""
        return [s for s in (lowest, highest + 1) if s <= COLLAPSE and not self.given(s)]

    def at_least(self, state, pga_m_s2, pgv_pga_s=None):
        """P(DS >= ``state``) at PGA levels (m/s^2): 1 for none, else the largest given
        P(DS >= k), k >= state (module docstring)."""
        pga = np.asarray(pga_m_s2, float)
        if state == 0:
            return np.ones(pga.shape)
        if not self.given(state):
            raise InputError(f"no fragility for damage state {STATES[state]!r}")
        out = np.zeros(pga.shape)
        for fragility in self.exceedance[state - 1:]:
            if fragility is not None:
                p = fragility.probability(pga, pgv_pga_s) if fragility.uses_ratio else \
                    fragility.probability(pga)
                out = np.maximum(out, p)
        return out

    def probability(self, lowest, highest, pga_m_s2, pgv_pga_s=None):
        """P(``lowest`` <= DS <= ``highest``) at PGA levels (m/s^2): P(DS >= lowest) -
        P(DS >= highest + 1)."""
        low = self.at_least(lowest, pga_m_s2, pgv_pga_s)
        if highest >= COLLAPSE:
            return low
        return np.maximum(low - self.at_least(highest + 1, pga_m_s2, pgv_pga_s), 0.0)

    @property
    def collapse(self):
        """P(topple): the fragility of collapse."""
        return self.exceedance[-1]

    def describe_states(self):
        """The given fragilities of the states below collapse, by name (as their
        ``describe()`` gives them)."""
        return {name: f.describe() for name, f in zip(STATES[1:-1], self.exceedance[:-1])
                if f is not None}
