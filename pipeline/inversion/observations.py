"""Observations of an inversion: sites with fallen and standing columns.

Schema (keys are a contract)::

    {"sites": [{"name": "A", "east_km": 0, "north_km": 0,
                "columns": [{"column": "drums", "state": "fallen",
                             "downfall_azimuth_deg": 240, "uncertainty_deg": 10},
                            {"column": "monolithic", "state": "standing"}]}]}

A site gives its position either as ``east_km``/``north_km`` (any local frame) or as
``latitude``/``longitude`` (degrees), the same way for every site.  Positions are turned
into km East/North of the first site: geographic ones on the local tangent plane about the
first site (azimuthal equidistant: distance and azimuth from obspy.geodetics).
``column`` is ``drums``, ``monolithic`` or a column file: a shipped example's name or a
JSON/YAML file (relative to the observations file's folder); ``invert`` computes a forward
table for each described column.  ``uncertainty_deg`` (optional, default
10) is the 1-sigma uncertainty of the measured downfall azimuth.  A standing column may
say more (docs/damage.md): ``damage_state`` (none, slight, moderate or severe: the state
it was seen in) or ``residual_slide_m`` with ``base_width_m`` (the largest shift measured
between neighbouring drums, or of the bottom drum on its base, and the bottom drum's
diameter, m: at least the state of the residual slide's limits; the peak measures leave
no trace).  Every problem is one
line naming the site and column; so is every problem with the file itself (too large,
not UTF-8, not JSON, nested too deeply, an integer of absurd length).
"""
import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from pipeline.files import InputError
from pipeline.outcome.damage import LEVELS, DamageState
from pipeline.userfiles import MAX_NESTING, read_text
from pipeline.userfiles import Unreadable as _Unreadable
from pipeline.userfiles import json_int as _json_int
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import nesting as _nesting
from pipeline.userfiles import number as _number
from pipeline.userfiles import show as _show

MAX_REGION_KM = 300.0   # sites further from the first are not one region (the forward
#                         table reaches 30 km; candidates are gridded over the region)

DEFAULT_UNCERTAINTY_DEG = 10.0
MAX_UNCERTAINTY_DEG = 120.0
STATES = ("fallen", "standing")
SITE_KEYS = {"name", "east_km", "north_km", "latitude", "longitude", "columns"}
COLUMN_KEYS = {"column", "state", "downfall_azimuth_deg", "uncertainty_deg", "note",
               "damage_state", "residual_slide_m", "base_width_m"}
STANDING_STATES = tuple(s.label for s in DamageState if s is not DamageState.COLLAPSE)
MAX_SLIDE_M = 10.0           # a residual slide beyond this is no joint's
BASE_WIDTH_RANGE_M = (0.01, 20.0)
MAX_SITES = 1000
MAX_COLUMNS_PER_SITE = 1000


@dataclass(frozen=True)
class ColumnObservation:
    """One column as found: ``state`` fallen or standing; a fallen one's
    ``downfall_azimuth_deg`` and its ``uncertainty_deg``; a standing one's
    ``damage_state`` (:class:`DamageState`, below collapse) or ``residual_slide_m`` and
    ``base_width_m`` (m), or neither."""
    column: str
    state: str
    downfall_azimuth_deg: float = None
    uncertainty_deg: float = DEFAULT_UNCERTAINTY_DEG
    damage_state: DamageState = None
    residual_slide_m: float = None
    base_width_m: float = None

    @property
    def fallen(self):
        return self.state == "fallen"

    @property
    def state_range(self):
        """(lowest, highest) :class:`DamageState` the column is in: collapse when it fell;
        standing, none to severe, its ``damage_state``, or from the state of its residual
        slide over the base width (docs/damage.md) to severe."""
        if self.fallen:
            return DamageState.COLLAPSE, DamageState.COLLAPSE
        if self.damage_state is not None:
            return self.damage_state, self.damage_state
        if self.residual_slide_m is not None:
            return DamageState.of(self.residual_slide_m / self.base_width_m,
                                  LEVELS.residual), DamageState.SEVERE
        return DamageState.NONE, DamageState.SEVERE

    def as_dict(self):
        """The column in the file's schema."""
        if self.fallen:
            return {"column": self.column, "state": self.state,
                    "downfall_azimuth_deg": self.downfall_azimuth_deg,
                    "uncertainty_deg": self.uncertainty_deg}
        out = {"column": self.column, "state": self.state}
        if self.damage_state is not None:
            out["damage_state"] = self.damage_state.label
        if self.residual_slide_m is not None:
            out.update(residual_slide_m=self.residual_slide_m, base_width_m=self.base_width_m)
        return out


@dataclass(frozen=True)
class Site:
    name: str
    east_km: float          # East of the first site
    north_km: float         # North of the first site
    columns: tuple
    latitude: float = None
    longitude: float = None


@dataclass(frozen=True)
class Observations:
    sites: tuple
    source: str = "observations"
    meta: dict = field(default_factory=dict)

    @property
    def n_columns(self):
        return sum(len(s.columns) for s in self.sites)

    @property
    def n_fallen(self):
        return sum(c.fallen for s in self.sites for c in s.columns)

    def column_types(self):
        return sorted({c.column for s in self.sites for c in s.columns})

    def as_dict(self):
        """The observations in the file's schema, positions in km from the first site."""
        sites = []
        for s in self.sites:
            site = {"name": s.name, "east_km": s.east_km, "north_km": s.north_km}
            if s.latitude is not None:
                site.update(latitude=s.latitude, longitude=s.longitude)
            site["columns"] = [c.as_dict() for c in s.columns]
            sites.append(site)
        return {"sites": sites}

    def turned(self, degrees):
        """The observations turned clockwise by ``degrees`` about the first site: positions
        and downfall azimuths (a check of the inversion's rotational symmetry)."""
        a = math.radians(degrees)
        sites = []
        for s in self.sites:
            east = s.east_km * math.cos(a) + s.north_km * math.sin(a)
            north = -s.east_km * math.sin(a) + s.north_km * math.cos(a)
            cols = tuple(c if not c.fallen else dataclasses.replace(
                c, downfall_azimuth_deg=(c.downfall_azimuth_deg + degrees) % 360.0)
                for c in s.columns)
            sites.append(Site(s.name, east, north, cols))
        return Observations(tuple(sites), self.source, dict(self.meta))


def _file_name(text):
    """Whether ``text`` can name a column file (printable, no part longer than a file
    system allows)."""
    return text.isprintable() and len(text) <= 1024 and \
        all(len(part.encode()) <= 255 for part in text.split("/"))


def parse_column(item, where):
    if not isinstance(item, dict):
        raise InputError(f"{where}: a column must be an object, got {type(item).__name__}")
    unknown = set(item) - COLUMN_KEYS
    if unknown:
        raise InputError(f"{where}: unknown key(s) {_keys(unknown)} (known: "
                         f"{', '.join(sorted(COLUMN_KEYS))})")
    column = item.get("column")
    if not isinstance(column, str) or not column.strip() or not _file_name(column.strip()):
        raise InputError(f"{where}: 'column' must be drums, monolithic or a column file name")
    state = item.get("state")
    if state not in STATES:
        raise InputError(f"{where}: 'state' must be 'fallen' or 'standing', got "
                         f"{_show(state)}")
    if state == "standing":
        if item.get("downfall_azimuth_deg") is not None:
            raise InputError(f"{where}: a standing column has no downfall_azimuth_deg")
        return ColumnObservation(column.strip(), state, **_standing_damage(item, where))
    damage = sorted({"damage_state", "residual_slide_m", "base_width_m"} & set(item))
    if damage:
        raise InputError(f"{where}: a fallen column is in collapse; {damage[0]} describes a "
                         "standing one")
    if item.get("downfall_azimuth_deg") is None:
        raise InputError(f"{where}: a fallen column needs downfall_azimuth_deg")
    azimuth = _number(item["downfall_azimuth_deg"], f"{where}: downfall_azimuth_deg", 0.0, 360.0)
    sigma = item.get("uncertainty_deg", DEFAULT_UNCERTAINTY_DEG)
    sigma = _number(sigma, f"{where}: uncertainty_deg", 0.0, MAX_UNCERTAINTY_DEG)
    return ColumnObservation(column.strip(), state, azimuth % 360.0, sigma)


def _standing_damage(item, where):
    """A standing column's ``damage_state`` or ``residual_slide_m`` and ``base_width_m``
    (keyword arguments of :class:`ColumnObservation`)."""
    if "damage_state" in item:
        if "residual_slide_m" in item or "base_width_m" in item:
            raise InputError(f"{where}: give damage_state or residual_slide_m with "
                             "base_width_m, not both")
        name = item["damage_state"]
        if name == DamageState.COLLAPSE.label:
            raise InputError(f"{where}: a column in collapse fell: state 'fallen'")
        if name not in STANDING_STATES:
            raise InputError(f"{where}: 'damage_state' must be one of "
                             f"{', '.join(STANDING_STATES)}, got {_show(name)}")
        return {"damage_state": DamageState[name.upper()]}
    if ("residual_slide_m" in item) != ("base_width_m" in item):
        raise InputError(f"{where}: residual_slide_m and base_width_m go together (the "
                         "shift over the bottom drum's diameter gives the damage state)")
    if "residual_slide_m" not in item:
        return {}
    return {"residual_slide_m": _number(item["residual_slide_m"],
                                        f"{where}: residual_slide_m", 0.0, MAX_SLIDE_M),
            "base_width_m": _number(item["base_width_m"], f"{where}: base_width_m",
                                    *BASE_WIDTH_RANGE_M)}


def parse_observations(data, source="observations"):
    """:class:`Observations` from the parsed JSON ``data``; InputError (one line) if bad."""
    if not isinstance(data, dict) or "sites" not in data:
        raise InputError(f"{source}: expected an object with a 'sites' list")
    sites = data["sites"]
    if not isinstance(sites, list) or not sites:
        raise InputError(f"{source}: 'sites' must be a non-empty list")
    if len(sites) > MAX_SITES:
        raise InputError(f"{source}: {len(sites)} sites, at most {MAX_SITES}")
    raw, names = [], set()
    for k, site in enumerate(sites):
        where = f"{source}: site {k + 1}"
        if not isinstance(site, dict):
            raise InputError(f"{where}: must be an object, got {type(site).__name__}")
        name = site.get("name", f"site{k + 1}")
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{where}: 'name' must be a non-empty string")
        where = f"{source}: site {_show(name)}"
        if name in names:
            raise InputError(f"{where}: two sites have this name")
        names.add(name)
        unknown = set(site) - SITE_KEYS
        if unknown:
            raise InputError(f"{where}: unknown key(s) {_keys(unknown)} (known: "
                             f"{', '.join(sorted(SITE_KEYS))})")
        position = _position(site, where)
        columns = site.get("columns")
        if not isinstance(columns, list) or not columns:
            raise InputError(f"{where}: 'columns' must be a non-empty list")
        if len(columns) > MAX_COLUMNS_PER_SITE:
            raise InputError(f"{where}: {len(columns)} columns, at most "
                             f"{MAX_COLUMNS_PER_SITE}")
        parsed = tuple(parse_column(c, f"{where}, column {j + 1}")
                       for j, c in enumerate(columns))
        raw.append((name, position, parsed))
    kinds = {p[0] for _, p, _ in raw}
    if len(kinds) > 1:
        raise InputError(f"{source}: mixes east_km/north_km and latitude/longitude between "
                         "sites; use one for all")
    out = _local_sites(raw)
    for site in out:                  # one rule, whether sites come in km or in degrees
        if math.hypot(site.east_km, site.north_km) > MAX_REGION_KM:
            raise InputError(f"{source}: site {_show(site.name)} lies "
                             f"{math.hypot(site.east_km, site.north_km):.0f} km from the "
                             f"first site (more than {MAX_REGION_KM:g} km: not one region)")
    for k, a in enumerate(out):
        for b in out[:k]:
            if math.hypot(a.east_km - b.east_km, a.north_km - b.north_km) < 1e-6:
                raise InputError(f"{source}: sites {_show(b.name)} and {_show(a.name)} are "
                                 "at the same place; list their columns under one site")
    return Observations(tuple(out), source)


def _position(site, where):
    """A site's position as ("km", east, north) or ("geo", latitude, longitude)."""
    has_km = "east_km" in site or "north_km" in site
    has_geo = "latitude" in site or "longitude" in site
    if has_km == has_geo:
        raise InputError(f"{where}: give either east_km and north_km or latitude and "
                         "longitude")
    if has_km:
        if "east_km" not in site or "north_km" not in site:
            raise InputError(f"{where}: needs both east_km and north_km")
        return ("km", _number(site["east_km"], f"{where}: east_km", -1e4, 1e4),
                _number(site["north_km"], f"{where}: north_km", -1e4, 1e4))
    if "latitude" not in site or "longitude" not in site:
        raise InputError(f"{where}: needs both latitude and longitude")
    return ("geo", _number(site["latitude"], f"{where}: latitude", -90.0, 90.0),
            _number(site["longitude"], f"{where}: longitude", -180.0, 360.0))


def _local_sites(raw):
    """Sites in km East/North of the first one, from (name, position, columns) tuples
    whose positions are all in km or all in degrees (then via obspy's geodesic)."""
    out = []
    if raw[0][1][0] == "km":
        _, e0, n0 = raw[0][1]
        for name, (_, e, n), cols in raw:
            out.append(Site(name, e - e0, n - n0, cols))
    else:
        from obspy.geodetics import gps2dist_azimuth  # lazy: obspy is slow to import
        _, lat0, lon0 = raw[0][1]
        for name, (_, lat, lon), cols in raw:
            if (lat, lon) == (lat0, lon0):
                east = north = 0.0
            else:
                dist_m, az, _ = gps2dist_azimuth(lat0, lon0, lat, lon)
                east = dist_m / 1e3 * math.sin(math.radians(az))
                north = dist_m / 1e3 * math.cos(math.radians(az))
            out.append(Site(name, east, north, cols, lat, lon))
    return out


def load_observations(path):
    """Read and check an observations file; InputError (one line) for any problem, whatever
    the file holds: its size is checked before reading, its nesting right after parsing."""
    path = Path(path)
    try:
        found = path.is_file()
    except (OSError, ValueError):               # a name too long, a NUL byte
        found = False
    if not found:
        raise InputError(f"observations file not found: {path}")
    try:
        text = read_text(path)
    except OSError as exc:
        raise InputError(f"{path.name}: cannot be read ({exc.strerror or exc})") from None
    except _Unreadable as exc:
        if exc.kind == "size":
            raise InputError(f"{path.name}: {exc}; not an observations file") from None
        raise InputError(f"{path.name}: not a text (JSON) file ({exc})") from None
    try:
        data = json.loads(text, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path.name}: not valid JSON (line {exc.lineno}, column "
                         f"{exc.colno}: {exc.msg})") from None
    except _Unreadable as exc:
        raise InputError(f"{path.name}: {exc}; not an observations file") from None
    except RecursionError:                          # deeper than the parser goes
        deep = True
    else:
        deep = _nesting(data, MAX_NESTING) > MAX_NESTING
    if deep:
        raise InputError(f"{path.name}: nested more than {MAX_NESTING} levels deep; not an "
                         "observations file")
    return parse_observations(data, path.name)


