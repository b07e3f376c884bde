"""The forward table: per (mechanism, depth, magnitude, distance, azimuth relative to strike)
the ensemble's toppling outcomes, computed once and reused by every inversion.

Symmetries (laterally homogeneous layered half-space, cylindrical columns):

- translation: the motion depends on the offset from the epicentre to the site only, so one
  pyprop8 computation per (mechanism, depth, magnitude) with receivers on a polar grid
  (``distances_km`` x ``azimuths``) gives every source-site pair;
- rotation: turning the strike by phi turns the offset and the horizontal motion by phi,
  and a cylindrical column's response to a turned motion is the turned response (the rim
  discretisation, which breaks this, is sampled as noise by the ensemble), so the grid is
  computed for strike 0 (North) only: a node's ``azimuth`` is the site azimuth from the
  epicentre minus the strike, and a downfall azimuth stored in this *strike frame* becomes
  the geographic one by adding the strike.

Sources follow the synthetics stage (:mod:`pipeline.motion.synthetics`): a line of five
equal sub-events along strike at the hypocentre depth, rupturing from the hypocentre at
2.8 km/s with trapezoid moment-rate functions; at Mw 6.5 the layout is the paper
scenario's exactly, other magnitudes scale lengths and durations self-similarly
(x 10^(0.5 (Mw - 6.5)), L ~ M0^(1/3)).  The epicentre is the hypocentre's surface point.

Every node gets the nominal twin run (the paper's values) and ``members`` Latin-hypercube
members (:func:`pipeline.campaign.ensemble.sample_members`, one seed: member k has the same
column parameters at every node).  The runs are the campaign ``inversion-forward`` on the
executor, so they are cached by content (run id = hash of motion, parameters and code) and
a second inversion reuses every finished run.
"""
import dataclasses
import json
import math
import os
import time
from dataclasses import dataclass, field
from multiprocessing import Pool
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.constants import COLUMN_TYPES
from pipeline import RESULTS_DIR, files
from pipeline.campaign import Campaign, register
from pipeline.campaign.definitions import column_specs, run_code_version, run_column_spec
from pipeline.files import InputError, content_hash, die_with_parent, write_csv, write_json
from pipeline.motion import Motion

GENERATOR_VERSION = 1          # bump when the written motions change
DEFAULT_FORWARD_DIR = RESULTS_DIR / "inversion-forward"
COLUMNS = COLUMN_TYPES
REFERENCE_MW = 6.5             # the paper scenario's magnitude: the sub-event template's
TEMPLATE_SOURCE = "strike_slip"  # sub-event layout, rupture velocity, rise and duration
SAMPLING_HZ = 100.0

# name: (dip deg, rake deg); strike is a candidate dimension (table: strike 0)
MECHANISMS = {
    "strike-slip": (90.0, 180.0),   # vertical, right-lateral (the paper's strike-slip source)
    "thrust": (40.0, 90.0),         # the paper's thrust source
    "normal": (50.0, -90.0),        # an Andersonian normal fault
}


def parse_mechanisms(text):
    """Mechanisms from ``name[,name...]``; a name is one of MECHANISMS or NAME:DIP:RAKE."""
    items = [t.strip() if isinstance(t, str) else t
             for t in (text.split(",") if isinstance(text, str) else text)]
    items = [t for t in items if t != ""]
    if not items:
        raise InputError("--mechanisms: give at least one mechanism")
    out = []
    for item in items:
        if isinstance(item, (tuple, list)):
            name, dip, rake = item
        elif ":" in item:
            try:
                name, dip, rake = item.split(":")
                dip, rake = float(dip), float(rake)
            except ValueError:
                raise InputError(f"--mechanisms {item!r}: expected NAME:DIP:RAKE") from None
        elif item in MECHANISMS:
            name, (dip, rake) = item, MECHANISMS[item]
        else:
            raise InputError(f"--mechanisms: unknown mechanism {item!r} (known: "
                             f"{', '.join(MECHANISMS)}, or NAME:DIP:RAKE)")
        if not (0 < float(dip) <= 90 and -180 <= float(rake) <= 180):
            raise InputError(f"mechanism {name}: dip must be in (0, 90] and rake in "
                             f"[-180, 180], got {dip:g}, {rake:g}")
        out.append((str(name), float(dip), float(rake)))
    if len({m[0] for m in out}) != len(out):
        raise InputError("--mechanisms: a mechanism is named twice")
    return tuple(out)


@dataclass(frozen=True)
class TableGrid:
    """Nodes and ensemble of a forward table."""
    mechanisms: tuple = (("strike-slip",) + MECHANISMS["strike-slip"],
                         ("thrust",) + MECHANISMS["thrust"])
    depths_km: tuple = (10.0,)
    magnitudes: tuple = (6.5,)
    distances_km: tuple = (2.5, 5.0, 10.0, 20.0)
    azimuth_step_deg: float = 30.0
    members: int = 6
    nominal: bool = True
    seed: int = 20091001
    fmax_hz: float = 10.0
    duration_s: float = 20.0
    tail_s: float = 5.0
    column_file: dict = None    # a column description: the table of that column alone

    def __post_init__(self):
        object.__setattr__(self, "mechanisms", parse_mechanisms(self.mechanisms))
        if self.column_file is not None:
            from pipeline.campaign.column_file import description
            object.__setattr__(self, "column_file", description(self.column_file))
        for name in ("depths_km", "magnitudes", "distances_km"):
            values = tuple(sorted(float(v) for v in getattr(self, name)))
            if not values or len(set(values)) != len(values) or \
                    not all(math.isfinite(v) for v in values):
                raise InputError(f"forward grid: {name} must be distinct finite numbers, "
                                 f"got {getattr(self, name)}")
            object.__setattr__(self, name, values)
        if min(self.depths_km) <= 0 or max(self.depths_km) > 40:
            raise InputError(f"--depths must lie in (0, 40] km, got {self.depths_km}")
        if min(self.magnitudes) < 4.5 or max(self.magnitudes) > 7.5:
            raise InputError(f"--magnitudes must lie in [4.5, 7.5], got {self.magnitudes}")
        if min(self.distances_km) <= 0 or max(self.distances_km) > 100:
            raise InputError(f"--distances must lie in (0, 100] km, got {self.distances_km}")
        step = float(self.azimuth_step_deg)
        if not (0 < step <= 180 and abs(360.0 / step - round(360.0 / step)) < 1e-9):
            raise InputError(f"--azimuth-step must divide 360 (<= 180), got {step:g}")
        if not (isinstance(self.members, int) and 0 <= self.members <= 1000):
            raise InputError(f"--members must be an integer in [0, 1000], got {self.members!r}")
        if self.members == 0 and not self.nominal:
            raise InputError("a forward table needs members or the nominal run")
        if not (0.5 <= self.fmax_hz <= 20 and 5 <= self.duration_s <= 120
                and 0 <= self.tail_s <= 60):
            raise InputError(f"forward grid: fmax {self.fmax_hz:g} Hz (0.5-20), duration "
                             f"{self.duration_s:g} s (5-120), tail {self.tail_s:g} s (0-60)")

    @property
    def azimuths_deg(self):
        return np.arange(0.0, 360.0 - 1e-9, float(self.azimuth_step_deg))

    def slices(self):
        """(mechanism name, dip, rake, depth, mw) in table order."""
        return [(m[0], m[1], m[2], d, g) for m in self.mechanisms for d in self.depths_km
                for g in self.magnitudes]

    def n_runs(self):
        return (len(self.slices()) * len(self.distances_km) * len(self.azimuths_deg)
                * (self.members + int(self.nominal)))

    @property
    def columns(self):
        """Column roles of the table: the twin model's, or the described column alone
        (in the drums' role of its runs)."""
        return COLUMNS if self.column_file is None else COLUMNS[:1]

    def as_dict(self):
        out = {**dataclasses.asdict(self), "mechanisms": [list(m) for m in self.mechanisms]}
        if self.column_file is None:
            out.pop("column_file")      # the twin grids' keys stay as they were
        return out

    def key(self):
        return content_hash(self.as_dict())

    def replace(self, **changes):
        return dataclasses.replace(self, **{k: v for k, v in changes.items() if v is not None})


# Grid presets.  quick: a smoke run of a few minutes; demo: what `make invert-demo` runs on
# a 2-core machine (~700 runs); full: the default of `invert`.
GRIDS = {
    "quick": TableGrid(distances_km=(2.5, 6.0), azimuth_step_deg=90.0, members=2,
                       nominal=False, fmax_hz=5.0, duration_s=15.0, tail_s=3.0),
    "demo": TableGrid(members=6),
    "full": TableGrid(mechanisms=("strike-slip", "thrust", "normal"), depths_km=(6.0, 12.0),
                      magnitudes=(6.5, 7.0), distances_km=(2.5, 5.0, 10.0, 20.0, 30.0),
                      members=8),
}


# ---------------------------------------------------------------- motions (pyprop8)
def subevent_layout(mw):
    """Sub-events of a source of magnitude ``mw`` with strike 0 (North) and its hypocentre
    at the origin: list of dicts x_km, y_km, delay_s, m0_nm, rise_s, duration_s."""
    from pipeline.motion.synthetics import SOURCES, moment_from_mw
    template = SOURCES[TEMPLATE_SOURCE]
    scale = 10.0 ** (0.5 * (mw - REFERENCE_MW))
    along = np.asarray(template["subevents_along_strike_km"], float) * scale
    return [{"x_km": 0.0, "y_km": float(a), "delay_s": float(abs(a) /
                                                              template["rupture_velocity_km_s"]),
             "m0_nm": moment_from_mw(mw) / len(along),
             "rise_s": template["subevent_rise_s"] * scale,
             "duration_s": template["subevent_duration_s"] * scale} for a in along]


def node_positions(grid):
    """(distance, azimuth) of every node and receiver x, y (km, strike frame), node order."""
    r, a = np.meshgrid(grid.distances_km, grid.azimuths_deg, indexing="ij")
    r, a = r.ravel(), a.ravel()
    return r, a, r * np.sin(np.radians(a)), r * np.cos(np.radians(a))


def _slice_key(grid, sl, num):
    from pipeline.motion.synthetics import CRUST_LAYERS, LEAD_TIME_S
    return content_hash(GENERATOR_VERSION, list(sl), subevent_layout(sl[4]), CRUST_LAYERS,
                        LEAD_TIME_S, grid.distances_km, float(grid.azimuth_step_deg),
                        grid.fmax_hz, grid.duration_s, SAMPLING_HZ, num)


def _slice_tag(sl):
    name, _, _, depth, mw = sl
    return f"{name}_z{depth:g}_m{mw:g}"


def _node_name(sl, key, r, a):
    return f"{_slice_tag(sl)}_{key[:6]}_r{r:g}_t{a:05.1f}"


def slice_motions(grid, motion_dir, jobs=None):
    """Compute (or reuse) the node motions of every slice; {slice: [npz paths in node
    order]}.  A slice is recomputed only when its manifest's key (hash of every parameter)
    differs or a file is missing; the pyprop8 calls of all slices share ``jobs`` processes."""
    from pipeline.motion.synthetics import numerics
    num = numerics(grid.duration_s, SAMPLING_HZ, grid.fmax_hz)
    r, a, x, y = node_positions(grid)
    out, tasks, todo = {}, [], []
    for sl in grid.slices():
        key = _slice_key(grid, sl, num)
        directory = Path(motion_dir) / f"{_slice_tag(sl)}_{key}"
        paths = [directory / f"{_node_name(sl, key, ri, ai)}.npz" for ri, ai in zip(r, a)]
        out[sl] = paths
        manifest = directory / "manifest.json"
        if manifest.is_file() and all(p.is_file() for p in paths) and \
                json.loads(manifest.read_text()).get("key") == key:
            continue
        todo.append((sl, key, directory, paths))
        for sub in subevent_layout(sl[4]):
            # a receiver right above a sub-event: pyprop8 divides by the horizontal
            # distance; 1 m aside the field is the same to far below the model's resolution
            above = np.hypot(x - sub["x_km"], y - sub["y_km"]) < 1e-3
            tasks.append((np.where(above, x + 1e-3, x), y, (0.0, sl[1], sl[2]),
                          dict(sub, depth_km=sl[3]), num, grid.fmax_hz))
    if not todo:
        return out
    from pipeline.motion.synthetics.compute import _point_source_task
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(tasks)))
    started = time.monotonic()
    print(f"inversion-forward: pyprop8 for {len(todo)} source slice(s), {len(r)} receivers, "
          f"{len(tasks)} sub-events on {jobs} process(es)", flush=True)
    if jobs > 1:
        with Pool(jobs, initializer=die_with_parent) as pool:
            results = pool.map(_point_source_task, tasks)      # in order: reproducible sums
    else:
        results = [_point_source_task(t) for t in tasks]
    elapsed = time.monotonic() - started
    per_slice = len(tasks) // len(todo)
    for k, (sl, key, directory, paths) in enumerate(todo):
        total = sum(results[k * per_slice:(k + 1) * per_slice])
        _write_slice(grid, sl, key, directory, paths, total, num, r, a, elapsed / len(todo))
    return out


def _write_slice(grid, sl, key, directory, paths, total, num, r, a, seconds):
    from pipeline.motion.synthetics import LEAD_TIME_S, band_limited_motion
    (directory / "manifest.json").unlink(missing_ok=True)
    name, dip, rake, depth, mw = sl
    for i, path in enumerate(paths):
        acc, vel, disp = band_limited_motion(total[i].T, num["dt_calc"], num["upsample"])
        meta = {
            "record_id": path.stem,
            "label": f"inversion node {name} z={depth:g} km Mw {mw:g} r={r[i]:g} km "
                     f"az-strike={a[i]:g}",
            "event": f"synthetic {name} Mw {mw:g} (strike 0: the table's strike frame)",
            "station": path.stem, "magnitude": mw, "mechanism": name,
            "back_azimuth_deg": float((a[i] + 180.0) % 360.0),
            "epicentral_distance_km": float(r[i]),
            "back_azimuth_source": "exact: node geometry in the strike frame (North = strike)",
            "has_vertical": True, "horizontals_compass": True, "orientation": "ENU",
            "frame": "strike frame: North is the strike direction, epicentre at the origin",
            "inversion_node": {"mechanism": name, "dip_deg": dip, "rake_deg": rake,
                               "depth_km": depth, "mw": mw, "distance_km": float(r[i]),
                               "azimuth_from_strike_deg": float(a[i])},
            "units": {"dt": "s", "acc": "m/s^2", "vel": "m/s", "disp": "m"},
            "columns": ["East", "North", "Up"],
            "processing": {"generator": "pyprop8 (pipeline.inversion.forward)",
                           "freqmin_hz": 0.0, "freqmax_hz": grid.fmax_hz,
                           "lead_time_s": LEAD_TIME_S, "duration_s": grid.duration_s, **num,
                           "cache_key": key, "version": GENERATOR_VERSION},
        }
        Motion(1.0 / SAMPLING_HZ, acc, vel, disp, meta=meta).save(path)
    write_json(directory / "manifest.json", {
        "key": key, "slice": list(sl), "subevents": subevent_layout(mw),
        "distances_km": list(grid.distances_km), "azimuth_step_deg": grid.azimuth_step_deg,
        "fmax_hz": grid.fmax_hz, "duration_s": grid.duration_s, "numerics": num,
        "compute_seconds": round(seconds, 1), "nodes": [p.name for p in paths]})


# ---------------------------------------------------------------- runs (campaign)
MEMBER_BATCH = 6    # members are drawn in Latin-hypercube batches of 6 (seeds seed, seed + 1,
#                     ...): a grown ensemble keeps its first members, so their runs are reused


def member_parameters(grid):
    """[(member, params)]: member -1 is the nominal twin run, 0.. the ensemble members
    (batch b of MEMBER_BATCH members: Latin hypercube with seed ``grid.seed + b``)."""
    from pipeline.campaign.column_file import column_kn
    from pipeline.campaign.ensemble import nominal, sample_members
    if grid.column_file is None:
        column, described = "both", {}
    else:                   # the described column alone, stiffness as in `campaign columns`
        column = "drums"
        described = {"description": grid.column_file,
                     "kn": column_kn(grid.column_file, "matched")}
    runs = [(-1, nominal(column, **described))] if grid.nominal else []
    for b, first in enumerate(range(0, grid.members, MEMBER_BATCH)):
        size = min(MEMBER_BATCH, grid.members - first)
        runs += list(enumerate(sample_members(size, grid.seed + b, column=column,
                                              **described), first))
    return [(m, {**p, "tail_s": float(grid.tail_s)}) for m, p in runs]


def forward_specs(records, campaign_dir, grid=None, jobs=None, **_):
    """Run specs of a forward table: every node x (nominal + members), twin model."""
    if records:
        raise InputError("the inversion-forward campaign takes no --records (see --grid)")
    grid = grid or GRIDS["full"]
    motions = slice_motions(grid, Path(campaign_dir) / "motions", jobs)
    r, a, _, _ = node_positions(grid)
    params = member_parameters(grid)
    runs, info = [], []
    for s, sl in enumerate(grid.slices()):
        for node, path in enumerate(motions[sl]):
            for member, p in params:
                runs.append((str(path), p))
                info.append({"slice": s, "node": node, "member": member,
                             "distance_km": float(r[node]), "azimuth_deg": float(a[node])})
    specs = column_specs(runs, campaign_dir)
    for spec, extra in zip(specs, info):
        spec.update(extra, keep_trajectory=False, grid=grid.as_dict())
    return specs


def table_path(campaign_dir, grid):
    return Path(campaign_dir) / "tables" / f"forward_table_{grid.key()}.npz"


def forward_outputs(specs, campaign_dir, failures, animations, figures=True):
    """Collect the finished runs of ``specs`` into the table file (tables/forward_table_<grid
    key>.npz) and its per-node summary (tables/forward_cells_<grid key>.csv)."""
    grid = TableGrid(**specs[0]["grid"])
    table = ForwardTable.from_runs(specs, campaign_dir, grid)
    path = table_path(campaign_dir, grid)
    table.save(path)
    write_csv(path.with_name(f"forward_cells_{grid.key()}.csv"), table.cells())
    done = int(table.valid.any(axis=3).sum() + (table.nominal_valid.any(axis=3).sum()
                                                 if table.nominal_valid is not None else 0))
    print(f"wrote {path} ({done} of {len(specs)} runs finished; YADE wall "
          f"{table.info['yade_wall_s']:.0f} s in total)")
    return {"table": str(path), "grid": grid.as_dict(), "grid_key": grid.key(),
            "runs_finished": done}


def run_forward(grid, campaign_dir=None, jobs=None, scheduler=None):
    """Run (or reuse) the forward campaign of ``grid``; return (ForwardTable, cost dict)."""
    from pipeline.campaign import run_campaign
    campaign_dir = Path(campaign_dir or DEFAULT_FORWARD_DIR)
    extra = {"scheduler": scheduler} if scheduler else {}
    started = time.monotonic()
    result = run_campaign("inversion-forward", jobs=jobs, campaign_dir=campaign_dir,
                          animations=0, options={"grid": grid, "jobs": jobs}, **extra)
    table = ForwardTable.load(result["table"])
    cost = {"runs": grid.n_runs(), "elapsed_s": round(time.monotonic() - started, 1),
            "yade_wall_s": table.info["yade_wall_s"], "table": result["table"]}
    return table, cost


def _forward_options(parser):
    parser.add_argument("--grid", choices=sorted(GRIDS), default="full",
                        help="forward grid preset (see python -m pipeline invert --help)")


def _read_forward_options(args):
    return {"grid": GRIDS[args.grid], "jobs": args.jobs}


register(Campaign("inversion-forward", "forward table of the source inversion: twin-model "
                  "ensembles at (mechanism, depth, magnitude, distance, azimuth from strike)",
                  forward_specs, run_column_spec, forward_outputs, label="runs",
                  options=_forward_options, read_options=_read_forward_options))


# ---------------------------------------------------------------- the table
@dataclass
class ForwardTable:
    """Outcomes at the nodes, all azimuths in the strike frame (strike = North).

    Arrays are indexed [slice, distance, azimuth, column, member]; ``toppled`` and
    ``valid`` (the run finished) are bool, ``azimuth_deg`` the downfall azimuth (NaN when
    standing).  ``nominal_*`` hold the nominal twin run ([slice, distance, azimuth,
    column]; None without).  ``slices``: dicts mechanism, dip_deg, rake_deg, depth_km, mw.
    """
    slices: list
    distances_km: np.ndarray
    azimuths_deg: np.ndarray
    members: np.ndarray
    toppled: np.ndarray
    azimuth_deg: np.ndarray
    valid: np.ndarray
    columns: tuple = COLUMNS
    nominal_toppled: np.ndarray = None
    nominal_azimuth_deg: np.ndarray = None
    nominal_valid: np.ndarray = None
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        self.distances_km = np.asarray(self.distances_km, float)
        self.azimuths_deg = np.asarray(self.azimuths_deg, float)
        self.members = np.asarray(self.members, int)
        shape = (len(self.slices), len(self.distances_km), len(self.azimuths_deg),
                 len(self.columns), len(self.members))
        for name in ("toppled", "azimuth_deg", "valid"):
            value = np.asarray(getattr(self, name))
            if value.shape != shape:
                raise InputError(f"forward table: {name} has shape {value.shape}, "
                                 f"expected {shape}")
            setattr(self, name, value)
        self.toppled = self.toppled.astype(bool) & self.valid.astype(bool)
        self.valid = self.valid.astype(bool)
        self.azimuth_deg = np.where(self.toppled, np.mod(self.azimuth_deg.astype(float), 360.0),
                                    np.nan)
        steps = np.diff(np.r_[self.azimuths_deg, self.azimuths_deg[0] + 360.0])
        if len(self.azimuths_deg) < 2 or not np.allclose(steps, steps[0]) or \
                abs(self.azimuths_deg[0]) > 1e-9:
            raise InputError("forward table: node azimuths must be evenly spaced from 0 "
                             "(at least two)")
        if np.any(np.diff(self.distances_km) <= 0):
            raise InputError("forward table: distances must increase")

    # -------------------------------------------------------------- construction
    @classmethod
    def from_runs(cls, specs, campaign_dir, grid):
        runs_dir = Path(campaign_dir) / "runs"
        sl = grid.slices()
        members = np.arange(grid.members)
        columns = grid.columns
        shape = (len(sl), len(grid.distances_km), len(grid.azimuths_deg), len(columns))
        top = np.zeros(shape + (len(members),), bool)
        az = np.full(shape + (len(members),), np.nan)
        valid = np.zeros(shape + (len(members),), bool)
        ntop, naz, nval = np.zeros(shape, bool), np.full(shape, np.nan), np.zeros(shape, bool)
        wall, simulated = 0.0, 0
        na = len(grid.azimuths_deg)
        for spec in specs:
            path = runs_dir / spec["run_id"] / "summary.json"
            if not path.exists():
                continue
            summary = json.loads(path.read_text())
            wall += float(summary.get("wall_s") or 0.0)
            simulated += bool(summary.get("simulated", True))
            i, j = divmod(spec["node"], na)
            for col in summary["columns"]:
                c = columns.index(col["column"])
                fell = bool(col["toppled"]) and col["downfall_azimuth_deg"] is not None
                value = col["downfall_azimuth_deg"] if fell else np.nan
                index = (spec["slice"], i, j, c)
                if spec["member"] < 0:
                    ntop[index], naz[index], nval[index] = fell, value, True
                else:
                    top[index + (spec["member"],)] = fell
                    az[index + (spec["member"],)] = value
                    valid[index + (spec["member"],)] = True
        slices = [{"mechanism": s[0], "dip_deg": s[1], "rake_deg": s[2], "depth_km": s[3],
                   "mw": s[4]} for s in sl]
        return cls(slices, grid.distances_km, grid.azimuths_deg, members, top, az, valid,
                   columns, ntop if grid.nominal else None, naz if grid.nominal else None,
                   nval if grid.nominal else None,
                   info={"grid": grid.as_dict(), "grid_key": grid.key(),
                         "yade_wall_s": round(wall, 1), "runs": len(specs),
                         "simulated_runs": simulated,
                         "code_version": _code_version()})

    @classmethod
    def toy(cls, slices, distances_km, azimuths_deg, falls, columns=COLUMNS, info=None):
        """A table from ``falls[s][i][j][c]`` = list of downfall azimuths (strike frame) or
        None for standing members (tests and examples)."""
        n_members = max(len(m) for a in falls for b in a for c in b for m in c)
        shape = (len(slices), len(distances_km), len(azimuths_deg), len(columns), n_members)
        top, az, valid = np.zeros(shape, bool), np.full(shape, np.nan), np.zeros(shape, bool)
        for index in np.ndindex(shape[:4]):
            outcomes = falls[index[0]][index[1]][index[2]][index[3]]
            for k, value in enumerate(outcomes):
                valid[index + (k,)] = True
                if value is not None:
                    top[index + (k,)], az[index + (k,)] = True, value
        slices = [dict(s) if isinstance(s, dict) else
                  {"mechanism": s[0], "dip_deg": s[1], "rake_deg": s[2], "depth_km": s[3],
                   "mw": s[4]} for s in slices]
        return cls(slices, distances_km, azimuths_deg, np.arange(n_members), top, az, valid,
                   tuple(columns), info=dict(info or {"toy": True}))

    def with_column(self, name, other):
        """This table and the first column of ``other`` (same slices, nodes and members,
        e.g. a described column's table) as column ``name``."""
        same = (self.slices == other.slices
                and np.array_equal(self.distances_km, other.distances_km)
                and np.array_equal(self.azimuths_deg, other.azimuths_deg)
                and np.array_equal(self.members, other.members)
                and (self.nominal_toppled is None) == (other.nominal_toppled is None))
        if not same:
            raise InputError(f"forward table of {name}: its grid differs from the main "
                             "table's (slices, rings, azimuths, members, nominal run)")
        if name in self.columns:
            raise InputError(f"forward table: column {name!r} is there already")

        def join(a, b):
            return None if a is None else np.concatenate([a, b[..., :1]], axis=3)

        def join_members(a, b):
            return np.concatenate([a, b[:, :, :, :1, :]], axis=3)

        return dataclasses.replace(
            self, columns=tuple(self.columns) + (name,),
            toppled=join_members(self.toppled, other.toppled),
            azimuth_deg=join_members(self.azimuth_deg, other.azimuth_deg),
            valid=join_members(self.valid, other.valid),
            nominal_toppled=join(self.nominal_toppled, other.nominal_toppled),
            nominal_azimuth_deg=join(self.nominal_azimuth_deg, other.nominal_azimuth_deg),
            nominal_valid=join(self.nominal_valid, other.nominal_valid),
            info={**self.info, "described_columns": {
                **self.info.get("described_columns", {}),
                name: {k: other.info.get(k) for k in ("grid_key", "yade_wall_s", "runs",
                                                      "code_version")}}})

    def select_members(self, mask):
        """A table with the members where ``mask`` (bool over ``members``) holds."""
        mask = np.asarray(mask, bool)
        return dataclasses.replace(self, members=self.members[mask],
                                   toppled=self.toppled[..., mask],
                                   azimuth_deg=self.azimuth_deg[..., mask],
                                   valid=self.valid[..., mask], info=dict(self.info))

    def select_slices(self, keep):
        """A table with the slices where ``keep`` (bool over ``slices``) holds."""
        keep = np.asarray(keep, bool)
        if not keep.any():
            raise InputError("no forward-table slice matches the chosen mechanisms, depths "
                             "and magnitudes")

        def pick(values):
            return None if values is None else values[keep]

        return dataclasses.replace(
            self, slices=[s for s, k in zip(self.slices, keep) if k],
            toppled=self.toppled[keep], azimuth_deg=self.azimuth_deg[keep],
            valid=self.valid[keep], nominal_toppled=pick(self.nominal_toppled),
            nominal_azimuth_deg=pick(self.nominal_azimuth_deg),
            nominal_valid=pick(self.nominal_valid), info=dict(self.info))

    # -------------------------------------------------------------- file
    def save(self, path):
        arrays = {"distances_km": self.distances_km, "azimuths_deg": self.azimuths_deg,
                  "members": self.members, "toppled": self.toppled,
                  "azimuth_deg": self.azimuth_deg, "valid": self.valid}
        if self.nominal_toppled is not None:
            arrays.update(nominal_toppled=self.nominal_toppled,
                          nominal_azimuth_deg=self.nominal_azimuth_deg,
                          nominal_valid=self.nominal_valid)
        meta = {"slices": self.slices, "columns": list(self.columns), "info": self.info,
                "frame": "downfall azimuths in the strike frame (strike = North); node "
                         "azimuth = site azimuth from the epicentre minus the strike"}
        files.write_npz(path, meta=np.array(json.dumps(meta)), **arrays)
        return Path(path)

    @classmethod
    def load(cls, path):
        path = Path(path)
        if not path.is_file():
            raise InputError(f"forward table not found: {path}")
        try:
            with np.load(path, allow_pickle=False) as archive:
                data = {k: archive[k] for k in archive.files}
            meta = json.loads(str(data.pop("meta")))
        except (ValueError, OSError, EOFError, KeyError):
            raise InputError(f"{path.name}: not a forward table (npz with meta)") from None
        try:
            return cls(meta["slices"], data["distances_km"], data["azimuths_deg"],
                       data["members"], data["toppled"], data["azimuth_deg"], data["valid"],
                       tuple(meta["columns"]), data.get("nominal_toppled"),
                       data.get("nominal_azimuth_deg"), data.get("nominal_valid"),
                       info=meta.get("info", {}))
        except KeyError as exc:
            raise InputError(f"{path.name}: forward table lacks {exc}") from None

    # -------------------------------------------------------------- views
    def slice_index(self, mechanism, depth_km=None, mw=None):
        for k, s in enumerate(self.slices):
            if s["mechanism"] == mechanism and (depth_km is None or s["depth_km"] == depth_km) \
                    and (mw is None or s["mw"] == mw):
                return k
        raise KeyError((mechanism, depth_km, mw))

    def cells(self):
        """One row per node and column: members, toppled, P (k/n), mean downfall azimuth
        in the strike frame and relative to the direction from epicentre to site."""
        from pipeline.stats.circular import circular_summary
        rows = []
        for index in np.ndindex(self.toppled.shape[:4]):
            s, i, j, c = index
            valid, fell = self.valid[index], self.toppled[index]
            az = self.azimuth_deg[index][fell]
            stats = circular_summary(az)
            rel = circular_summary((az - self.azimuths_deg[j]) % 360.0)
            row = {**self.slices[s], "distance_km": self.distances_km[i],
                   "azimuth_from_strike_deg": self.azimuths_deg[j],
                   "column": self.columns[c], "members": int(valid.sum()),
                   "toppled": int(fell.sum()),
                   "p_toppled": float(fell.sum() / valid.sum()) if valid.any() else np.nan,
                   "mean_downfall_strike_frame_deg": stats["mean_deg"],
                   "mean_downfall_from_site_direction_deg": rel["mean_deg"],
                   "resultant_length": stats["resultant_length"]}
            if self.nominal_toppled is not None:
                row["nominal_toppled"] = bool(self.nominal_toppled[index]) \
                    if self.nominal_valid[index] else None
                row["nominal_downfall_strike_frame_deg"] = self.nominal_azimuth_deg[index]
            rows.append(row)
        return pd.DataFrame(rows)


def _code_version():
    return run_code_version()
