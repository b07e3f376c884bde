"""The forward table (:class:`ForwardTable`): the ensemble's outcomes at every node of a
grid (:mod:`pipeline.inversion.grid`), from the finished runs of the campaign
``inversion-forward`` (:mod:`pipeline.inversion.forward`), saved and loaded as one npz."""
import dataclasses
import io
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import files
from pipeline.simulate import run_code_version
from pipeline.campaign.run_dirs import finished_runs
from pipeline.constants import COLUMN_TYPES as COLUMNS
from pipeline.files import InputError
from pipeline.stats.circular import circular_summary
from pipeline.userfiles import read_user_bytes

# the runs' arrays: the members' [slice, distance, azimuth, column, member], the nominal
# run's [slice, distance, azimuth, column] (None without one)
OUTCOMES = ("toppled", "azimuth_deg", "valid", "nominal_toppled", "nominal_azimuth_deg",
            "nominal_valid")


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
        for spec, summary in finished_runs(campaign_dir, specs):
            wall += summary.wall_s
            simulated += summary.simulated
            i, j = divmod(spec.tags.node, na)
            for col in summary.columns:
                c = columns.index(col.column)
                fell = col.toppled and col.downfall_azimuth_deg is not None
                value = col.downfall_azimuth_deg if fell else np.nan
                index = (spec.tags.slice, i, j, c)
                if spec.tags.member < 0:
                    ntop[index], naz[index], nval[index] = fell, value, True
                else:
                    top[index + (spec.tags.member,)] = fell
                    az[index + (spec.tags.member,)] = value
                    valid[index + (spec.tags.member,)] = True
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

        def join(a, b):                   # b's first column after a's columns (axis 3)
            return np.concatenate([a, b[:, :, :, :1]], axis=3)

        return dataclasses.replace(
            self, columns=tuple(self.columns) + (name,), **self._outcomes(join, other),
            info={**self.info, "described_columns": {
                **self.info.get("described_columns", {}),
                name: {k: other.info.get(k) for k in ("grid_key", "yade_wall_s", "runs",
                                                      "code_version")}}})

    def with_rings(self, other, grid):
        """This table and ``other``'s rings in one table of ``grid`` (a
        :class:`~pipeline.inversion.grid.TableGrid` whose rings are both tables' rings): the
        same slices, node azimuths, columns, members and nominal runs, other rings.  The info
        keeps each part's grid key, code version and YADE time (``parts``)."""
        same = (self.slices == other.slices
                and np.array_equal(self.azimuths_deg, other.azimuths_deg)
                and tuple(self.columns) == tuple(other.columns)
                and np.array_equal(self.members, other.members)
                and (self.nominal_toppled is None) == (other.nominal_toppled is None))
        if not same:
            raise InputError("forward tables to join: they differ in more than their rings "
                             "(slices, node azimuths, columns, members or nominal run)")
        distances = np.r_[self.distances_km, other.distances_km]
        if len(np.unique(distances)) < len(distances):
            raise InputError("forward tables to join share a ring: "
                             f"{sorted(set(self.distances_km) & set(other.distances_km))} km")
        if sorted(distances.tolist()) != [float(d) for d in grid.distances_km]:
            raise InputError(f"forward tables to join: rings {sorted(distances.tolist())} km "
                             f"are not the grid's {list(grid.distances_km)} km")
        order = np.argsort(distances)

        def join(a, b):
            return np.concatenate([a, b], axis=1)[:, order]

        parts = [part for table in (self, other)
                 for part in table.info.get("parts", [_part_info(table)])]
        return dataclasses.replace(
            self, distances_km=distances[order], **self._outcomes(join, other),
            info={"grid": grid.as_dict(), "grid_key": grid.key(),
                  "yade_wall_s": round(sum(p["yade_wall_s"] for p in parts), 1),
                  "runs": sum(p["runs"] for p in parts),
                  "simulated_runs": sum(p["simulated_runs"] for p in parts),
                  "code_version": parts[-1]["code_version"], "parts": parts})

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

        return dataclasses.replace(
            self, slices=[s for s, k in zip(self.slices, keep) if k],
            **self._outcomes(lambda values: values[keep]), info=dict(self.info))

    def select_nodes(self, rings, azimuth_stride=1):
        """A table with the rings where ``rings`` (bool over ``distances_km``) holds and
        every ``azimuth_stride``-th node azimuth from 0 (still evenly spaced)."""
        rings = np.asarray(rings, bool)
        stride = int(azimuth_stride)

        return dataclasses.replace(
            self, distances_km=self.distances_km[rings],
            azimuths_deg=self.azimuths_deg[::stride],
            **self._outcomes(lambda values: values[:, rings][:, :, ::stride]),
            info=dict(self.info))

    def _outcomes(self, change, other=None):
        """The runs' arrays (:data:`OUTCOMES`) each changed, as keywords of
        :func:`dataclasses.replace`: ``change(a)``, or with ``other`` ``change(a, b)`` (b
        ``other``'s); the nominal run's None without one."""
        return {name: None if getattr(self, name) is None else change(
            getattr(self, name), *(() if other is None else (getattr(other, name),)))
            for name in OUTCOMES}

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
        if not path.exists():
            raise InputError(f"forward table not found: {path}")
        content = read_user_bytes(path, "forward table")
        try:
            with np.load(io.BytesIO(content), allow_pickle=False) as archive:
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

    def toppled_fraction_by_slice(self):
        """Per source slice: its mechanism, depth (km), Mw and the share of its finished
        runs' columns (all nodes and members) that toppled."""
        return [{**{k: sl[k] for k in ("mechanism", "depth_km", "mw")},
                 "fraction": round(float(self.toppled[i][self.valid[i]].mean()), 4)}
                for i, sl in enumerate(self.slices)]

    def cells(self):
        """One row per node and column: members, toppled, P (k/n), mean downfall azimuth
        in the strike frame and relative to the direction from epicentre to site."""
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


def _part_info(table):
    """What :meth:`ForwardTable.with_rings` keeps of a table it joins."""
    return {"distances_km": [float(d) for d in table.distances_km],
            **{k: table.info.get(k) for k in ("grid_key", "code_version", "yade_wall_s",
                                              "runs", "simulated_runs")}}
