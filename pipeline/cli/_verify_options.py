"""The ``verify`` command's options, one class a test, declared as
:func:`~pipeline.scenario.parameters.param` fields (the command builds each test's flags
from its class); checked on creation, before any integration or YADE run.  The ranges are
the model's (:class:`~pipeline.scenario.parameters.Block`,
:class:`~pipeline.scenario.parameters.Contact`) and the checks' (:mod:`pipeline.verification`);
the classes live here, not beside the checks, whose code is hashed into the verification
runs' ids."""
import dataclasses
import math
from dataclasses import dataclass

from pipeline import paper
from pipeline.cli._fields import several
from pipeline.rocking.frame import MAX_BEAM_MASS_RATIO
from pipeline.scenario.parameters import MU_K_OVER_MU_S, Block, Contact, check_fields, param
from pipeline.verification import MARBLE_BLOCK, PULSE_BLOCK, SLIDING_BELOW, SLIDING_MU
from pipeline.verification.checks import HOUSNER_DAMPING, MAX_AMPLITUDE_RATIO, MAX_IMPACTS, \
    MAX_OMEGA_RATIO
from pipeline.verification.one_cosine import MAX_RUNS, MR_BLOCK, MR_PERIOD_S, PERIOD_RANGE_S, \
    YADE_RUNS


def _declared(cls, name):
    """The metadata of field ``name`` of parameter dataclass ``cls``."""
    return next(f.metadata for f in dataclasses.fields(cls) if f.name == name)


def _block(name, block):
    """The test block's size ``name`` (m), its default ``block[name]``, its range Block's."""
    meta = _declared(Block, name)
    return param(block[name], "m", meta["help"], meta["low"], meta["high"], f"--{name}")


def _kn(unset):
    meta = _declared(Contact, "kn")
    return param(None, "N/m", "contact stiffness per rim contact point", meta["low"],
                 meta["high"], "--kn", optional=unset)


def _damping(unset):
    meta = _declared(Contact, "damping")
    return param(None, "", "contact damping ratio (1 = critical)", meta["low"], meta["high"],
                 "--damping", optional=unset)


def _period():
    return param(MR_PERIOD_S, "s", "pulse period T_p", *PERIOD_RANGE_S, "--period")


def _runs():
    return param(YADE_RUNS, "", "YADE runs of the bisection", 3, MAX_RUNS, "--runs")


MARBLE_KN = f"{paper.MARBLE_BLOCK_KN_N_M:g}, the marble block's"
CRITICAL = f"{HOUSNER_DAMPING:g}, critical: Housner's restitution"
PAPER_KN, PAPER_DAMPING = f"{paper.COLUMN_KN_N_M:g}", f"{paper.DAMPING_RATIO:g}, the paper's"
# the sliding test's tilt: the test block's range (Block.theta0_rad) in degrees
THETA0_DEG = tuple(math.degrees(_declared(Block, "theta0_rad")[k]) for k in ("low", "high"))


class _Checked:
    """Options checked against their declarations on creation."""

    def __post_init__(self):
        check_fields(self)


def _sized(block):
    """A base of the options of a test of a block: its three sizes (m), their defaults
    ``block``'s, their ranges Block's."""
    return dataclasses.make_dataclass(
        "_Block", [(k, float, _block(k, block)) for k in ("height", "width", "depth")],
        bases=(_Checked,), frozen=True)


_Marble, _Pulse, _MakrisRoussos = _sized(MARBLE_BLOCK), _sized(PULSE_BLOCK), _sized(MR_BLOCK)


@dataclass(frozen=True)
class HousnerOptions(_Marble):
    """Free rocking of a block released from a tilt (Housner 1963)."""
    theta0_ratio: float = param(0.5, "", "initial tilt over the critical angle, theta0 / alpha",
                                0.0, 1.0, "--theta0-ratio", low_open=True, high_open=True)
    impacts: int = param(5, "", "impacts compared", 1, MAX_IMPACTS, "--impacts")
    kn: float = _kn(MARBLE_KN)
    damping: float = _damping(CRITICAL)


@dataclass(frozen=True)
class SinePulseOptions(_Pulse):
    """A block under a one-sine pulse (Zhang & Makris 2000)."""
    amplitude_ratio: float = param(None, "", "pulse amplitude over alpha g, A / (alpha g)", 0.0,
                                   MAX_AMPLITUDE_RATIO, "--amplitude-ratio", low_open=True,
                                   required=True)
    omega_ratio: float = param(5.0, "", "pulse frequency over the block's, omega / p", 0.0,
                               MAX_OMEGA_RATIO, "--omega-ratio", low_open=True)
    kn: float = _kn(PAPER_KN)
    damping: float = _damping(PAPER_DAMPING)


@dataclass(frozen=True)
class SlidingOptions(_Checked):
    """The marble block rocking from a tilt at several static friction coefficients."""
    mu_s: tuple[float, ...] = several(param(
        (), "", f"static friction values, one at least at or below {SLIDING_BELOW:g} x the "
        "Augusti & Sinopoli limit", *(_declared(Contact, "mu_s")[k] for k in ("low", "high")),
        "--mu-s", metavar="MU", optional=f"{max(SLIDING_MU):g} down to {min(SLIDING_MU):g}"))
    theta0_deg: float = param(10.0, "deg", "initial tilt (+ leans East)", *THETA0_DEG,
                              "--theta0-deg")
    friction: str = param("switch", "", f"switch: mu_s sticking, mu_k = {MU_K_OVER_MU_S:.3g} "
                          "mu_s sliding; static: mu_s only, to see the effect of the kinetic "
                          "coefficient", flag="--friction", choices=("switch", "static"))
    kn: float = _kn(MARBLE_KN)
    damping: float = _damping(PAPER_DAMPING)


@dataclass(frozen=True)
class OneCosineOptions(_MakrisRoussos):
    """The smallest overturning amplitude under a one-cosine pulse (Makris & Roussos 2000)."""
    period: float = _period()
    runs: int = _runs()
    kn: float = _kn(PAPER_KN)
    damping: float = _damping(CRITICAL)


@dataclass(frozen=True)
class FrameOptions(_Checked):
    """The smallest overturning amplitude of columns under a beam (Makris & Vassiliou 2013)."""
    columns: int = param(2, "", "columns under the beam", 2, None, "--columns")
    gamma: float = param(1.0, "", "beam mass over the columns' mass", 0.0, MAX_BEAM_MASS_RATIO,
                         "--gamma")
    period: float = _period()
    runs: int = _runs()
    kn: float = _kn(f"{paper.COLUMN_KN_N_M:g} x (1 + 3 gamma): the frame rocks on its "
                    "contacts at the single column's frequency")
    damping: float = _damping(CRITICAL)


OPTIONS = {"housner": HousnerOptions, "sine-pulse": SinePulseOptions,
           "sliding": SlidingOptions, "one-cosine": OneCosineOptions, "frame": FrameOptions}
