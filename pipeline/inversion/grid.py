"""The forward table's grid: mechanisms, depths, magnitudes and the polar grid of sites
around the epicentre (:class:`TableGrid`; its presets in :mod:`pipeline.inversion.presets`),
and the pyprop8 motions at its nodes (:func:`slice_motions`).  Symmetries and sources:
:mod:`pipeline.inversion.forward`."""
import dataclasses
import json
import logging
import math
import os
import time
from dataclasses import dataclass
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from pipeline.constants import COLUMN_TYPES
from pipeline.files import InputError, content_hash, die_with_parent, write_json
from pipeline.motion import Motion
from pipeline.motion.synthetics import CRUST_LAYERS, LEAD_TIME_S, SOURCES, moment_from_mw, numerics
from pipeline.motion.synthetics.compute import _point_source_task
from pipeline.campaign.column_file import description
from pipeline.motion.synthetics import band_limited_motion

log = logging.getLogger(__name__)

GENERATOR_VERSION = 1          # bump when the written motions change
REFERENCE_MW = 6.5             # the paper scenario's magnitude: the sub-event template's
TEMPLATE_SOURCE = "strike_slip"  # sub-event layout, rupture velocity, rise and duration
SAMPLING_HZ = 100.0

# name: (dip deg, rake deg); strike is a candidate dimension (table: strike 0)
MECHANISMS = {
    "strike-slip": (90.0, 180.0),   # vertical, right-lateral (the paper's strike-slip source)
    "thrust": (40.0, 90.0),         # the paper's thrust source
    "normal": (50.0, -90.0),        # an Andersonian normal fault
}

# the forward grid's ranges (the invert options' too: pipeline.inversion.grid_options)
DEPTH_KM = (0.0, 40.0)           # hypocentre depths, above 0
MAGNITUDE = (4.5, 7.5)           # moment magnitudes
DISTANCE_KM = (0.0, 100.0)       # the table's rings, above 0
MAX_AZIMUTH_STEP_DEG = 180.0     # the table's azimuth step, which divides 360
MEMBERS = (0, 1000)              # ensemble members per node
FMAX_HZ = (0.5, 20.0)            # the synthetics' highest frequency
DURATION_S = (5.0, 120.0)        # the synthetics' duration


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
            object.__setattr__(self, "column_file", description(self.column_file))
        for name in ("depths_km", "magnitudes", "distances_km"):
            values = tuple(sorted(float(v) for v in getattr(self, name)))
            if not values or len(set(values)) != len(values) or \
                    not all(math.isfinite(v) for v in values):
                raise InputError(f"forward grid: {name} must be distinct finite numbers, "
                                 f"got {getattr(self, name)}")
            object.__setattr__(self, name, values)
        if min(self.depths_km) <= DEPTH_KM[0] or max(self.depths_km) > DEPTH_KM[1]:
            raise InputError(f"--depths must lie in ({DEPTH_KM[0]:g}, {DEPTH_KM[1]:g}] km, "
                             f"got {self.depths_km}")
        if min(self.magnitudes) < MAGNITUDE[0] or max(self.magnitudes) > MAGNITUDE[1]:
            raise InputError(f"--magnitudes must lie in [{MAGNITUDE[0]:g}, {MAGNITUDE[1]:g}], "
                             f"got {self.magnitudes}")
        if min(self.distances_km) <= DISTANCE_KM[0] or max(self.distances_km) > DISTANCE_KM[1]:
            raise InputError(f"--distances must lie in ({DISTANCE_KM[0]:g}, "
                             f"{DISTANCE_KM[1]:g}] km, got {self.distances_km}")
        step = float(self.azimuth_step_deg)
        if not (0 < step <= MAX_AZIMUTH_STEP_DEG and
                abs(360.0 / step - round(360.0 / step)) < 1e-9):
            raise InputError(f"--azimuth-step must divide 360 (<= {MAX_AZIMUTH_STEP_DEG:g}), "
                             f"got {step:g}")
        if not (isinstance(self.members, int) and MEMBERS[0] <= self.members <= MEMBERS[1]):
            raise InputError(f"--members must be an integer in [{MEMBERS[0]}, {MEMBERS[1]}], "
                             f"got {self.members!r}")
        if self.members == 0 and not self.nominal:
            raise InputError("a forward table needs members or the nominal run")
        if not (FMAX_HZ[0] <= self.fmax_hz <= FMAX_HZ[1]
                and DURATION_S[0] <= self.duration_s <= DURATION_S[1]
                and 0 <= self.tail_s <= 60):
            raise InputError(f"forward grid: fmax {self.fmax_hz:g} Hz ({FMAX_HZ[0]:g}-"
                             f"{FMAX_HZ[1]:g}), duration {self.duration_s:g} s ({DURATION_S[0]:g}"
                             f"-{DURATION_S[1]:g}), tail {self.tail_s:g} s (0-60)")

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
        return COLUMN_TYPES if self.column_file is None else COLUMN_TYPES[:1]

    def as_dict(self):
        out = {**dataclasses.asdict(self), "mechanisms": [list(m) for m in self.mechanisms]}
        if self.column_file is None:
            out.pop("column_file")      # the twin grids' keys stay as they were
        return out

    def key(self):
        return content_hash(self.as_dict())

    def replace(self, **changes):
        return dataclasses.replace(self, **{k: v for k, v in changes.items() if v is not None})


# ---------------------------------------------------------------- motions (pyprop8)
def subevent_layout(mw):
    """Sub-events of a source of magnitude ``mw`` with strike 0 (North) and its hypocentre
    at the origin: list of dicts x_km, y_km, delay_s, m0_nm, rise_s, duration_s."""
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
    return content_hash(GENERATOR_VERSION, list(sl), subevent_layout(sl[4]), CRUST_LAYERS,
                        LEAD_TIME_S, grid.distances_km, float(grid.azimuth_step_deg),
                        grid.fmax_hz, grid.duration_s, SAMPLING_HZ, num)


def _slice_tag(sl):
    name, _, _, depth, mw = sl
    return f"{name}_z{depth:g}_m{mw:g}"


def _node_name(sl, key, r, a):
    return f"{_slice_tag(sl)}_{key[:6]}_r{r:g}_t{a:05.1f}"


def slice_motions(grid, motion_dir, jobs=None, positions=None):
    """Compute (or reuse) the node motions of every slice; {slice: [npz paths in node
    order]}.  A slice is recomputed only when its manifest's key (hash of every parameter)
    differs or a file is missing; the pyprop8 calls of all slices share ``jobs`` processes.
    ``positions``: (distances km, azimuths from strike deg) of receivers instead of the
    grid's nodes (a hidden-truth test's sites, :mod:`pipeline.inversion.truth`)."""
    num = numerics(grid.duration_s, SAMPLING_HZ, grid.fmax_hz)
    if positions is None:
        r, a, x, y = node_positions(grid)
    else:
        r, a = (np.asarray(v, float) for v in positions)
        x, y = r * np.sin(np.radians(a)), r * np.cos(np.radians(a))
    out, tasks, todo = {}, [], []
    for sl in grid.slices():
        key = _slice_key(grid, sl, num)
        if positions is not None:
            key = content_hash(key, r.round(9).tolist(), a.round(9).tolist())
        directory = Path(motion_dir) / f"{_slice_tag(sl)}_{key}"
        paths = [directory / (f"{_node_name(sl, key, ri, ai)}.npz" if positions is None
                              else f"{_slice_tag(sl)}_{key[:6]}_site{k:03d}.npz")
                 for k, (ri, ai) in enumerate(zip(r, a))]
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
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(tasks)))
    started = time.monotonic()
    log.info(f"inversion-forward: pyprop8 for {len(todo)} source slice(s), {len(r)} receivers, "
             f"{len(tasks)} sub-events on {jobs} process(es)")
    if jobs > 1:
        with Pool(jobs, initializer=die_with_parent, initargs=(os.getpid(),)) as pool:
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
