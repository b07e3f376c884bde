"""The joint hazard of PGA and PGV at sites (:class:`JointHazard`) and its one loader
(:func:`load_joint_hazard`): OpenQuake's mean rate density, the dataset ``mrd`` that the
engine's post-processor ``compute_mrd.main`` writes into a classical calculation's HDF5
datastore (engine 3.17 and later; the manual's "Vector-valued PSHA calculations").

What the loader reads (h5py), from the engine's datastore or an extract with the same
names (``records/tools/oq_mrd_extract.py``):

- ``mrd``: (L-1) x (L-1) x N annual rates, one per cell between consecutive levels of the
  two intensity measures and per site; axis 0 the second IMT (``imt2``), axis 1 the first,
  as ``openquake.hazardlib.calc.mrd`` fills it.  The engine writes the mean over its
  realisations only;
- ``mrd-rlzs`` where a file holds it (the engine 3.26 writes none; an extract may): the
  same per realisation, (L-1) x (L-1) x N x R, realisation r that of ``rlz_id`` r;
- ``oqparam`` (JSON): ``hazard_imtls`` (the levels, PGA in g and PGV in cm/s),
  ``investigation_time`` (years) and ``postproc_args`` (``imt1``, ``imt2``);
- ``sitecol/lon`` and ``sitecol/lat`` (degrees).

Checks (a one-line InputError each): not a regular HDF5 file, no ``mrd``, no or unreadable
``oqparam``, a rate density of other intensity measures than PGA and PGV, levels whose
count does not match the ``mrd``'s shape or that do not increase, sites that do not match,
rates negative or not finite, a site index beyond the file.  Units out: PGA in m/s^2, PGV
in m/s, rates in 1/yr.
"""
import json
import math
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError

PGV_CM_S_TO_M_S = 0.01        # the engine's PGV unit, cm/s
REQUIRED_IMTS = ("PGA", "PGV")


@dataclass(frozen=True)
class JointHazard:
    """PGA and PGV together at ``sites`` ((lon, lat) in degrees): ``cell_rates_per_yr[s,
    i, j]`` the annual rate (1/yr) of events whose PGA falls in [``pga_levels_m_s2[i]``,
    ``pga_levels_m_s2[i+1]``) and PGV in [``pgv_levels_m_s[j]``, ``pgv_levels_m_s[j+1]``)
    at site ``s`` (the engine's "mean rate density", a rate per cell).  Nothing below the
    first levels or above the last is held.  ``investigation_time_yr``: the calculation's;
    ``source``: where it comes from (dict); ``realisation_rates_per_yr[r, s, i, j]``: the
    same per realisation r, or None (the file holds the mean's only)."""
    pga_levels_m_s2: np.ndarray
    pgv_levels_m_s: np.ndarray
    cell_rates_per_yr: np.ndarray
    investigation_time_yr: float
    sites: tuple
    source: dict = field(default_factory=dict, compare=False)
    realisation_rates_per_yr: np.ndarray | None = field(default=None, compare=False)

    def __post_init__(self):
        where = self.source.get("file", "joint hazard")
        for name, levels, unit in (("PGA", self.pga_levels_m_s2, "m/s^2"),
                                   ("PGV", self.pgv_levels_m_s, "m/s")):
            if levels.ndim != 1 or levels.size < 2:
                raise InputError(f"{where}: {name} needs at least 2 levels, got "
                                 f"{levels.size}")
            if not (np.all(np.isfinite(levels)) and np.all(levels > 0)):
                raise InputError(f"{where}: {name} levels must be positive numbers ({unit})")
            if np.any(np.diff(levels) <= 0):
                raise InputError(f"{where}: {name} levels do not increase")
        expected = (len(self.sites), self.pga_levels_m_s2.size - 1,
                    self.pgv_levels_m_s.size - 1)
        _check_rates(where, "the rates", self.cell_rates_per_yr, expected)
        if self.realisation_rates_per_yr is not None:
            rlz = self.realisation_rates_per_yr
            _check_rates(where, "the realisations' rates", rlz, (rlz.shape[0], *expected))
        if not (math.isfinite(self.investigation_time_yr) and self.investigation_time_yr > 0):
            raise InputError(f"{where}: investigation time {self.investigation_time_yr!r} "
                             "is not a positive number of years")
        for lon, lat in self.sites:
            if not (abs(lon) <= 360.0 and abs(lat) <= 90.0):
                raise InputError(f"{where}: site ({lon}, {lat}) is not a coordinate")

    def site(self, index):
        """The joint hazard at site ``index`` (0-based) alone."""
        n = len(self.sites)
        if not (isinstance(index, int | np.integer) and 0 <= index < n):
            raise InputError(f"{self.source.get('file', 'joint hazard')}: site {index} "
                             f"beyond the file's {n} site(s) (0 to {n - 1})")
        rlz = self.realisation_rates_per_yr
        return JointHazard(self.pga_levels_m_s2, self.pgv_levels_m_s,
                           self.cell_rates_per_yr[index:index + 1],
                           self.investigation_time_yr, (self.sites[index],),
                           {**self.source, "site_index": int(index)},
                           None if rlz is None else rlz[:, index:index + 1])

    @property
    def realisations(self):
        """How many realisations the file holds a rate density of (0: the mean's only)."""
        rlz = self.realisation_rates_per_yr
        return 0 if rlz is None else rlz.shape[0]

    def pga_interval_rates(self):
        """Summed over PGV: sites x PGA cells, the annual rate (1/yr) of PGA falling in
        each interval between consecutive levels (what the PGA curve gives as
        lambda(x_i) - lambda(x_i+1), less what falls outside the PGV levels)."""
        return self.cell_rates_per_yr.sum(axis=2)


def _check_rates(where, what, rates, expected):
    """InputError unless ``rates`` has the shape ``expected`` and holds finite rates >= 0."""
    if rates.shape != expected:
        raise InputError(f"{where}: {what} are {rates.shape} ([realisations x] sites x PGA "
                         f"cells x PGV cells); the levels and sites make {expected}")
    if not np.all(np.isfinite(rates)):
        raise InputError(f"{where}: a rate that is not a finite number")
    if np.any(rates < 0):
        raise InputError(f"{where}: a negative rate ({rates.min():.3g} /yr)")


def load_joint_hazard(path):
    """The :class:`JointHazard` of the HDF5 file ``path`` (an OpenQuake datastore holding
    ``mrd`` or its extract; see the module)."""
    path = Path(path)
    _regular_file(path)
    try:
        with h5py.File(path, "r") as f:
            return _read(path, f)
    except OSError as exc:
        raise InputError(f"{path}: not an HDF5 file ({exc})") from None


def _regular_file(path):
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise InputError(f"joint hazard file not found: {path}") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"joint hazard file {path}: not a regular file")


def _read(path, f):
    if not isinstance(f.get("mrd"), h5py.Dataset):
        raise InputError(f"{path}: no dataset 'mrd' (run the calculation with "
                         "postproc_func = compute_mrd.main)")
    params = _oqparam(path, f)
    args = params.get("postproc_args")
    args = args if isinstance(args, dict) else {}
    imts = (args.get("imt1"), args.get("imt2"))
    if sorted(map(str, imts)) != sorted(REQUIRED_IMTS):
        raise InputError(f"{path}: the mrd is of {imts[0]} and {imts[1]}; the joint hazard "
                         "needs PGA and PGV")
    imtls = params.get("hazard_imtls") or {}
    levels = {}
    for imt in REQUIRED_IMTS:
        try:
            levels[imt] = np.asarray(imtls[imt], float)
        except (KeyError, TypeError, ValueError):
            raise InputError(f"{path}: no levels of {imt} in oqparam") from None
    try:
        mrd = np.asarray(f["mrd"][()], float)
    except (TypeError, ValueError):
        raise InputError(f"{path}: mrd does not hold numbers") from None
    if mrd.ndim != 3:
        raise InputError(f"{path}: mrd has {mrd.ndim} dimensions, not 3 (levels x levels "
                         "x sites)")
    wanted = (levels[imts[1]].size - 1, levels[imts[0]].size - 1)
    if mrd.shape[:2] != wanted:
        raise InputError(f"{path}: mrd is {mrd.shape[0]} x {mrd.shape[1]} cells; the levels "
                         f"of {imts[1]} and {imts[0]} make {wanted[0]} x {wanted[1]}")
    sites = _sites(path, f)
    if len(sites) != mrd.shape[2]:
        raise InputError(f"{path}: mrd holds {mrd.shape[2]} site(s), sitecol "
                         f"{len(sites)}")
    rates = _pga_first(mrd, imts)
    rlz = _realisations(path, f, mrd.shape, imts)
    time = params.get("investigation_time")
    source = {"format": "OpenQuake mean rate density (mrd)", "file": str(path),
              "engine_version": _attr(f, "engine_version"),
              "cross_correlation": args.get("cross_correlation"),
              "method": args.get("method"), "kind": "mean over the realisations"}
    return JointHazard(levels["PGA"] * STANDARD_GRAVITY, levels["PGV"] * PGV_CM_S_TO_M_S,
                       rates, float(time) if isinstance(time, int | float) else math.nan,
                       sites, source, rlz)


def _pga_first(mrd, imts):
    """imt2 x imt1 x sites [x realisations] as [realisations x] sites x PGA x PGV."""
    rates = np.moveaxis(mrd, 2, 0) if mrd.ndim == 3 else np.moveaxis(mrd, (3, 2), (0, 1))
    return np.swapaxes(rates, -2, -1) if imts[0] == "PGA" else rates


def _realisations(path, f, shape, imts):
    """The rate density per realisation (``mrd-rlzs``, see the module) or None."""
    if "mrd-rlzs" not in f:
        return None
    try:
        rlz = np.asarray(f["mrd-rlzs"][()], float)
    except (TypeError, ValueError, AttributeError):
        raise InputError(f"{path}: mrd-rlzs does not hold numbers") from None
    if rlz.ndim != 4 or rlz.shape[:3] != shape or rlz.shape[3] < 1:
        raise InputError(f"{path}: mrd-rlzs is {rlz.shape}; the mrd {shape} makes "
                         f"{shape[0]} x {shape[1]} x {shape[2]} x realisations")
    return _pga_first(rlz, imts)


def _oqparam(path, f):
    if not isinstance(f.get("oqparam"), h5py.Dataset):
        raise InputError(f"{path}: no 'oqparam' (the calculation's parameters)")
    raw = f["oqparam"][()]
    try:
        params = json.loads(raw.decode() if isinstance(raw, bytes) else str(raw))
    except (ValueError, UnicodeDecodeError):
        raise InputError(f"{path}: 'oqparam' is not JSON") from None
    if not isinstance(params, dict):
        raise InputError(f"{path}: 'oqparam' is not a JSON object")
    return params


def _sites(path, f):
    try:
        lon, lat = (np.asarray(f[f"sitecol/{k}"][()], float) for k in ("lon", "lat"))
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{path}: no sitecol/lon and sitecol/lat (numbers)") from None
    if lon.shape != lat.shape or lon.ndim != 1:
        raise InputError(f"{path}: sitecol/lon and sitecol/lat differ in shape")
    return tuple((float(a), float(b)) for a, b in zip(lon, lat))


def _attr(f, key):
    value = f.attrs.get(key)
    return value.decode() if isinstance(value, bytes) else (None if value is None
                                                            else str(value))
