"""A hidden-truth test a user runs: a source they choose, twin columns simulated at their
sites, inverted with a forward table that never saw those runs.

The truth file (keys are a contract)::

    {"source": {"mechanism": "strike-slip", "strike_deg": 30, "depth_km": 10, "mw": 6.5,
                "east_km": 4, "north_km": -3},
     "sites": [{"name": "A", "east_km": 0, "north_km": 0, "twins": 3}, ...],
     "seed": 7000001}

Positions are km East/North in any local frame; ``twins`` (1-50) is the number of twin
models at a site (each a drum column and a monolith, one ensemble member); ``seed``
(optional) the Latin hypercube's of the hidden members.  The motion at each site comes from
the forward table's own generator (pyprop8, the same sub-events, in the strike frame, at the
site's distance and azimuth from the strike: :func:`pipeline.inversion.grid.slice_motions`),
the members from the ensemble's sampling with the hidden seed, which no table batch uses
(a table's batches use seed, seed + 1, ...); the runs are the campaign
``inversion-truth``, cached by content like every run.  The fallen columns' downfall
azimuths (turned by the strike into geographic ones) and the standing columns become an
observations file (``observations.json``, the schema of
:mod:`pipeline.inversion.observations`), which ``invert`` inverts as any other.
"""
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pipeline.campaign import Campaign, register
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.campaign.tables import collect
from pipeline.files import InputError
from pipeline.inversion.grid import MECHANISMS, slice_motions
from pipeline.stats.circular import azimuth_deg
from pipeline.userfiles import read_json
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import number as _number
from pipeline.inversion.forward import MEMBER_BATCH, member_parameters

TRUTH_SEED = 7_000_001           # far beyond any table's seed + batch
MAX_TWINS = 50
SOURCE_KEYS = {"mechanism", "strike_deg", "depth_km", "mw", "east_km", "north_km"}
SITE_KEYS = {"name", "east_km", "north_km", "twins"}
TRUTH_KEYS = {"source", "sites", "seed"}
MAX_TRUTH_SITES = 100


@dataclass(frozen=True)
class HiddenTruth:
    """A chosen source (epicentre km East/North in the file's frame, strike deg clockwise
    from North) and the sites where twin models are simulated."""
    mechanism: str
    strike_deg: float
    depth_km: float
    mw: float
    east_km: float
    north_km: float
    sites: tuple            # (name, east_km, north_km, twins)
    seed: int = TRUTH_SEED

    @property
    def dip_rake(self):
        return MECHANISMS[self.mechanism]

    def strike_frame(self):
        """(distances km, azimuths from the strike deg) of the sites from the epicentre."""
        de = np.array([s[1] - self.east_km for s in self.sites])
        dn = np.array([s[2] - self.north_km for s in self.sites])
        return np.hypot(de, dn), np.mod(azimuth_deg(de, dn) - self.strike_deg, 360.0)

    def as_truth(self):
        """What the inversion should find, in its frame (km East/North of the first site;
        back azimuth from the first site to the epicentre)."""
        e = self.east_km - self.sites[0][1]
        n = self.north_km - self.sites[0][2]
        return {"epicentre_km": [e, n], "distance_km": math.hypot(e, n),
                "back_azimuth_deg": azimuth_deg(e, n),
                "mechanism": self.mechanism, "strike_deg": self.strike_deg,
                "depth_km": self.depth_km, "mw": self.mw}


def parse_truth(data, source="truth"):
    """:class:`HiddenTruth` from the parsed JSON ``data``; InputError (one line) if bad."""
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected an object with 'source' and 'sites'")
    unknown = set(data) - TRUTH_KEYS
    if unknown or "source" not in data or "sites" not in data:
        raise InputError(f"{source}: needs 'source' and 'sites' (and optionally 'seed')"
                         + (f"; unknown key(s) {_keys(unknown)}" if unknown else ""))
    src = data["source"]
    if not isinstance(src, dict) or set(src) != SOURCE_KEYS:
        raise InputError(f"{source}: 'source' needs exactly {', '.join(sorted(SOURCE_KEYS))}")
    if not isinstance(src["mechanism"], str) or src["mechanism"] not in MECHANISMS:
        raise InputError(f"{source}: source mechanism must be one of {', '.join(MECHANISMS)}, "
                         f"got {repr(src['mechanism'])[:60]}")
    where = f"{source}: source"
    values = {"strike_deg": _number(src["strike_deg"], f"{where} strike_deg", 0.0, 360.0),
              "depth_km": _number(src["depth_km"], f"{where} depth_km", 0.5, 40.0),
              "mw": _number(src["mw"], f"{where} mw", 4.5, 7.5),
              "east_km": _number(src["east_km"], f"{where} east_km", -1e3, 1e3),
              "north_km": _number(src["north_km"], f"{where} north_km", -1e3, 1e3)}
    sites = data["sites"]
    if not isinstance(sites, list) or not 1 <= len(sites) <= MAX_TRUTH_SITES:
        raise InputError(f"{source}: 'sites' must be a list of 1-{MAX_TRUTH_SITES} sites")
    parsed, names = [], set()
    for k, site in enumerate(sites):
        where = f"{source}: site {k + 1}"
        if not isinstance(site, dict) or set(site) != SITE_KEYS:
            raise InputError(f"{where}: needs exactly {', '.join(sorted(SITE_KEYS))}")
        name = site["name"]
        if not isinstance(name, str) or not name.strip() or name in names:
            raise InputError(f"{where}: 'name' must be a non-empty string of its own")
        names.add(name)
        twins = site["twins"]
        if isinstance(twins, bool) or not isinstance(twins, int) or \
                not 1 <= twins <= MAX_TWINS:
            raise InputError(f"{where}: twins must be an integer in [1, {MAX_TWINS}], got "
                             f"{twins!r}")
        e = _number(site["east_km"], f"{where}: east_km", -1e3, 1e3)
        n = _number(site["north_km"], f"{where}: north_km", -1e3, 1e3)
        distance = math.hypot(e - values["east_km"], n - values["north_km"])
        if not 0.05 <= distance <= 100.0:
            raise InputError(f"{where}: {distance:.2f} km from the epicentre; the generator "
                             "takes 0.05-100 km")
        for other, oe, on, _ in parsed:        # the observations file's rule, before any run
            if math.hypot(e - oe, n - on) < 1e-6:
                raise InputError(f"{source}: sites {other} and {name} are at the same place; "
                                 "give one site with more twins")
        parsed.append((name, e, n, twins))
    seed = data.get("seed", TRUTH_SEED)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 62:
        raise InputError(f"{source}: seed must be a non-negative integer, got {seed!r}")
    return HiddenTruth(src["mechanism"], sites=tuple(parsed), seed=seed, **values)


def load_truth(path):
    """Read a truth file; InputError (one line) for any problem."""
    path = Path(path)
    return parse_truth(read_json(path, "truth file"), path.name)


def truth_grid(truth, grid):
    """The forward grid of the truth's one slice, with the hidden members (the table's
    motion settings: duration, band, tail)."""
    twins = max(s[3] for s in truth.sites)
    return grid.replace(mechanisms=((truth.mechanism,) + truth.dip_rake,),
                        depths_km=(truth.depth_km,), magnitudes=(truth.mw,), members=twins,
                        nominal=False, seed=truth.seed, column_file=None)


def check_hidden(truth, table_grid):
    """InputError when the table's member batches could hold the hidden seed's members."""
    batches = -(-table_grid.members // MEMBER_BATCH)
    if table_grid.seed <= truth.seed < table_grid.seed + max(batches, 1):
        raise InputError(f"truth seed {truth.seed} is one of the forward table's member "
                         f"seeds ({table_grid.seed}-{table_grid.seed + batches - 1}): the "
                         "table would have seen these runs; choose another seed")


@dataclass(frozen=True)
class TruthTags:
    """A hidden-truth run: the ``site`` and its twin ``member``; the source's ``strike_deg``."""
    site: str
    member: int
    strike_deg: float


def truth_specs(records, campaign_dir, truth=None, grid=None, jobs=None):
    """Run specs: at every site its ``twins`` hidden members on the site's motion."""
    if records:
        raise InputError("the inversion-truth campaign takes no --records")
    if truth is None or grid is None:
        raise InputError("the inversion-truth campaign runs from `invert --hidden-truth "
                         "TRUTH.json`")
    tgrid = truth_grid(truth, grid)
    (paths,) = slice_motions(tgrid, Path(campaign_dir) / "motions", jobs,
                             positions=truth.strike_frame()).values()
    params = [p for m, p in member_parameters(tgrid) if m >= 0]
    runs, info = [], []
    for (name, _, _, twins), path in zip(truth.sites, paths):
        for member in range(twins):
            runs.append((str(path), params[member]))
            info.append(TruthTags(name, member, truth.strike_deg))
    return column_specs(runs, campaign_dir, info, keep_trajectory=False)


def truth_observations(specs, campaign_dir):
    """The observations dict of the finished runs: per site its columns fallen (downfall
    azimuth turned from the strike frame by the strike) or standing."""
    runs, _ = collect(specs, "inversion-truth", campaign_dir)
    site_of = {s.run_id: s.tags.site for s in specs}
    strike = specs[0].tags.strike_deg
    sites = {}
    for spec in specs:
        sites.setdefault(spec.tags.site, [])
    for _, row in runs.iterrows():
        cols = sites[site_of[row["run_id"]]]
        if row["toppled"] and math.isfinite(row["downfall_azimuth_deg"]):
            cols.append({"column": row["column"], "state": "fallen", "downfall_azimuth_deg":
                         round(float((row["downfall_azimuth_deg"] + strike) % 360.0), 3)})
        else:
            cols.append({"column": row["column"], "state": "standing"})
    return sites


def truth_outputs(specs, campaign_dir, failures, animations, figures=True):
    sites = truth_observations(specs, campaign_dir)
    return {"sites": sites}


register(Campaign("inversion-truth", "a hidden-truth test: twin models at chosen sites of a "
                  "chosen source (invert --hidden-truth)", truth_specs, run_column_spec,
                  truth_outputs, label="runs"))
