"""What the two statistics files of a colonnade's runs share (``colonnade_statistics.json``
per record or direction, ``direction_statistics.json`` per direction and pulse): a count
of runs as a :class:`Proportion` with its Wilson 95 % interval (the Monte Carlo error of
a probability from that many runs), the runs in which k of the colonnade's n columns
fell, k = 0..n, as :class:`FallCounts` (counted from colonnades.csv's rows, checked,
written and read here only), and a file of them as :class:`WilsonFile` (its header, its
writer, the check of its top level on reading)."""
from dataclasses import dataclass
from pathlib import Path

from pipeline.files import InputError, read_run_json, write_json
from pipeline.stats.ensemble import wilson_interval

CONFIDENCE = 0.95
INTERVAL = "Wilson score"
_TOLERANCE = 1e-9            # a stated probability or interval bound against its counts


@dataclass(frozen=True)
class Proportion:
    """``count`` runs of ``of``: the fraction (None without runs) and its Wilson 95 %
    interval ([0, 1] without runs)."""
    count: int
    of: int

    def __post_init__(self):
        for key in ("count", "of"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InputError(f"{key} must be a count, got {value!r}")
        if self.count > self.of:
            raise InputError(f"count {self.count} of {self.of}: more than there are")

    @property
    def p(self):
        return self.count / self.of if self.of else None

    @property
    def ci95(self):
        return wilson_interval(self.count, self.of, CONFIDENCE)

    def to_json(self):
        return {"count": self.count, "of": self.of, "p": self.p, "ci95": self.ci95}

    @classmethod
    def from_json(cls, data, where):
        if not isinstance(data, dict):
            raise InputError(f"{where} must be an object")
        try:
            out = cls(data.get("count"), data.get("of"))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        stated = [data.get("p"), *(data.get("ci95") or [None, None])]
        for value, own in zip(stated, [out.p, *out.ci95]):
            if (value is None) != (own is None) or (
                    own is not None and not abs(float(value) - own) <= _TOLERANCE):
                raise InputError(f"{where}: p and ci95 {stated} are not those of "
                                 f"{out.count} of {out.of}")
        return out


@dataclass(frozen=True, kw_only=True)
class FallCounts:
    """The ``runs`` of a colonnade of ``columns`` columns: ``fallen`` the runs in which k
    of its columns fell, k = 0..columns, a :class:`Proportion` of the runs each.  A base:
    a kind of it adds the fields that name its runs (:meth:`where`, :meth:`own_from_json`)
    and writes them around :meth:`counts_json`."""
    columns: int
    runs: int
    fallen: tuple

    def __post_init__(self):
        object.__setattr__(self, "fallen", tuple(self.fallen))
        where = self.where()
        for key in ("columns", "runs"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InputError(f"{where}: {key} must be a count >= 1, got {value!r}")
        if len(self.fallen) != self.columns + 1:
            raise InputError(f"{where}: {len(self.fallen)} counts of columns fallen, not "
                             f"{self.columns + 1} (0 to {self.columns})")
        if not all(isinstance(f, Proportion) and f.of == self.runs for f in self.fallen) \
                or sum(f.count for f in self.fallen) != self.runs:
            raise InputError(f"{where}: the counts of columns fallen, k = 0.."
                             f"{self.columns}, do not add up to the {self.runs} runs")

    def where(self):
        """These runs as an error names them."""
        return "colonnade runs"

    @classmethod
    def counted(cls, rows, what, **own):
        """The counts of ``rows`` (colonnades.csv's rows of one colonnade: columns,
        columns_fallen; ``what`` names them in an error) with the fields ``own``."""
        sizes = set(int(c) for c in rows["columns"])
        if len(sizes) != 1:
            raise InputError(f"colonnades.csv: {what} has {sorted(sizes)} columns in "
                             "different runs")
        n, fallen = sizes.pop(), [int(k) for k in rows["columns_fallen"]]
        return cls(columns=n, runs=len(rows),
                   fallen=[Proportion(fallen.count(k), len(rows)) for k in range(n + 1)],
                   **own)

    def counts_json(self):
        """columns, runs and fallen (k with its :class:`Proportion`) as the files hold
        them."""
        return {"columns": self.columns, "runs": self.runs,
                "fallen": [{"k": k, **f.to_json()} for k, f in enumerate(self.fallen)]}

    @classmethod
    def own_from_json(cls, data):
        """The fields a kind adds, read from its JSON object ``data``."""
        return {}

    @classmethod
    def from_json(cls, data, where):
        """One from its JSON object ``data`` (``where`` names it in an error)."""
        if not isinstance(data, dict) or not isinstance(data.get("fallen"), list):
            raise InputError(f"{where} must be an object with 'fallen'")
        fallen = data["fallen"]
        if [f.get("k") if isinstance(f, dict) else None for f in fallen] != \
                list(range(len(fallen))):
            raise InputError(f"{where}.fallen: k must run 0, 1, ... in order")
        try:
            return cls(columns=data.get("columns"), runs=data.get("runs"),
                       fallen=[Proportion.from_json(f, f"fallen[{k}]")
                               for k, f in enumerate(fallen)],
                       **cls.own_from_json(data))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None


class WilsonFile:
    """A statistics file of :class:`FallCounts`: named ``FILE``, its list of ``ITEM``
    under the key ``ITEMS`` (the attribute that holds them too); a kind gives
    ``head_json()``, its keys before the list, and ``from_items``, itself from the list
    read and the file's other keys."""
    FILE = ""
    ITEMS = ""
    ITEM = FallCounts

    def head_json(self):
        return {}

    def to_json(self):
        return {"confidence": CONFIDENCE, "interval": INTERVAL, **self.head_json(),
                self.ITEMS: [item.to_json() for item in getattr(self, self.ITEMS)]}

    def save(self, directory):
        """Write ``directory``/``FILE`` (atomically)."""
        write_json(Path(directory) / self.FILE, self.to_json())

    @classmethod
    def from_items(cls, items, data):
        raise NotImplementedError

    @classmethod
    def load(cls, path):
        """Read the file ``path`` (the file or its directory); a one-line InputError for
        a file that is not one."""
        path = Path(path)
        path = path / cls.FILE if path.is_dir() else path
        path, data = read_run_json(path, cls.FILE)
        if not isinstance(data, dict) or not isinstance(data.get(cls.ITEMS), list):
            raise InputError(f"{path}: not a {cls.FILE} (no '{cls.ITEMS}')")
        return cls.from_items(tuple(cls.ITEM.from_json(item, f"{path}: {cls.ITEMS}[{k}]")
                                    for k, item in enumerate(data[cls.ITEMS])), data)
