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
members (:func:`pipeline.campaign.ensemble_members.sample_members`, one seed: member k has the same
column parameters at every node).  The runs are the campaign ``inversion-forward`` on the
executor, so they are cached by content (run id = hash of motion, parameters and code) and
a second inversion reuses every finished run.
"""
from dataclasses import dataclass
import logging
import time
from pathlib import Path

from pipeline.campaign import Campaign, register
from pipeline.campaign.options import CampaignOptions
from pipeline.scenario.parameters import param
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.files import InputError, write_csv
from pipeline.inversion.options import DEFAULT_FORWARD_DIR
from pipeline.inversion.grid import TableGrid, node_positions, slice_motions
from pipeline.inversion.presets import GRIDS
from pipeline.inversion.table import ForwardTable
from pipeline.campaign.column_file import column_kn
from pipeline.campaign.ensemble_members import nominal, sample_members
from pipeline.campaign import run_campaign

log = logging.getLogger(__name__)



# ---------------------------------------------------------------- runs (campaign)
MEMBER_BATCH = 6    # members are drawn in Latin-hypercube batches of 6 (seeds seed, seed + 1,
#                     ...): a grown ensemble keeps its first members, so their runs are reused


def member_parameters(grid):
    """[(member, params)]: member -1 is the nominal twin run, 0.. the ensemble members
    (batch b of MEMBER_BATCH members: Latin hypercube with seed ``grid.seed + b``)."""
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


@dataclass(frozen=True)
class ForwardTags:
    """A forward-table run: its magnitude ``slice``, table ``node`` (at ``distance_km`` and
    ``azimuth_deg`` from strike), ensemble ``member`` (-1 nominal) and the table's ``grid``
    (:class:`~pipeline.inversion.grid.TableGrid`)."""
    slice: int
    node: int
    member: int
    distance_km: float
    azimuth_deg: float
    grid: TableGrid


def forward_specs(records, campaign_dir, grid=None, jobs=None):
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
                info.append(ForwardTags(s, node, member, float(r[node]), float(a[node]), grid))
    return column_specs(runs, campaign_dir, info, keep_trajectory=False)


def table_path(campaign_dir, grid):
    return Path(campaign_dir) / "tables" / f"forward_table_{grid.key()}.npz"


def forward_outputs(specs, campaign_dir, failures, animations, figures=True):
    """Collect the finished runs of ``specs`` into the table file (tables/forward_table_<grid
    key>.npz) and its per-node summary (tables/forward_cells_<grid key>.csv)."""
    grid = specs[0].tags.grid
    table = ForwardTable.from_runs(specs, campaign_dir, grid)
    path = table_path(campaign_dir, grid)
    table.save(path)
    write_csv(path.with_name(f"forward_cells_{grid.key()}.csv"), table.cells())
    done = int(table.valid.any(axis=3).sum() + (table.nominal_valid.any(axis=3).sum()
                                                 if table.nominal_valid is not None else 0))
    log.info(f"wrote {path} ({done} of {len(specs)} runs finished; YADE wall "
             f"{table.info['yade_wall_s']:.0f} s in total)")
    return {"table": str(path), "grid": grid.as_dict(), "grid_key": grid.key(),
            "runs_finished": done}


def run_forward(grid, campaign_dir=None, jobs=None, scheduler=None):
    """Run (or reuse) the forward campaign of ``grid``; return (ForwardTable, cost dict)."""
    campaign_dir = Path(campaign_dir or DEFAULT_FORWARD_DIR)
    extra = {"scheduler": scheduler} if scheduler else {}
    started = time.monotonic()
    result = run_campaign("inversion-forward", jobs=jobs, campaign_dir=campaign_dir,
                          animations=0, options={"grid": grid, "jobs": jobs}, **extra)
    table = ForwardTable.load(result["table"])
    cost = {"runs": grid.n_runs(), "elapsed_s": round(time.monotonic() - started, 1),
            "yade_wall_s": table.info["yade_wall_s"], "table": result["table"]}
    return table, cost


@dataclass(frozen=True)
class ForwardOptions(CampaignOptions):
    grid: str = param("full", "", "forward grid preset (see python -m pipeline invert --help)",
                      flag="--grid", choices=tuple(sorted(GRIDS)))
    TAKES_JOBS = True           # pyprop8 shares the command's processes

    def kwargs(self):
        return {"grid": GRIDS[self.grid]}


register(Campaign("inversion-forward", "forward table of the source inversion: twin-model "
                  "ensembles at (mechanism, depth, magnitude, distance, azimuth from strike)",
                  forward_specs, run_column_spec, forward_outputs, label="runs",
                  options=ForwardOptions))
