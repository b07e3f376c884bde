"""The runs of one column that several campaigns share: run specs from (record,
parameters) pairs (each record processed once, its motion cached), the worker that runs
one, the twin model's parameters, the pulse record, the outputs of a column campaign."""
import logging

from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.campaign.column_file import column_kn, runs_colonnade, summary_entry
from pipeline.campaign.spec import RunSpec
from pipeline.campaign.tables import (collect, colonnade_table, write_colonnade_files,
                                      write_tables)
from pipeline.files import InputError, csv_true_column, write_csv
from pipeline.motion import Motion
from pipeline.records import CACHE_DIR, catalog, catalog_row, processed_motion, resolve
from pipeline.scenario import RunParams
from pipeline.simulate import run_code_version, simulate
from pipeline.stats.circular import direction_statistics

log = logging.getLogger(__name__)


# ---------------------------------------------------------------- column runs
def motion_cache(campaign_dir):
    """Where a campaign caches processed motions: results/cache/motions, or inside the
    campaign directory when it lies outside results/."""
    campaign_dir = Path(campaign_dir).resolve()
    if RESULTS_DIR.resolve() in campaign_dir.parents:
        return CACHE_DIR
    return campaign_dir / "motions"


def column_specs(runs, campaign_dir, tags=None, keep_trajectory=True, core_s=None):
    """Resolve (record, parameters) pairs into :class:`~pipeline.campaign.spec.RunSpec`:
    each record processed once, record ids unique, run id = hash(code, motion content,
    parameters); ``tags``: one campaign tags dataclass per run (:mod:`pipeline.campaign.tags`);
    ``keep_trajectory``: a bool for every run or one per run; ``core_s``: None (the
    campaign's estimate) or one core-seconds estimate per run."""
    version = run_code_version()
    cache = motion_cache(campaign_dir)
    resolved, ids = {}, {}
    for record, _ in runs:
        if record in resolved:
            continue
        source = resolve(record)
        _, path = processed_motion(source, cache_dir=cache)
        record_id = source.id
        if source.row is None and catalog_row(record_id) is not None:
            record_id = f"{record_id}-{path.stem[:6]}"      # a file named like a catalogue id
        if ids.get(record_id, path) != path:
            record_id = f"{record_id}-{path.stem[:6]}"      # two files with one stem
        ids[record_id] = path
        resolved[record] = (record_id, path)
    tags = [None] * len(runs) if tags is None else list(tags)
    keep = [keep_trajectory] * len(runs) if isinstance(keep_trajectory, bool) \
        else list(keep_trajectory)
    core_s = [None] * len(runs) if core_s is None else list(core_s)
    if not len(tags) == len(keep) == len(core_s) == len(runs):
        raise ValueError("column_specs: one tags, keep_trajectory and core_s per run")
    built = {}        # id of a parameters dict shared by many runs -> (it, its RunParams)
    for _, params in runs:
        if not isinstance(params, RunParams) and id(params) not in built:
            built[id(params)] = (params, RunParams.from_dict(params))   # checked once
    return [RunSpec.create(record, resolved[record][0], resolved[record][1],
                           built[id(params)][1] if id(params) in built else params, version,
                           tag, keep_trajectory=kept, core_s=cost)
            for (record, params), tag, kept, cost in zip(runs, tags, keep, core_s)]


def run_column_spec(spec, run_dir):
    """Worker: one twin-model (or single column) run of a spec; ``column_file`` in its
    parameters is a column description (dict, so that the run id covers its content) or
    a shipped example's name."""
    simulate(Motion.load(spec.motion_file), run_dir, spec.params, record=spec.record_id,
             motion_file=spec.motion_file)


def twin(**params):
    """The flat parameters (:class:`~pipeline.scenario.parameters.RunParams` names) of a
    twin-model run: the paper's for what is not given; with ``column_file`` (a
    description dict) the described column and a monolith of its outline take the drums'
    and the monolith's places."""
    return RunParams.from_dict(params).to_dict()


def pulse_record():
    """Catalogue id of the pulse-like record that stands in for the paper's GM23."""
    table = catalog()
    chosen = table[csv_true_column(table["replaces_gm23"].astype(str))]
    if chosen.empty:
        raise InputError("records/catalog.csv nominates no record with replaces_gm23 = True")
    return str(chosen["id"].iloc[0])


def column_outputs(name, size_by=None):
    """Outputs of a column campaign: runs.csv, impacts.csv, direction statistics, figures;
    for a colonnade runs.csv, impacts.csv, colonnades.csv and its statistics
    (:func:`pipeline.campaign.tables.write_colonnade_files`)."""

    def outputs(specs, campaign_dir, failures, animations, figures=True):
        campaign_dir = Path(campaign_dir)
        runs, impacts = collect(specs, name, campaign_dir)
        described = summary_entry(specs)
        if described and not runs.empty:
            names = {s.run_id: s.params.column.column_file["name"] for s in specs}
            runs.insert(1, "description", runs["run_id"].map(names))
        write_tables(campaign_dir, runs, impacts)
        written = []
        if runs_colonnade(specs):
            # the colonnade's own outcomes instead of the twin columns' statistics
            written = write_colonnade_files(campaign_dir, colonnade_table(specs, campaign_dir),
                                            figures, runs=runs,
                                            description=described["column_file"])
        elif not runs.empty:
            write_csv(campaign_dir / "direction_statistics.csv", direction_statistics(runs))
            if figures:
                from pipeline import figures as figure_module  # lazy: matplotlib, not imported by a run or after Ctrl-C
                written = figure_module.campaign_figures(name, runs, impacts, campaign_dir,
                                                         size_by, animations)
        toppled = runs.groupby("column")["toppled"].agg(["sum", "count"]) if not runs.empty \
            else None
        log.info(f"wrote {campaign_dir / 'runs.csv'}" + (
            "" if toppled is None else "; toppled: " + ", ".join(
                f"{c} {int(r['sum'])}/{int(r['count'])}" for c, r in toppled.iterrows())))
        return {"code_version": run_code_version(), **described,
                "figures": [str(p.relative_to(campaign_dir)) for p in written]}

    return outputs


def described_twins(runs, column_file, stiffness):
    """(record, twin parameters) pairs with the description ``column_file`` (a dict) and
    its contact stiffness added; unchanged without one."""
    if column_file is None:
        return runs
    kn = column_kn(column_file, stiffness)
    return [(r, {**p, "column_file": column_file, "kn": kn}) for r, p in runs]
