"""A colonnade shaken in several directions (``direction_statistics.json``, beside the
directions campaign's ``colonnades.csv``): per direction of shaking and pulse, the
probability that k of its n columns fell, k = 0..n, over the runs of that direction and
pulse, each a :class:`~pipeline.stats.colonnade_counts.Proportion` with its Wilson 95 %
interval (the Monte Carlo error of a probability from that many runs).

:class:`DirectionStatistics` is the one type: built from the table by :meth:`of`,
written by :meth:`save`, read only by :meth:`load`."""
from dataclasses import dataclass

from pipeline.files import InputError
from pipeline.stats.colonnade_counts import FallCounts, WilsonFile

FILE = "direction_statistics.json"
KEYS = ("direction", "angle_from_row_deg", "azimuth_deg", "pga_g", "pgv_pga_s")


@dataclass(frozen=True, kw_only=True)
class PulseFalls(FallCounts):
    """The runs of one ``direction`` (its angle from the row and its azimuth, deg
    clockwise from North) and pulse (PGA, g; PGV/PGA, s): ``fallen`` the runs in which
    k of the ``columns`` columns fell, k = 0..columns, a Proportion of ``runs`` each."""
    direction: str
    angle_from_row_deg: float
    azimuth_deg: float
    pga_g: float
    pgv_pga_s: float

    def __post_init__(self):
        where = self.where()
        if not isinstance(self.direction, str) or not self.direction:
            raise InputError(f"{where}: direction must be named")
        for key, low, high in (("angle_from_row_deg", 0.0, 180.0), ("azimuth_deg", 0.0, 360.0),
                               ("pga_g", 0.0, None), ("pgv_pga_s", 0.0, None)):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not low <= value or (high is not None and not value <= high) or \
                    (key == "azimuth_deg" and value == high):
                raise InputError(f"{where}: {key} {value!r} outside its range "
                                 f"[{low:g}, {high if high is not None else 'inf'}]")
        super().__post_init__()

    def where(self):
        return f"{self.direction}, {self.pga_g} g, {self.pgv_pga_s} s"

    def to_json(self):
        return {**{k: getattr(self, k) for k in KEYS}, **self.counts_json()}

    @classmethod
    def own_from_json(cls, data):
        return {k: data.get(k) for k in KEYS}


@dataclass(frozen=True)
class DirectionStatistics(WilsonFile):
    """``cases``: a :class:`PulseFalls` per direction and pulse of the ``colonnade``."""
    FILE, ITEMS, ITEM = FILE, "cases", PulseFalls
    colonnade: str
    cases: tuple

    def __post_init__(self):
        object.__setattr__(self, "cases", tuple(self.cases))
        if not all(isinstance(c, PulseFalls) for c in self.cases):
            raise InputError("direction statistics: cases must be PulseFalls")
        keys = [(c.direction, c.pga_g, c.pgv_pga_s) for c in self.cases]
        if len(set(keys)) != len(keys):
            raise InputError("direction statistics: a direction and pulse given twice")

    @classmethod
    def of(cls, table):
        """The statistics of ``table``, rows as the directions campaign's colonnades.csv
        holds them (one colonnade: colonnade, direction, angle_from_row_deg, azimuth_deg,
        pga_g, pgv_pga_s, columns, columns_fallen), in the order of first appearance."""
        names = set(table["colonnade"])
        if len(names) != 1:
            raise InputError(f"colonnades.csv: one colonnade expected, got {sorted(names)}")
        cases = [PulseFalls.counted(rows, key[0], **{
                     k: (str(v) if k == "direction" else float(v)) for k, v in zip(KEYS, key)})
                 for key, rows in table.groupby(list(KEYS), sort=False)]
        return cls(str(names.pop()), tuple(cases))

    def head_json(self):
        return {"colonnade": self.colonnade}

    @classmethod
    def from_items(cls, items, data):
        return cls(str(data.get("colonnade")), items)
