"""``--state-lognormal``: stated lognormal fragilities of the damage states below collapse
(docs/damage.md), for what a site's columns say when their damage states were seen
(``survival --observations``, docs/survival.md).  Each is ``STATE,MEDIAN_G,BETA``:
P(DS >= STATE | PGA) = Phi(ln(PGA / median) / beta); collapse is the column's fragility
of toppling (``--fragility``, ``--median-g``/``--beta`` or ``--logistic``).

Without ``--state-lognormal``, a campaign's ``fragility.json`` (``--fragility``) gives
them per column type from its ``damage_states`` fits
(:func:`pipeline.hazard.fragility.load.load_state_fragilities`), in the same
:class:`~pipeline.hazard.damage_states.StateFragility` (:func:`state_fragility`).
"""
import math

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.damage_states import COLLAPSE, STATES, StateFragility
from pipeline.hazard.fragility import Lognormal
from pipeline.hazard.fragility.kinds import BETA_RANGE, MEDIAN_G_RANGE

FLAG = "--state-lognormal"
STATED = STATES[1:COLLAPSE]             # slight, moderate, severe


def parse_state_lognormal(texts):
    """{state index: (median g, beta)} of ``--state-lognormal`` values; InputError (one
    line) for a bad one, a state given twice, or medians not rising with the state."""
    out = {}
    for text in texts:
        parts = text.split(",")
        if len(parts) != 3:
            raise InputError(f"{FLAG} {text!r}: expected STATE,MEDIAN_G,BETA")
        name = parts[0].strip()
        if name not in STATED:
            raise InputError(f"{FLAG} {text!r}: the state must be one of "
                             f"{', '.join(STATED)} (collapse is the toppling fragility)")
        try:
            median, beta = float(parts[1]), float(parts[2])
        except ValueError:
            raise InputError(f"{FLAG} {text!r}: MEDIAN_G and BETA must be numbers") from None
        for value, what, (low, high) in ((median, "median", MEDIAN_G_RANGE),
                                         (beta, "beta", BETA_RANGE)):
            if not (math.isfinite(value) and low <= value <= high):
                raise InputError(f"{FLAG} {text!r}: {what} {value:g} outside [{low:g}, "
                                 f"{high:g}]")
        index = STATES.index(name)
        if index in out:
            raise InputError(f"{FLAG}: the state {name} is given twice")
        out[index] = (median, beta)
    ordered = sorted(out.items())
    for (a, (ma, _)), (b, (mb, _)) in zip(ordered, ordered[1:]):
        if not ma < mb:
            raise InputError(f"{FLAG}: the median of {STATES[b]} ({mb:g} g) must be above "
                             f"that of {STATES[a]} ({ma:g} g): a worse state needs a "
                             "stronger motion")
    return out


STATED_SOURCE = f"stated ({FLAG})"


def state_fragility(collapse, stated):
    """The :class:`StateFragility` of a column: ``collapse`` its fragility of toppling,
    ``stated`` the lower states' lognormals ({state index: (median g, beta)})."""
    lower = tuple(None if s not in stated else Lognormal(
        stated[s][0] * STANDARD_GRAVITY, stated[s][1],
        label=f"stated lognormal of {STATES[s]}: median {stated[s][0]:g} g, beta "
              f"{stated[s][1]:g}") for s in range(1, COLLAPSE))
    return StateFragility(lower + (collapse,), STATED_SOURCE if stated else None)
