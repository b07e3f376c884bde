"""OpenQuake's disaggregation of PGA by magnitude and distance
(:class:`MagDistDisaggregation`) and its one loader (:func:`load_mag_dist`).

The engine's ``Mag_Dist`` CSV export (``Mag_Dist-mean-<site>_<calc>.csv``, and per
realisation ``Mag_Dist-<site>_<calc>.csv``): a first line starting with ``#`` stating
``investigation_time``, ``mag_bin_edges``, ``dist_bin_edges``, ``lon`` and ``lat``; the
header ``imt,iml,poe,mag,dist,<column>...`` (``mean``, or ``rlz0``, ``rlz1``, ...); one
row per PGA level (``iml``, g), magnitude bin and distance bin (``mag``, ``dist``: the
bin's centre, km) with each column's probability that an event of that bin exceeds the
level in the investigation time T.  Bin rates (1/yr) are -ln(1 - p) / T and add up.

Checks (a one-line InputError each): a missing header value, an IMT other than PGA,
unreadable numbers, a bin centre that is no bin's, a cell given twice or missing,
probabilities outside [0, 1), levels not positive, and a statistic column (``mean``) whose
bins do not add up to its level's rate, -ln(1 - poe) / T, within
:data:`BIN_SUM_TOLERANCE` (the engine computes the bins apart from the curve: up to
0.6 % apart on the shipped case, ``records/hazard/openquake_postproc_case_mrd``).  A realisation's column is
checked against that realisation's curve with :meth:`MagDistDisaggregation.check_curve`.
"""
import csv
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.userfiles import DATA_FILE_BYTES, read_user_text, show

BIN_SUM_TOLERANCE = 0.02       # relative, bins' total rate against the level's rate
STATISTICS = ("mean",)         # columns whose level is the file's poe
_FIXED = ("imt", "iml", "poe", "mag", "dist")


@dataclass(frozen=True)
class MagDistDisaggregation:
    """PGA exceedance by magnitude and distance at one site: ``bin_rates_per_yr[c, l, m,
    d]`` the annual rate (1/yr) of events of magnitude bin m and distance bin d that
    exceed PGA level l (``levels_m_s2``), for column c (``columns``: "mean", "rlz0",
    ...).  ``poes``: the file's probability of exceedance of each level in
    ``investigation_time_yr``; ``mag_edges``, ``dist_edges_km``: the bins' edges;
    ``site``: (lon, lat) in degrees; ``source``: where it comes from."""
    levels_m_s2: np.ndarray
    poes: np.ndarray
    mag_edges: np.ndarray
    dist_edges_km: np.ndarray
    columns: tuple
    bin_rates_per_yr: np.ndarray
    investigation_time_yr: float
    site: tuple
    source: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        where = self.source.get("file", "disaggregation")
        if not (math.isfinite(self.investigation_time_yr) and self.investigation_time_yr > 0):
            raise InputError(f"{where}: investigation_time must be a positive number of years")
        for name, edges in (("mag_bin_edges", self.mag_edges),
                            ("dist_bin_edges", self.dist_edges_km)):
            if edges.size < 2 or not np.all(np.isfinite(edges)) or np.any(np.diff(edges) <= 0):
                raise InputError(f"{where}: {name} must be at least 2 increasing numbers")
        levels = self.levels_m_s2
        if levels.size < 1 or not np.all(np.isfinite(levels)) or np.any(levels <= 0):
            raise InputError(f"{where}: PGA levels must be positive numbers")
        if np.any((self.poes <= 0) | (self.poes >= 1)):
            raise InputError(f"{where}: a level's poe outside (0, 1)")
        shape = (len(self.columns), levels.size, self.mag_edges.size - 1,
                 self.dist_edges_km.size - 1)
        if self.bin_rates_per_yr.shape != shape:
            raise InputError(f"{where}: bins {self.bin_rates_per_yr.shape}, expected {shape}")
        if not np.all(np.isfinite(self.bin_rates_per_yr)) or np.any(self.bin_rates_per_yr < 0):
            raise InputError(f"{where}: a bin's probability outside [0, 1)")
        for c, name in enumerate(self.columns):
            if name in STATISTICS:
                target = -np.log1p(-self.poes) / self.investigation_time_yr
                self._check_sums(c, target, "the file's poe")

    def level_rates(self):
        """Columns x levels: the annual rate (1/yr) of exceeding each level, summed over
        the bins."""
        return self.bin_rates_per_yr.sum(axis=(2, 3))

    def check_curve(self, column, curve):
        """InputError unless column ``column``'s bins add up to the rate of ``curve`` (a
        :class:`~pipeline.hazard.curves.HazardCurve` of the same realisation) at each
        level, interpolated in (ln PGA, ln rate), within :data:`BIN_SUM_TOLERANCE`."""
        self.check_rates(column, curve.levels_m_s2, curve.rates_per_yr, "the hazard curve")

    def check_rates(self, column, levels_m_s2, rates_per_yr, against):
        """:meth:`check_curve` against a curve given as its levels (m/s^2) and annual rates
        of exceedance (1/yr); ``against``: the curve in words, for the message."""
        if column not in self.columns:
            raise InputError(f"{self.source.get('file')}: no column {show(column)} (has "
                             f"{', '.join(self.columns)})")
        levels = np.asarray(levels_m_s2, float)
        inside = (self.levels_m_s2 >= levels[0]) & (self.levels_m_s2 <= levels[-1])
        if not inside.all():
            raise InputError(f"{self.source.get('file')}: a level outside the curve's "
                             f"{levels[0]:.4g}-{levels[-1]:.4g} m/s^2")
        target = np.exp(np.interp(np.log(self.levels_m_s2), np.log(levels),
                                  np.log(np.asarray(rates_per_yr, float))))
        self._check_sums(self.columns.index(column), target, against)

    def _check_sums(self, c, target, against):
        total = self.bin_rates_per_yr[c].sum(axis=(1, 2))
        for level, got, want in zip(self.levels_m_s2, total, target):
            if abs(got - want) > BIN_SUM_TOLERANCE * want:
                raise InputError(
                    f"{self.source.get('file', 'disaggregation')}: column {self.columns[c]}: "
                    f"the bins at PGA {level / STANDARD_GRAVITY:.6g} g add up to "
                    f"{got:.6g} /yr, {against} gives {want:.6g} /yr (more than "
                    f"{100 * BIN_SUM_TOLERANCE:g} % apart)")


def load_mag_dist(path):
    """The :class:`MagDistDisaggregation` of OpenQuake's ``Mag_Dist`` CSV ``path``."""
    path = Path(path)
    text = read_user_text(path, "disaggregation file", DATA_FILE_BYTES)
    lines = [line for line in text.splitlines() if line.strip()]
    if len(lines) < 3 or not lines[0].startswith("#"):
        raise InputError(f"{path}: not an OpenQuake Mag_Dist export (a '#' line, the header "
                         "imt,iml,poe,mag,dist,..., rows)")
    meta = _header(path, lines[0])
    rows = list(csv.reader(io.StringIO("\n".join(lines[1:]))))
    names = [n.strip() for n in rows[0]]
    if tuple(names[:5]) != _FIXED or len(names) < 6:
        raise InputError(f"{path}: header {show(','.join(names))}, expected "
                         f"{','.join(_FIXED)},<column>...")
    columns = tuple(names[5:])
    mag_edges, dist_edges = meta["mag_bin_edges"], meta["dist_bin_edges"]
    cells = {}
    for n, row in enumerate(rows[1:], start=1):
        if len(row) != len(names):
            raise InputError(f"{path}: data row {n} has {len(row)} values for {len(names)} "
                             "columns")
        if row[0].strip() != "PGA":
            raise InputError(f"{path}: data row {n} is of {show(row[0].strip())}; only PGA "
                             "is read")
        iml, poe, mag, dist, *values = (_number(path, n, names[k + 1], c)
                                        for k, c in enumerate(row[1:]))
        key = (iml, _bin(path, n, "mag", mag, mag_edges), _bin(path, n, "dist", dist,
                                                                dist_edges))
        if key in cells:
            raise InputError(f"{path}: data row {n} repeats PGA {iml:g} g, mag {mag:g}, "
                             f"dist {dist:g} km")
        if any(not 0 <= v < 1 for v in values):
            raise InputError(f"{path}: data row {n}: a probability outside [0, 1)")
        cells[key] = (poe, values)
    return _assemble(path, meta, columns, cells)


def _assemble(path, meta, columns, cells):
    mag_edges, dist_edges = meta["mag_bin_edges"], meta["dist_bin_edges"]
    imls = sorted({key[0] for key in cells})
    shape = (len(columns), len(imls), mag_edges.size - 1, dist_edges.size - 1)
    if len(cells) != shape[1] * shape[2] * shape[3]:
        raise InputError(f"{path}: {len(cells)} rows; {shape[1]} level(s) x {shape[2]} "
                         f"magnitude x {shape[3]} distance bins make "
                         f"{shape[1] * shape[2] * shape[3]}")
    poes = np.zeros(len(imls))
    probabilities = np.zeros(shape)
    for (iml, m, d), (poe, values) in cells.items():
        level = imls.index(iml)
        poes[level] = poe
        probabilities[:, level, m, d] = values
    time = meta["investigation_time"]
    source = {"format": "OpenQuake Mag_Dist CSV", "file": str(path),
              "generated_by": meta.get("generated_by"),
              "rate_from_poe": "annual rate = -ln(1 - p) / investigation_time (Poisson)"}
    return MagDistDisaggregation(np.asarray(imls) * STANDARD_GRAVITY, poes, mag_edges,
                                 dist_edges, columns, -np.log1p(-probabilities) / time, time,
                                 (meta["lon"], meta["lat"]), source)


def _header(path, line):
    meta = {}
    for key in ("investigation_time", "lon", "lat"):
        found = re.search(rf"\b{key}\s*=\s*([^,\"'\s\]]+)", line)
        if not found:
            raise InputError(f"{path}: no {key} in the first line")
        meta[key] = _number(path, 0, key, found.group(1))
    if not meta["investigation_time"] > 0:
        raise InputError(f"{path}: investigation_time must be a positive number of years")
    for key in ("mag_bin_edges", "dist_bin_edges"):
        found = re.search(rf"\b{key}\s*=\s*\[([^\]]*)\]", line)
        if not found:
            raise InputError(f"{path}: no {key} in the first line")
        meta[key] = np.array([_number(path, 0, key, v) for v in found.group(1).split(",")])
    found = re.search(r"generated_by\s*=\s*'([^']*)'", line)
    meta["generated_by"] = found.group(1) if found else None
    return meta


def _number(path, row, column, text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        where = "the first line" if row == 0 else f"data row {row}"
        raise InputError(f"{path}: {where}, {column}: not a number: {show(text.strip())}")
    return value


def _bin(path, row, name, centre, edges):
    """The index of the bin whose centre is ``centre``."""
    mids = 0.5 * (edges[:-1] + edges[1:])
    k = int(np.argmin(np.abs(mids - centre)))
    if abs(mids[k] - centre) > 1e-6 * max(1.0, abs(centre)):
        raise InputError(f"{path}: data row {row}: {name} {centre:g} is no bin's centre")
    return k
