"""What each campaign of this package notes on its runs beside the run's inputs: one frozen
dataclass per kind of run, read by attribute (``spec.tags.member``); none enters a run id
(:class:`~pipeline.campaign.spec.RunSpec`).  A member number -1 is the nominal run."""
from dataclasses import dataclass


@dataclass(frozen=True)
class ConvergenceTags:
    """A convergence run: the numerical ``variant`` and its ensemble ``member``."""
    variant: str
    member: int
    seed: int


@dataclass(frozen=True)
class EnsembleTags:
    """An ensemble run: its ``member`` (-1 nominal) and the sampling ``seed``."""
    member: int
    seed: int


@dataclass(frozen=True)
class LevelTags:
    """A fragility run of a record scaled to a level (m/s^2) of ``levels``; ``azimuths``:
    directions of the 2D block over 180 deg."""
    level_m_s2: float
    level_index: int
    member: int
    scale: float
    seed: int
    azimuths: int
    levels: list


@dataclass(frozen=True)
class PulseTags:
    """A pulse-grid run: its ``cell`` (i, j) of PGA (g) and PGV/PGA (s), parameter set
    ``member`` and its ``point`` (the set's values), ``heading`` and its azimuth (deg); the
    grid's options (``pulses``, ``ranges``, ``azimuth``, ``headings``, ``members``) and
    whether the run belongs to an ``adaptive`` sampling."""
    cell: tuple
    pga_g: float
    pgv_pga_s: float
    member: int
    heading: int
    azimuth_deg: float
    point: dict
    seed: int
    pulses: object
    ranges: object
    azimuth: object
    headings: int
    members: int
    adaptive: bool = False


@dataclass(frozen=True)
class ShakeTableTags:
    """A shake-table run of the calibration grid or the validation: the experiment
    ``test``, whether it ``observed`` an overturn, the ``stage``, the parameter ``point``
    and its label ``grid_point``."""
    test: str
    observed: bool
    stage: str
    grid_point: str
    point: dict


@dataclass(frozen=True)
class ShakeMemberTags:
    """A shake-table run of the members stage: the experiment ``test``, whether it
    ``observed`` an overturn, the parameter set ``member`` (-1 the single calibrated set)
    and its ``point``."""
    test: str
    observed: bool
    stage: str
    member: int
    point: dict


@dataclass(frozen=True)
class ColumnsTags:
    """A run of the columns campaign: the name of the column ``description`` it runs."""
    description: str
