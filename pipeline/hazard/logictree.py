"""The one loader of a hazard model's logic tree: its branches, their weights and one
hazard curve (annual rate of exceeding PGA) per branch, on common levels.

Two formats (:func:`load_logic_tree`):

- OpenQuake's export: ``realizations.csv`` (or ``realizations_<calc>.csv``: an optional
  ``#`` line, then ``rlz_id,branch_path,weight``, one row per realisation) and beside it
  one hazard-curve CSV per realisation (``hazard_curve-rlz-000_PGA.csv``,
  ``hazard_curve-rlz-000-PGA_<calc>.csv``, or older names such as
  ``hazard_curve-smltp_b1_b2-gsimltp_b1.csv``): each curve is found by the ``kind=
  'rlz-NNN'`` of its first line and read by :func:`pipeline.hazard.curves.load_hazard`;
  curves of other IMTs and the statistics (mean, quantiles) beside them are passed over.
  Give the directory or the realizations file.
- A plain table: comment lines starting with ``#`` anywhere, the header
  ``branch,weight,pga_<g|m_s2|cm_s2>,annual_rate_per_yr`` (an optional fifth column
  ``path``: the branch's path in the tree), then one row per branch and level (long
  format); a branch's weight is repeated on each of its rows; a last column ``site``
  (0-based integers) holds several sites' curves, one read at a time.  The IMT must be PGA (the
  fragility's); another (``sa(1.0)_g``) only when the caller asks for it by name.

Every branch's curve is on the same levels.  Levels where a curve has no finite positive
rate (OpenQuake's probability of exceedance 1 at the lowest levels, an unbounded rate;
rates of 0 at the top) are dropped for every branch, said in ``notes``: the rates are
interpolated in (ln PGA, ln rate), where neither has a value.

One-line refusals (InputError): weights negative or not numbers, weights whose sum differs
from 1 by more than :data:`WEIGHT_TOLERANCE` (then they are divided by their sum, so that
they sum to 1 to the last bit), curves on different levels, sites or IMTs, a branch
without a curve, a curve without a branch, a branch twice, OpenQuake curves of different
investigation times (two calculations' curves), a curve's values as
:func:`pipeline.hazard.curves.check_curve` refuses them (levels outside 1e-6 g to 100 g,
rates not finite, negative, above 1e3 per year or rising with the level), more than
:data:`MAX_BRANCHES` branches or :data:`MAX_LEVELS` levels (and each file at most
``pipeline.userfiles.MAX_FILE_BYTES``).
"""
import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.hazard.curves import (MAX_LEVELS, OQ_HEADER_IMT, PLAIN_RATE_COLUMN, PLAIN_UNITS,
                                    check_curve, level_unit, load_hazard, parse_number,
                                    plain_body)
from pipeline.hazard.logictree_sites import plain_site_rows, plain_site_tables
from pipeline.files import InputError
from pipeline.userfiles import DATA_FILE_BYTES, read_user_bytes, read_user_text, show

MAX_BRANCHES = 10_000
ROUNDING = 1e-15                 # per weight: a sum this close to 1 is 1 written in decimals
WEIGHT_TOLERANCE = 1e-6          # |sum of weights - 1| allowed (the sum is 1: absolute = relative)
MAX_CURVE_FILES = 4 * MAX_BRANCHES   # hazard_curve*.csv files looked at in one directory
REALIZATIONS_COLUMNS = ("rlz_id", "branch_path", "weight")
_KIND = re.compile(r"\bkind\s*=\s*['\"]?rlz-(\d+)")


@dataclass(frozen=True)
class LogicTree:
    """Branches of a hazard model: ``branch_ids`` and ``branch_paths`` (str, one per
    branch), ``weights`` (B, sum 1), ``levels_m_s2`` (L, PGA, increasing), ``rates_per_yr``
    (B x L, annual rate of exceeding each level, positive, not increasing along a row),
    ``imt`` ("PGA"; a plain table read with another ``imt`` keeps its levels in the same
    units, g converted to m/s^2), ``source`` (dict: format, file, site, ...), ``notes`` (what the loader
    dropped or repaired, and why)."""
    branch_ids: tuple
    branch_paths: tuple
    weights: np.ndarray = field(compare=False)
    levels_m_s2: np.ndarray = field(compare=False)
    rates_per_yr: np.ndarray = field(compare=False)
    imt: str = "PGA"
    source: dict = field(default_factory=dict, compare=False)
    notes: tuple = ()

    @property
    def size(self):
        return len(self.branch_ids)


def load_logic_tree(path, site=None, imt="PGA"):
    """The :class:`LogicTree` in ``path``: an OpenQuake export (its directory or its
    realizations file) or a plain table (see the module); ``site``: the row (0-based) of
    OpenQuake curves with several sites; ``imt``: the intensity measure the curves must be
    of (PGA, as the fragility; a plain table may hold another, e.g. "SA(1.0)", for the
    statistics over branches alone)."""
    path = Path(path)
    if imt.upper() != "PGA" and (path.is_dir() or _is_openquake(path)):
        raise InputError(f"{path}: OpenQuake exports are read for PGA only, not {imt}")
    if path.is_dir():
        found = sorted(path.glob("realizations*.csv"))
        if len(found) != 1:
            raise InputError(f"logic tree directory {path}: expected one realizations*.csv "
                             f"(OpenQuake's export), found {len(found)}")
        return _openquake(found[0], site)
    lines = _lines(path, "logic tree file")
    if _header(lines).replace(" ", "").lower().startswith("rlz_id,"):
        return _openquake(path, site)
    return _plain(path, plain_site_rows(path, lines, site), imt)


def load_logic_trees(path, sites, imt="PGA"):
    """{site: :func:`load_logic_tree` (path, site, imt)} for each of ``sites``, a plain
    table read and split by site once."""
    path = Path(path)
    lines = None if path.is_dir() else _lines(path, "logic tree file")
    if lines is None or _header(lines).replace(" ", "").lower().startswith("rlz_id,"):
        return {site: load_logic_tree(path, site, imt) for site in sites}
    return {site: _plain(path, table, imt)
            for site, table in zip(sites, plain_site_tables(path, lines, sites))}


def _header(lines):
    return next((line for line in lines if line.strip() and not line.startswith("#")), "")


def _is_openquake(path):
    """True when ``path`` is a realizations file (its first row rlz_id,...)."""
    return path.is_file() and _header(_lines(path, "logic tree file")).replace(
        " ", "").lower().startswith("rlz_id,")


def _lines(path, what):
    text = read_user_text(path, what, DATA_FILE_BYTES)
    lines = [line.strip() for line in text.splitlines()]
    if not any(line and not line.startswith("#") for line in lines):
        raise InputError(f"{what} {path} is empty")
    return lines


# ---------------------------------------------------------------- OpenQuake
def _openquake(path, site):
    rows = _realizations(path)
    curves = _curve_files(path.parent)
    ids = [r[0] for r in rows]
    extra = sorted(set(curves) - set(ids))
    if extra:
        raise InputError(f"{curves[extra[0]].name} is the curve of realisation {extra[0]}, "
                         f"which {path.name} does not list (a curve without a branch)")
    loaded = []
    for rlz, branch_path, _ in rows:
        if rlz not in curves:
            raise InputError(f"branch {rlz} ({branch_path}) has no PGA hazard curve in "
                             f"{path.parent} (no hazard_curve*.csv of kind rlz-{rlz:03d})")
        loaded.append(load_hazard(curves[rlz], site))
    _one_investigation_time(loaded, [curves[r[0]].name for r in rows])
    sites = {(c.source.get("lon"), c.source.get("lat")) for c in loaded}
    if len(sites) > 1:
        raise InputError(f"{path.parent}: the curves are of different sites "
                         f"({show(sorted(sites))})")
    levels, rates, notes = _common_levels(
        [(c.levels_m_s2, c.rates_per_yr, c.zero_rate_from_m_s2) for c in loaded],
        [f"rlz-{r[0]:03d}" for r in rows])
    notes = _grouped([(f"rlz-{r[0]:03d}", n) for r, c in zip(rows, loaded)
                      for n in c.notes]) + notes
    first = loaded[0].source
    source = {"format": "OpenQuake realizations and hazard curves", "file": str(path),
              "directory": str(path.parent), "imt": "PGA",
              "investigation_time_yr": first.get("investigation_time_yr"),
              "site_index": first.get("site_index"), "lon": first.get("lon"),
              "lat": first.get("lat"),
              "curve_files": [curves[r[0]].name for r in rows],
              "rate_from_poe": first.get("rate_from_poe")}
    weights, more = _weights([r[2] for r in rows], path)
    return LogicTree(tuple(str(r[0]) for r in rows), tuple(r[1] for r in rows), weights,
                     levels, rates, "PGA", source, tuple(notes + more))


def _one_investigation_time(loaded: list, names: list[str]) -> None:
    """InputError unless every curve states one investigation time: the realisations of
    one calculation share it, so curves of two are two calculations' (each curve's
    rates are annual, -ln(1 - poe) / T, but their branches are not one tree's)."""
    times = [c.source["investigation_time_yr"] for c in loaded]
    for name, time in zip(names, times):
        if time != times[0]:
            raise InputError(f"{name}: investigation_time {time:g} yr, {names[0]}: "
                             f"{times[0]:g} yr: the realisations of one calculation share "
                             "one investigation time (curves of two calculations mixed?)")


def _realizations(path):
    """[(rlz_id int, branch_path, weight)] of an OpenQuake realizations CSV."""
    lines = [line for line in _lines(path, "realizations file")
             if line and not line.startswith("#")]
    table = list(csv.reader(lines))
    names = tuple(c.strip().lower() for c in table[0])
    if names[:3] != REALIZATIONS_COLUMNS:
        raise InputError(f"{path}: expected the columns {','.join(REALIZATIONS_COLUMNS)}, got "
                         f"{show(','.join(table[0]))}")
    if len(table) - 1 > MAX_BRANCHES:
        raise InputError(f"{path}: {len(table) - 1} realisations (at most {MAX_BRANCHES})")
    if len(table) < 2:
        raise InputError(f"{path}: no realisations below the header")
    rows, seen = [], {}
    for number, cells in enumerate(table[1:], start=2):
        if len(cells) < 3:
            raise InputError(f"{path}, row {number}: expected rlz_id,branch_path,weight, got "
                             f"{show(','.join(cells))}")
        try:
            rlz = int(cells[0])
        except ValueError:
            raise InputError(f"{path}, row {number}: rlz_id {show(cells[0])} is not an "
                             "integer") from None
        if rlz < 0:
            raise InputError(f"{path}, row {number}: negative rlz_id {rlz}")
        if rlz in seen:
            raise InputError(f"{path}: realisation {rlz} twice (rows {seen[rlz]} and {number})")
        seen[rlz] = number
        rows.append((rlz, cells[1].strip(),
                     parse_number(cells[2], f"{path}, row {number}: weight")))
    return rows


def _curve_files(directory):
    """{rlz id: path} of the PGA curves of realisations in ``directory`` (first lines read)."""
    files = sorted(directory.glob("hazard_curve*.csv"))
    if len(files) > MAX_CURVE_FILES:
        raise InputError(f"{directory}: {len(files)} hazard_curve*.csv files (at most "
                         f"{MAX_CURVE_FILES})")
    curves, other_imts = {}, set()
    for path in files:
        head = read_user_bytes(path, "hazard curve file", DATA_FILE_BYTES)[:4096]
        first = head.decode("utf-8", errors="replace").split("\n", 1)[0]
        kind, imt = _KIND.search(first), OQ_HEADER_IMT.search(first)
        if kind is None:
            continue                      # a statistic (mean, quantile) or not a curve
        if imt is not None and imt.group(1).upper() != "PGA":
            other_imts.add(imt.group(1))
            continue
        rlz = int(kind.group(1))
        if rlz in curves:
            raise InputError(f"{directory}: two PGA curves of realisation {rlz}: "
                             f"{curves[rlz].name} and {path.name}")
        curves[rlz] = path
    if not curves and other_imts:
        raise InputError(f"{directory}: no PGA curves of the realisations (IMTs: "
                         f"{', '.join(sorted(other_imts))}); the fragility is over PGA")
    return curves


# ---------------------------------------------------------------- plain table
def _plain(path, lines, imt="PGA"):
    body = plain_body(lines)
    names = [n.strip().lower() for n in body[0][1].split(",")]
    unit = _plain_header(path, names, imt)
    with_path = len(names) == 5
    branches = {}
    for number, line in body[1:]:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(names):
            raise InputError(f"{path}, line {number}: expected {len(names)} values, got "
                             f"{len(cells)}")
        name = cells[0]
        if not name or not name.isprintable() or len(name) > 200:
            raise InputError(f"{path}, line {number}: branch name {show(name)} must be 1-200 "
                             "printable characters")
        entry = branches.setdefault(name, {"weight": cells[1], "path": cells[4] if with_path
                                           else name, "rows": [], "line": number})
        if len(branches) > MAX_BRANCHES:
            raise InputError(f"{path}: more than {MAX_BRANCHES} branches")
        if cells[1] != entry["weight"] \
                and parse_number(cells[1], "") != parse_number(entry["weight"], ""):
            raise InputError(f"{path}, line {number}: branch {show(name)} has weight "
                             f"{cells[1]} here and {entry['weight']} on line {entry['line']}")
        if with_path and cells[4] != entry["path"]:
            raise InputError(f"{path}, line {number}: branch {show(name)} has two paths")
        entry["rows"].append((parse_number(cells[2], f"{path}, line {number}: level"),
                              parse_number(cells[3], f"{path}, line {number}: rate")))
        if len(entry["rows"]) > MAX_LEVELS:
            raise InputError(f"{path}: branch {show(name)} has more than {MAX_LEVELS} levels")
    if not branches:
        raise InputError(f"{path}: no rows below the header")
    curves = [_plain_curve(path, name, entry["rows"], PLAIN_UNITS[unit], unit)
              for name, entry in branches.items()]
    first = curves[0][0]
    for name, (levels, _) in zip(branches, curves):
        if levels.shape != first.shape or not np.array_equal(levels, first):
            raise InputError(f"{path}: curves on different levels: branch {show(name)} has "
                             f"{levels.size} levels {_levels_text(levels)}, branch "
                             f"{show(next(iter(branches)))} {first.size} "
                             f"{_levels_text(first)}")
    ids = list(branches)
    levels, rates, notes = _common_levels([(lv[r > 0], r[r > 0], None) for lv, r in curves],
                                          ids)
    weights, more = _weights([parse_number(branches[n]["weight"],
                                           f"{path}: branch {show(n)} weight")
                              for n in ids], path)
    source = {"format": "plain logic-tree table", "file": str(path), "imt": imt.upper(),
              "unit_in_file": unit}
    return LogicTree(tuple(ids), tuple(branches[n]["path"] for n in ids), weights, levels,
                     rates, imt.upper(), source, tuple(notes + more))


def _plain_header(path, names, imt="PGA"):
    """The unit of a plain table's level column, the header checked."""
    if len(names) not in (4, 5) or names[:2] != ["branch", "weight"] \
            or names[3] != PLAIN_RATE_COLUMN or (len(names) == 5 and names[4] != "path"):
        raise InputError(f"{path}: expected the header branch,weight,pga_<unit>,"
                         f"{PLAIN_RATE_COLUMN}[,path], got {show(','.join(names))}")
    return level_unit(names[2], path, "third", imt)


def _plain_curve(path, name, rows, to_m_s2, unit):
    """(levels m/s^2, rates 1/yr) of one branch of a plain table, checked."""
    levels = np.array([r[0] for r in rows])
    rates = np.array([r[1] for r in rows])
    check_curve(levels, rates, to_m_s2, unit, f"{path}: branch {show(name)}")
    return levels * to_m_s2, rates


# ---------------------------------------------------------------- shared
def _levels_text(levels):
    return f"{levels[0]:.6g}-{levels[-1]:.6g}" if levels.size else "none"


def _grouped(labelled):
    """One note per text, naming every branch it holds for ("rlz-000, rlz-001: ...")."""
    branches = {}
    for label, note in labelled:
        branches.setdefault(note, []).append(label)
    return [f"{', '.join(labels)}: {note}" for note, labels in branches.items()]


def _weights(values, path):
    """(weights divided by their sum, notes): each finite and >= 0, the sum 1 within
    WEIGHT_TOLERANCE."""
    w = np.array(values, float)
    for k, v in enumerate(w):
        if not math.isfinite(v) or v < 0:
            raise InputError(f"{path}: branch {k} has weight {v:g}: weights must be finite "
                             "and 0 or more")
    total = float(w.sum())
    if not abs(total - 1.0) <= WEIGHT_TOLERANCE:
        raise InputError(f"{path}: the weights sum to {total:.9g}, not 1 (within "
                         f"{WEIGHT_TOLERANCE:g})")
    rounding = abs(total - 1.0) <= ROUNDING * len(w)   # 1/3 + 1/3 + 1/3 written out: no note
    notes = [] if rounding else [f"weights summed to {total:.15g}: divided by their sum"]
    zero = int((w == 0).sum())
    if zero:
        notes.append(f"{zero} branch(es) of weight 0")
    return w / total, notes


def _common_levels(curves, names):
    """(levels, rates B x L, notes) from [(levels, rates, zero_rate_from)] per branch, each
    the positive finite part of the same file levels: the levels every branch has a rate
    at.  InputError when the branches' levels differ within the range they share."""
    for (levels, _, _), name in zip(curves, names):
        if levels.size < 2:
            raise InputError(f"{name}: fewer than 2 levels with a positive, finite rate")
    union = np.unique(np.concatenate([c[0] for c in curves]))
    if union.size > MAX_LEVELS:
        raise InputError(f"the curves have {union.size} levels (at most {MAX_LEVELS})")
    for (levels, _, _), name in zip(curves, names):
        inside = union[(union >= levels[0]) & (union <= levels[-1])]
        if inside.shape != levels.shape or not np.array_equal(inside, levels):
            other = next(n for (lv, _, _), n in zip(curves, names)
                         if not np.array_equal(lv[(lv >= levels[0]) & (lv <= levels[-1])],
                                               levels))
            raise InputError(f"curves on different levels: {name} has {levels.size} levels "
                             f"{_levels_text(levels)} m/s^2, {other} others in that range")
    lo = max(c[0][0] for c in curves)
    hi = min(c[0][-1] for c in curves)
    keep = union[(union >= lo) & (union <= hi)]
    if keep.size < 2:
        raise InputError("fewer than 2 levels at which every branch has a positive, finite "
                         "rate")
    rates = np.array([r[np.searchsorted(lv, keep)] for lv, r, _ in curves])
    notes = []
    if lo > union[0]:
        notes.append(f"levels below {lo:.6g} m/s^2 dropped for every branch: some branch has "
                     "no finite rate there (probability of exceedance 1)")
    if hi < union[-1]:
        notes.append(f"levels above {hi:.6g} m/s^2 dropped for every branch: some branch has "
                     "a rate of 0 there (the curves end at the last level all branches "
                     "exceed)")
    return keep, rates, notes
