"""A colonnade shaken in several directions (``direction_statistics.json``, beside the
directions campaign's ``colonnades.csv``): per direction of shaking and pulse, the
probability that k of its n columns fell, k = 0..n, over the runs of that direction and
pulse, each a :class:`~pipeline.stats.colonnade.Proportion` with its Wilson 95 %
interval (the Monte Carlo error of a probability from that many runs).

:class:`DirectionStatistics` is the one type: built from the table by :meth:`of`,
written by :meth:`save`, read only by :meth:`load`."""
from dataclasses import dataclass

from pipeline.files import InputError, read_run_json, write_json
from pipeline.stats.colonnade import CONFIDENCE, Proportion

FILE = "direction_statistics.json"
KEYS = ("direction", "angle_from_row_deg", "azimuth_deg", "pga_g", "pgv_pga_s")


@dataclass(frozen=True, kw_only=True)
class PulseFalls:
    """The runs of one ``direction`` (its angle from the row and its azimuth, deg
    clockwise from North) and pulse (PGA, g; PGV/PGA, s): ``fallen`` the runs in which
    k of the ``columns`` columns fell, k = 0..columns, a Proportion of ``runs`` each."""
    direction: str
    angle_from_row_deg: float
    azimuth_deg: float
    pga_g: float
    pgv_pga_s: float
    columns: int
    runs: int
    fallen: tuple

    def __post_init__(self):
        object.__setattr__(self, "fallen", tuple(self.fallen))
        where = f"{self.direction}, {self.pga_g} g, {self.pgv_pga_s} s"
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
        for key in ("columns", "runs"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InputError(f"{where}: {key} must be a count >= 1, got {value!r}")
        if len(self.fallen) != self.columns + 1 or \
                not all(isinstance(f, Proportion) and f.of == self.runs for f in self.fallen) \
                or sum(f.count for f in self.fallen) != self.runs:
            raise InputError(f"{where}: the runs with k = 0..{self.columns} columns fallen "
                             f"must add up to the {self.runs} runs")

    def to_json(self):
        return {**{k: getattr(self, k) for k in KEYS}, "columns": self.columns,
                "runs": self.runs,
                "fallen": [{"k": k, **f.to_json()} for k, f in enumerate(self.fallen)]}

    @classmethod
    def from_json(cls, data, where):
        if not isinstance(data, dict) or not isinstance(data.get("fallen"), list):
            raise InputError(f"{where} must be an object with 'fallen'")
        fallen = data["fallen"]
        if [f.get("k") if isinstance(f, dict) else None for f in fallen] != \
                list(range(len(fallen))):
            raise InputError(f"{where}.fallen: k must run 0, 1, ... in order")
        try:
            return cls(**{k: data.get(k) for k in (*KEYS, "columns", "runs")},
                       fallen=[Proportion.from_json(f, f"fallen[{k}]")
                               for k, f in enumerate(fallen)])
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None


@dataclass(frozen=True)
class DirectionStatistics:
    """``cases``: a :class:`PulseFalls` per direction and pulse of the ``colonnade``."""
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
        cases = []
        for key, rows in table.groupby(list(KEYS), sort=False):
            counts = set(int(c) for c in rows["columns"])
            if len(counts) != 1:
                raise InputError(f"colonnades.csv: {key[0]} has {sorted(counts)} columns "
                                 "in different runs")
            n, fallen = counts.pop(), [int(k) for k in rows["columns_fallen"]]
            cases.append(PulseFalls(
                **{k: (str(v) if k == "direction" else float(v)) for k, v in zip(KEYS, key)},
                columns=n, runs=len(rows),
                fallen=[Proportion(fallen.count(k), len(rows)) for k in range(n + 1)]))
        return cls(str(names.pop()), tuple(cases))

    def to_json(self):
        return {"confidence": CONFIDENCE, "interval": "Wilson score",
                "colonnade": self.colonnade, "cases": [c.to_json() for c in self.cases]}

    def save(self, directory):
        """Write ``directory``/direction_statistics.json (atomically)."""
        write_json(directory / FILE, self.to_json())

    @classmethod
    def load(cls, path):
        """Read a direction_statistics.json (``path`` the file or its directory); a
        one-line InputError for a file that is not one."""
        path = path / FILE if path.is_dir() else path
        path, data = read_run_json(path, FILE)
        if not isinstance(data, dict) or not isinstance(data.get("cases"), list):
            raise InputError(f"{path}: not a {FILE} (no 'cases')")
        return cls(str(data.get("colonnade")),
                   tuple(PulseFalls.from_json(c, f"{path}: cases[{k}]")
                         for k, c in enumerate(data["cases"])))
