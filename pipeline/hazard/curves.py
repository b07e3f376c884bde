"""The one loader of a site's hazard curve: annual rate of exceedance against PGA.

Three formats: a second line ``lon,lat...`` is OpenQuake's, a first ``{`` the USGS
web service's, anything else a plain table.

- OpenQuake's hazard-curve CSV as the engine exports it: a first line starting with
  ``#`` that states ``investigation_time`` (years) and ``imt`` (e.g. ``#,,,"generated_by=
  'OpenQuake engine 3.7.0', ..., kind='mean', investigation_time=50.0, imt='PGA'"`` or the
  older ``# ..., investigation_time=1.0, imt="PGA"``), a second line ``lon,lat[,depth],
  poe-<level>,...`` (older files ``PGA-<level>:float32``), then one row per site with the
  probability of exceedance (poe) over the investigation time T at each level (PGA in g).
  Annual rate = -ln(1 - poe) / T (Poisson).  The header's ``kind`` (mean, quantile-0.16,
  rlz-001, ...) is kept in ``source``.
- The USGS hazard web service's static-curve JSON (NSHM editions; the earthquake-hazard-tool
  response ``{"response": [{"metadata": {"imt": {"value": "PGA"}, "xlabel": "Ground Motion
  (g)", "ylabel": "Annual Frequency of Exceedence", "xvals": [...]}, "data": [{"yvals":
  [...]}]}, ...]}``): the PGA curve, annual rates as given.
- A plain table: comment lines starting with ``#`` anywhere, then the header
  ``pga_<unit>,annual_rate_per_yr`` with unit ``g``, ``m_s2`` or ``cm_s2``, then one row
  per level: PGA and the annual rate of exceeding it (1/yr).

Checks (a one-line InputError each): a file that is not a regular file (a named pipe is
refused before it is read) or is larger than 64 MB, an empty file, a missing IMT or
investigation time, an IMT other than PGA, an unknown unit, unreadable numbers, a value of
another type in the USGS JSON (metadata, imt, edition, vs30, coordinates), JSON nested too
deep, levels not in [1e-6 g, 100 g] or more than 1000 of them, negative rates or
probabilities, an infinite or NaN rate (OpenQuake's poe of 1 aside, below), a rate above
1e3 per year, levels not increasing, rates rising with the level (non-monotonic)
(:func:`check_curve`: the one check of a curve's values, the logic tree's too), fewer
than two levels with a positive rate.  Said in ``notes``, never silent: levels dropped
because their poe is 1 (an unbounded rate) and the rates of 0 at the top (the curve ends
at the last positive rate; the first level of rate 0 is kept as ``zero_rate_from_m_s2``).
"""
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.userfiles import DATA_FILE_BYTES, Unreadable, json_int, read_user_text, show

PLAIN_UNITS = {"g": STANDARD_GRAVITY, "m_s2": 1.0, "cm_s2": 0.01}    # factor to m/s^2
PLAIN_RATE_COLUMN = "annual_rate_per_yr"
OPENQUAKE_PGA_UNIT = "g"               # the engine's unit of PGA (and SA)
_IMT = r"[A-Za-z]+(?:\([0-9.]+\))?"    # PGA, PGV, SA(0.1), ...
_OQ_LEVEL = re.compile(rf"^(poe|{_IMT})-([^:]+)(?::\w+)?$")
OQ_HEADER_IMT = re.compile(rf"\bimt\s*=\s*['\"]?({_IMT})")   # imt=... in an OpenQuake header
MAX_PGA_M_S2 = 100.0 * STANDARD_GRAVITY  # the highest level a curve may state (100 g)
MIN_PGA_M_S2 = 1e-6 * STANDARD_GRAVITY   # the lowest (1e-6 g: below any felt motion)
MAX_RATE_PER_YR = 1e3                    # the highest annual rate of exceedance (1/yr)
MAX_LEVELS = 1_000                       # levels of one curve (engines give 20-50)
MAX_INVESTIGATION_YR = 1e7


@dataclass(frozen=True)
class HazardCurve:
    """A site's hazard curve: ``levels_m_s2`` (PGA, m/s^2, increasing) and
    ``rates_per_yr`` (annual rate of exceeding each level, 1/yr, positive and not
    increasing); ``source`` (dict: format, file, imt, investigation_time_yr, site, ...);
    ``notes``: what the loader dropped and why; ``zero_rate_from_m_s2``: the lowest level
    the file gives a rate of 0 (None when every level has a positive rate)."""
    levels_m_s2: np.ndarray
    rates_per_yr: np.ndarray
    source: dict
    notes: tuple = ()
    zero_rate_from_m_s2: float | None = None


def load_hazard(path, site=None):
    """The hazard curve in ``path`` (OpenQuake CSV, USGS JSON or plain table: see the module);
    ``site``: the row (0-based) of an OpenQuake file with several sites."""
    path = Path(path)
    text = read_user_text(path, "hazard file", DATA_FILE_BYTES)
    lines = [line.strip() for line in text.splitlines()]
    while lines and not lines[-1]:
        lines.pop()
    if not any(lines):
        raise InputError(f"hazard file {path} is empty")
    if len(lines) > 1 and lines[1].lower().startswith("lon,lat"):
        return _openquake(path, lines, site)
    if site is not None:
        raise InputError(f"--site applies to OpenQuake files with several sites; {path} is "
                         "not one")
    if text.lstrip().startswith("{"):
        return _usgs(path, text)
    return _plain(path, lines)


def _oq_levels(path, header, names):
    """(the levels of the columns ``names``, poe-<level> or <IMT>-<level>; the IMT the
    first line ``header`` or the columns state, checked)."""
    found = OQ_HEADER_IMT.search(header)
    imt = found.group(1) if found else None
    levels = []
    for name in names:
        match = _OQ_LEVEL.match(name)
        if not match:
            raise InputError(f"{path}: column {show(name)} is not poe-<level> or <IMT>-<level>")
        if match.group(1) != "poe":
            if imt is not None and match.group(1) != imt:
                raise InputError(f"{path}: the first line says imt {imt}, column {name} "
                                 f"says {match.group(1)}")
            imt = match.group(1)
        levels.append(parse_number(match.group(2), f"{path}: level of column {show(name)}"))
    if imt is None:
        raise InputError(f"{path}: missing IMT (no imt=... in the first line, poe-<level> "
                         "columns)")
    _check_imt(imt, path)
    return levels, imt


def _openquake(path, lines, site):
    header, columns = lines[0], [c.strip() for c in lines[1].split(",")]
    if not header.startswith("#"):
        raise InputError(f"{path}: an OpenQuake hazard curve starts with a '#' line stating "
                         "investigation_time and imt")
    found = re.search(r"investigation_time\s*=\s*([^,\"'\s]+)", header)
    if not found:
        raise InputError(f"{path}: no investigation_time in the first line")
    time_yr = parse_number(found.group(1), f"{path}: investigation_time")
    if not (math.isfinite(time_yr) and 0 < time_yr <= MAX_INVESTIGATION_YR):
        raise InputError(f"{path}: investigation_time must be a positive number of years "
                         f"(at most {MAX_INVESTIGATION_YR:g}), got {show(found.group(1))}")
    first = 3 if len(columns) > 2 and columns[2].lower() == "depth" else 2
    levels, imt = _oq_levels(path, header, columns[first:])
    if not levels:
        raise InputError(f"{path}: no poe-<level> columns")
    if len(levels) > MAX_LEVELS:
        raise InputError(f"{path}: {len(levels)} levels (at most {MAX_LEVELS})")
    rows = [line for line in lines[2:] if line]
    if not rows:
        raise InputError(f"{path}: no site rows below the header")
    if site is None and len(rows) > 1:
        raise InputError(f"{path} holds {len(rows)} sites: choose one with --site "
                         f"(0 to {len(rows) - 1})")
    site = 0 if site is None else site
    if not (isinstance(site, int) and 0 <= site < len(rows)):
        raise InputError(f"--site must be 0 to {len(rows) - 1} for {path}, got {site}")
    cells = [c.strip() for c in rows[site].split(",")]
    if len(cells) != len(columns):
        raise InputError(f"{path}: site row {site} has {len(cells)} values for "
                         f"{len(columns)} columns")
    values = [parse_number(c, f"{path}: site row {site}, column {columns[k]}")
              for k, c in enumerate(cells)]
    poe = np.array(values[first:])
    where = f"{path} (site {site})"
    for name, value, bound in (("lon", values[0], 360.0), ("lat", values[1], 90.0)):
        if not (math.isfinite(value) and abs(value) <= bound):
            raise InputError(f"{where}: {name} {value:g} is not a coordinate (at most "
                             f"{bound:g} deg in size)")
    for level, p in zip(levels, poe):
        if not math.isfinite(p):
            raise InputError(f"{where}: poe at {level:g} g is {p}")
        if p < 0:
            raise InputError(f"{where}: negative probability of exceedance {p:g} at "
                             f"{level:g} g")
        if p > 1:
            raise InputError(f"{where}: probability of exceedance {p:g} above 1 at "
                             f"{level:g} g")
    with np.errstate(divide="ignore"):
        rates = -np.log1p(-poe) / time_yr
    kind = re.search(r"\bkind\s*=\s*['\"]?([\w.\-]+)", header)
    source = {"format": "OpenQuake hazard-curve CSV", "file": str(path), "imt": imt,
              "kind": kind.group(1) if kind else None,
              "unit_in_file": OPENQUAKE_PGA_UNIT, "investigation_time_yr": time_yr,
              "site_index": site, "sites_in_file": len(rows),
              "lon": values[0], "lat": values[1],
              "rate_from_poe": "annual rate = -ln(1 - poe) / investigation_time (Poisson)"}
    return _curve(np.array(levels), rates, STANDARD_GRAVITY, OPENQUAKE_PGA_UNIT, where, source,
                  from_poe=True)


def _plain(path, lines):
    body = plain_body(lines)
    if not body:
        raise InputError(f"hazard file {path} is empty (comment lines only)")
    names = [n.strip() for n in body[0][1].split(",")]
    unit = level_unit(names[0], path, "first")
    if len(names) != 2 or names[1].lower() != PLAIN_RATE_COLUMN:
        raise InputError(f"{path}: expected the two columns pga_{unit},{PLAIN_RATE_COLUMN}, "
                         f"got {show(body[0][1])}")
    if len(body) - 1 > MAX_LEVELS:
        raise InputError(f"{path}: {len(body) - 1} levels (at most {MAX_LEVELS})")
    levels, rates = [], []
    for number, line in body[1:]:
        cells = line.split(",")
        if len(cells) != 2:
            raise InputError(f"{path}, line {number}: expected 2 values, got {len(cells)}")
        levels.append(parse_number(cells[0], f"{path}, line {number}: level"))
        rates.append(parse_number(cells[1], f"{path}, line {number}: rate"))
    source = {"format": "plain table", "file": str(path), "imt": "PGA", "unit_in_file": unit}
    return _curve(np.array(levels), np.array(rates), PLAIN_UNITS[unit],
                  unit.replace("_s2", "/s^2"), str(path), source)


def plain_body(lines):
    """(line number from 1, line) of a plain table's lines that are not empty or comments."""
    return [(k + 1, line) for k, line in enumerate(lines) if line and not line.startswith("#")]


def level_unit(name, path, column, imt="PGA"):
    """The unit of a plain table's level column ``name`` (``<imt>_<unit>``, its
    ``column``: "first", "third"), its IMT ``imt`` and its unit (:data:`PLAIN_UNITS`)
    checked: InputError naming ``path`` otherwise."""
    match = re.fullmatch(rf"({_IMT})_(.+)", name.strip().lower())
    if not match:
        raise InputError(f"{path}: missing IMT: the {column} column must be pga_<unit> "
                         f"({', '.join(f'pga_{u}' for u in PLAIN_UNITS)}), got {show(name)}")
    if match.group(1) != imt.lower():
        if imt.upper() != "PGA":
            raise InputError(f"{path}: IMT {match.group(1).upper()}, expected {imt.upper()}")
        _check_imt(match.group(1).upper(), path)
    if match.group(2) not in PLAIN_UNITS:
        raise InputError(f"{path}: unknown unit {show(match.group(2))} of column {show(name)} "
                         f"(known: {', '.join(PLAIN_UNITS)})")
    return match.group(2)


def _usgs(path, text):
    """The PGA curve of a USGS hazard web-service response (static curves: ``response``
    a list of {metadata: {imt: {value}, xlabel "Ground Motion (g)", xvals, latitude,
    longitude, edition {display}, vs30 {display}}, data: [{yvals}]}, yvals annual
    frequencies of exceedance); every value read checked for its type."""
    try:
        data = json.loads(text, parse_int=json_int)
    except RecursionError:
        raise InputError(f"{path}: not JSON (nested too deep)") from None
    except (ValueError, Unreadable) as exc:
        raise InputError(f"{path}: not JSON ({exc})") from None
    curves = data.get("response") if isinstance(data, dict) else None
    if not isinstance(curves, list) or not all(isinstance(c, dict) for c in curves):
        raise InputError(f"{path}: not a USGS hazard-curve response (no 'response' list)")
    metas = [_usgs_object(c, "metadata", f"{path}: response[{k}]", True)
             for k, c in enumerate(curves)]
    imts = [_usgs_object(m, "imt", f"{path}: response[{k}].metadata", True).get("value")
            for k, m in enumerate(metas)]
    if None in imts:
        raise InputError(f"{path}: missing IMT (a curve without metadata.imt.value)")
    if not all(isinstance(v, str) for v in imts):
        raise InputError(f"{path}: metadata.imt.value must be a text (e.g. PGA), got "
                         f"{show(next(v for v in imts if not isinstance(v, str)))}")
    if "PGA" not in imts:
        raise InputError(f"{path}: no PGA curve (IMTs: {show(', '.join(imts))}); survival "
                         "uses PGA hazard curves")
    k = imts.index("PGA")
    meta, rows, where = metas[k], curves[k].get("data"), f"{path}: response[{k}].metadata"
    xlabel, ylabel = (_usgs_text(meta, key, where) for key in ("xlabel", "ylabel"))
    unit = re.search(r"\(([^)]*)\)\s*$", xlabel or "")
    if not unit or unit.group(1) != "g":
        raise InputError(f"{path}: unknown unit of PGA: xlabel {show(xlabel)} "
                         "(expected 'Ground Motion (g)')")
    if "annual" not in (ylabel or "").lower():
        raise InputError(f"{path}: ylabel {show(ylabel)} is not an annual "
                         "frequency of exceedance")
    if not isinstance(rows, list) or len(rows) != 1 or not isinstance(rows[0], dict):
        raise InputError(f"{path}: expected one PGA data entry, got "
                         f"{len(rows) if isinstance(rows, list) else show(rows)}")
    x, y = meta.get("xvals"), rows[0].get("yvals")
    if not (isinstance(x, list) and isinstance(y, list)) or len(x) != len(y):
        raise InputError(f"{path}: xvals and yvals must be lists of one length")
    if len(x) > MAX_LEVELS:
        raise InputError(f"{path}: {len(x)} levels (at most {MAX_LEVELS})")
    for v in x + y:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"{path}: not a number: {show(v)}")
    source = {"format": "USGS hazard web service (static curve)", "file": str(path),
              "imt": "PGA", "unit_in_file": "g",
              "lat": _usgs_coordinate(meta, "latitude", 90.0, where),
              "lon": _usgs_coordinate(meta, "longitude", 360.0, where),
              "edition": _usgs_text(_usgs_object(meta, "edition", where, True), "display",
                                    f"{where}.edition"),
              "vs30": _usgs_text(_usgs_object(meta, "vs30", where, True), "display",
                                 f"{where}.vs30")}
    try:
        levels, rates = np.array(x, float), np.array(y, float)
    except OverflowError:
        raise InputError(f"{path}: a number beyond a float's range in xvals or yvals") from None
    return _curve(levels, rates, STANDARD_GRAVITY, "g", str(path), source)


def _usgs_object(parent, key, where, optional=False):
    """``parent[key]``, an object ({} when ``optional`` and absent or null)."""
    value = parent.get(key)
    if value is None and optional:
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{where}.{key} must be an object, got {show(value)}")
    return value


def _usgs_text(parent, key, where):
    """``parent[key]``: a text, or None when absent or null."""
    value = parent.get(key)
    if value is not None and not isinstance(value, str):
        raise InputError(f"{where}.{key} must be a text, got {show(value)}")
    return value


def _usgs_coordinate(meta, key, bound, where):
    """A latitude or longitude (deg, at most ``bound`` in size), or None when absent."""
    value = meta.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not (math.isfinite(value) and abs(value) <= bound):
        raise InputError(f"{where}.{key} must be a number of at most {bound:g} deg in size, "
                         f"got {show(value)}")
    return float(value)


def _check_imt(imt, path):
    if imt.upper() != "PGA":
        raise InputError(f"{path}: IMT {imt}: the fragility is over PGA and PGV/PGA (give PGA "
                         "hazard curves)")


def parse_number(text, what):
    """``text`` (a value of a table) as a float; InputError naming ``what`` when it is not
    a number."""
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{what}: not a number: {show(text.strip())}") from None


def check_curve(levels: np.ndarray, rates: np.ndarray, to_m_s2: float, unit: str,
                where: str, from_poe: bool = False) -> None:
    """The one check of a hazard curve's values, as a file gives them (``levels`` in the
    file's ``unit``, ``to_m_s2`` to m/s^2; ``rates`` 1/yr): at least 2 levels, each from
    MIN_PGA_M_S2 to MAX_PGA_M_S2 and increasing; each rate a number from 0 to
    MAX_RATE_PER_YR (infinite only ``from_poe``: a probability of exceedance of 1), not
    rising with the level.  InputError naming ``where`` and the value."""
    levels, rates = np.asarray(levels, float), np.asarray(rates, float)
    if levels.size < 2:
        raise InputError(f"{where}: {levels.size} level(s); a hazard curve needs at least 2")
    low, top = MIN_PGA_M_S2 / to_m_s2, MAX_PGA_M_S2 / to_m_s2
    in_g = "" if unit == "g" else " (1e-6 g to 100 g)"
    for x in levels:
        if not (math.isfinite(x) and low <= x <= top):
            raise InputError(f"{where}: level {x:g} {unit}: levels must be positive, at least "
                             f"{low:g} and at most {top:g} {unit}{in_g}")
    rising = np.flatnonzero(np.diff(levels) <= 0)
    if rising.size:
        k = rising[0]
        raise InputError(f"{where}: levels not increasing: {levels[k]:g} then "
                         f"{levels[k + 1]:g} {unit}")
    for x, r in zip(levels, rates):
        if math.isinf(r) and not (from_poe and r > 0):
            raise InputError(f"{where}: rate at {x:g} {unit} is infinite: rates must be finite")
        if math.isnan(r):
            raise InputError(f"{where}: rate at {x:g} {unit} is not a number")
        if r < 0:
            raise InputError(f"{where}: negative annual rate {r:g} at {x:g} {unit}")
        if math.isfinite(r) and r > MAX_RATE_PER_YR:
            raise InputError(f"{where}: annual rate {r:g} at {x:g} {unit}: at most "
                             f"{MAX_RATE_PER_YR:g} per year (is it a rate of exceedance "
                             "per year?)")
    with np.errstate(invalid="ignore"):
        up = np.flatnonzero(np.diff(rates) > 0)
    if up.size:
        k = up[0]
        raise InputError(f"{where}: non-monotonic: the rate of exceedance rises from "
                         f"{rates[k]:.6g} at {levels[k]:g} {unit} to {rates[k + 1]:.6g} at "
                         f"{levels[k + 1]:g} {unit}")


def _curve(levels, rates, to_m_s2, unit, where, source, from_poe=False):
    """HazardCurve from levels (file unit; ``to_m_s2`` converts) and annual rates: the
    checks (:func:`check_curve`) and repairs of the module docstring; an infinite rate
    only ``from_poe`` (a probability of exceedance of 1, dropped with a note)."""
    check_curve(levels, rates, to_m_s2, unit, where, from_poe)
    notes = []
    unbounded = ~np.isfinite(rates)
    if unbounded.any():
        notes.append(f"{int(unbounded.sum())} level(s) up to {levels[unbounded][-1]:g} {unit} "
                     "dropped: probability of exceedance 1 (unbounded rate)")
    zero = rates == 0
    zero_from = None
    if zero.any():
        zero_from = float(levels[zero][0] * to_m_s2)
        notes.append(f"rates are 0 from {levels[zero][0]:g} {unit} up: the curve ends at the "
                     "last positive rate")
    keep = np.isfinite(rates) & ~zero
    if keep.sum() < 2:
        raise InputError(f"{where}: fewer than 2 levels with a positive, finite rate")
    return HazardCurve(levels[keep] * to_m_s2, rates[keep].astype(float), source, tuple(notes),
                       zero_from)
