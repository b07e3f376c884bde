"""The ``records`` and ``synthetics`` commands' options, declared as
:func:`~pipeline.scenario.parameters.param` fields (the commands build their flags from
them); checked on creation, before any record is read or any motion computed.  They live
here, not beside their stages: the code of :mod:`pipeline.records` and
:mod:`pipeline.motion` is hashed into the processed motions' cache keys."""
from dataclasses import dataclass

from pipeline.motion.synthetics import AZIMUTH_STEP_DEG
from pipeline.motion.synthetics.sites import MIN_AZIMUTH_STEP_DEG
from pipeline.scenario.parameters import check_fields, param


@dataclass(frozen=True)
class RecordsOptions:
    """How records without coordinates are oriented."""
    back_azimuth: float = param(None, "deg", "back azimuth of the records whose file and "
                                "catalogue give none (coordinates or a catalogued value "
                                "win)", 0.0, 360.0, "--back-azimuth", metavar="DEG",
                                high_open=True,
                                optional="such a record's back azimuth is unknown")

    def __post_init__(self):
        check_fields(self)


@dataclass(frozen=True)
class SyntheticsOptions:
    """How densely the synthetics' rings are sampled."""
    step: float = param(AZIMUTH_STEP_DEG, "deg", "azimuth step between the sites of a ring",
                        MIN_AZIMUTH_STEP_DEG, 360.0, "--step", metavar="DEG")

    def __post_init__(self):
        check_fields(self)
