"""The hazard as ``survival.json`` and ``constrain.json`` describe it (their ``hazard``):
the loader's ``source`` (format, file and the keys of that format, written first) and what
the result used of it: a hazard curve's levels and rates (:class:`CurveHazard`), the joint
hazard's levels at one site (:class:`JointHazardDescribed`) or a logic tree's integration
(:class:`TreeHazard`).  PGA in m/s^2 or g, PGV in m/s, rates in 1/yr, as named."""
from dataclasses import dataclass, fields

from pipeline.files import InputError
from pipeline.hazard.record import Record, as_json


@dataclass(frozen=True, kw_only=True)
class _Described(Record):
    """A hazard described: ``source`` (the loader's description, its keys those of the
    file's format, ``format`` and ``file`` among them; empty for a hazard made in code)
    and the fields of the use, written after it (a key of both is refused)."""
    source: dict
    NAME = "hazard"

    def __post_init__(self):
        if not isinstance(self.source, dict):
            raise ValueError("the source is not an object")
        for key in ("format", "file"):
            if not isinstance(self.source.get(key, ""), str):
                raise ValueError(f"the source's {key} is not a string")
        both = sorted(set(self.source) & set(self._own()))
        if both:
            raise ValueError(f"the source and the description both hold {', '.join(both)}")

    @classmethod
    def _own(cls):
        return [f.name for f in fields(cls) if f.name != "source"]

    @property
    def file(self) -> str | None:
        """The file the hazard was read from (None: made in code)."""
        return self.source.get("file")

    @property
    def format(self) -> str | None:
        """The file's format, in words (None: made in code)."""
        return self.source.get("format")

    def as_json(self) -> dict:
        """The source's keys, then the fields of the use in their order."""
        return {**self.source, **{k: as_json(getattr(self, k)) for k in self._own()}}

    @classmethod
    def from_json(cls, data):
        """The description of the JSON object ``data``: the keys of the use named, every
        other key the source's."""
        if not isinstance(data, dict):
            raise InputError(f"{cls.NAME}: not a JSON object")
        own = cls._own()
        return super().from_json({"source": {k: v for k, v in data.items() if k not in own},
                                  **{k: v for k, v in data.items() if k in own}})


@dataclass(frozen=True, kw_only=True)
class CurveHazard(_Described):
    """A hazard curve as survival used it: its levels (m/s^2 and g), annual rates, the
    loader's notes and the interpolation."""
    levels_m_s2: list
    levels_g: list
    rates_per_yr: list
    notes: list
    interpolation: str

    def __post_init__(self):
        super().__post_init__()
        if not len(self.levels_m_s2) == len(self.levels_g) == len(self.rates_per_yr):
            raise ValueError(f"{len(self.levels_m_s2)} levels, {len(self.levels_g)} in g, "
                             f"{len(self.rates_per_yr)} rates")


@dataclass(frozen=True, kw_only=True)
class JointHazardDescribed(_Described):
    """The joint hazard of PGA and PGV at one site: the site, the levels of both, the
    investigation time (yr) and the annual rate of events in its cells."""
    site: list
    pga_levels_m_s2: list
    pgv_levels_m_s: list
    investigation_time_yr: float
    events_per_yr: float


@dataclass(frozen=True, kw_only=True)
class TreeHazard(_Described):
    """A logic tree as constrain integrated it: the loader's notes, the interpolation and
    the cells per level interval."""
    notes: list
    interpolation: str
    cells_per_interval: int


def read_survival_hazard(data):
    """survival.json's ``hazard``: the joint route's (it holds ``pga_levels_m_s2``) or a
    hazard curve's."""
    joint = isinstance(data, dict) and "pga_levels_m_s2" in data
    return (JointHazardDescribed if joint else CurveHazard).from_json(data)
