"""The campaigns of the paper's experiments and the verification, one definition each (their
runs: :mod:`pipeline.campaign.runs`)."""
import logging

from dataclasses import dataclass
from pathlib import Path

from pipeline.constants import COLUMN_KINDS
from pipeline import paper
from pipeline.campaign import Campaign, register
from pipeline.campaign.options import (CAMPAIGN_NOTE, CampaignOptions, ColumnFileOptions,
                                       column_file_param, contact_file_param, contact_of,
                                       refuse_ignored_stiffness, stiffness_param)
from pipeline.scenario.contact_file import contact_values, refuse_set_twice, with_contact
from pipeline.campaign.run_dirs import finished_runs
from pipeline.campaign.column_file import (at_slenderness, check_stiffness, column_kn,
                                           description, mark, matched_kn, runs_colonnade)
from pipeline.campaign.runs import (column_outputs, column_specs, described_twins,
                                    pulse_record, run_column_spec, twin)
from pipeline.campaign.tables import collect, write_tables
from pipeline.files import (InputError, code_hash, content_hash, write_csv,
                            write_json, write_text)
from pipeline.motion import Motion, synthetics
from pipeline.records import resolve, sets
from pipeline.records.processing import signal_end_s
from pipeline.scenario.parameters import param
from pipeline.simulate import run_code_version
from pipeline.stats.circular import direction_table
from pipeline.motion.synthetics import rupture_centre
from pipeline.stats.location import locate_source_from_falls
from pipeline.scenario.column_format import example_names
from pipeline.scenario.geometry import ColumnGeometry
from pipeline import verification
from pipeline.campaign.tags import ColumnsTags
import pandas as pd

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SlendernessOptions(ColumnFileOptions):
    column_file: str = column_file_param(
        CAMPAIGN_NOTE + "; its block heights are scaled by one factor to each h/d of the "
        "sweep (overall height over base width)")


def _records_or(records, default):
    return list(records) if records else list(default)


def _contact(contact_file):
    """The contact values of ``--contact-file`` (None without one)."""
    return None if contact_file is None else contact_values(contact_file)


def slenderness_specs(records, campaign_dir, column_file=None, stiffness="matched",
                      contact_file=None):
    """h/d sweep of the twin model; with a description, the described column's block
    heights scaled to each h/d (:func:`pipeline.campaign.column_file.at_slenderness`)."""
    data = description(column_file)
    check_stiffness(stiffness)
    contact = _contact(contact_file)
    recs = _records_or(records, [paper.SWEEP_RECORD, pulse_record()])
    if data is None:
        return column_specs(with_contact([(r, twin(hd=hd)) for r in recs
                                          for hd in paper.SLENDERNESS_HD], contact),
                            campaign_dir)
    sweep = []
    for hd in paper.SLENDERNESS_HD:
        scaled = at_slenderness(data, hd)
        sweep.append(twin(hd=hd, column_file=scaled, kn=column_kn(scaled, stiffness)))
    return mark(column_specs(with_contact([(r, p) for r in recs for p in sweep], contact),
                             campaign_dir), data)


def friction_specs(records, campaign_dir, column_file=None, stiffness="matched",
                   contact_file=None):
    data = description(column_file, meshes=True, colonnades=True)
    check_stiffness(stiffness)
    contact = _contact(contact_file)
    refuse_set_twice(contact, ("mu_s", "mu_k"), "the friction campaign's sweep")
    runs = [(r, twin(mu_s=mu, mu_k=round(paper.FRICTION_SWEEP_MU_K_OVER_MU_S * mu, 4)))
            for r in _records_or(records, [paper.SWEEP_RECORD, pulse_record()])
            for mu in paper.FRICTION_MU_S]
    return mark(column_specs(with_contact(described_twins(runs, data, stiffness), contact),
                             campaign_dir), data)


register(Campaign(
    "slenderness", f"h/d {paper.SLENDERNESS_HD[0]:g}-{paper.SLENDERNESS_HD[-1]:g} on the "
    "paper's sweep record and the pulse record",
    slenderness_specs, run_column_spec, column_outputs("slenderness", "hd"),
    options=SlendernessOptions))

register(Campaign(
    "friction", f"mu_s {paper.FRICTION_MU_S[0]:g}-{paper.FRICTION_MU_S[-1]:g} "
    f"(mu_k = {paper.FRICTION_SWEEP_MU_K_OVER_MU_S:g} mu_s, the paper's rule)",
    friction_specs, run_column_spec, column_outputs("friction", "mu_s"),
    options=ColumnFileOptions))


def _nearsource_records():
    return sets.record_ids("nearsource")


def records_specs(records, campaign_dir, column_file=None, stiffness="matched",
                  contact_file=None):
    data = description(column_file, meshes=True, colonnades=True)
    check_stiffness(stiffness)
    runs = [(r, twin()) for r in (list(records) if records else _nearsource_records())]
    return mark(column_specs(with_contact(described_twins(runs, data, stiffness),
                                          _contact(contact_file)), campaign_dir), data)


register(Campaign(
    "records", "the twin model under the paper's record selection (record set nearsource; "
    "--set all / fema for the others)",
    records_specs, run_column_spec, column_outputs("records"),
    options=ColumnFileOptions))


def signal_window(record):
    """[start, end] (s, record's clock): a motion given ready-made (a synthetic npz) up
    to the end of its signal, as the processing cuts records (:func:`~pipeline.records.
    processing.signal_end_s`): its quiet tail would only keep a rocking column
    simulated.  None for a record that the processing cuts anyway."""
    source = resolve(record)
    if not source.processed:
        return None
    motion = Motion.load(source.path)
    start = motion.start_in_file_s                     # windows are on the record's clock
    return [start, round(start + float(signal_end_s(motion.acc, motion.dt)), 6)]


def synthetic_specs(records, campaign_dir, column_file=None, stiffness="matched",
                    contact_file=None):
    data = description(column_file, meshes=True, colonnades=True)
    check_stiffness(stiffness)
    contact = _contact(contact_file)
    paths = list(records) if records else [
        p for source_paths in synthetics.generate_sources(synthetics.SOURCES).values()
        for p in source_paths]
    runs = []
    for path in paths:
        window = signal_window(path)
        runs.append((str(path), twin(window=window) if window else twin()))
    return mark(column_specs(with_contact(described_twins(runs, data, stiffness), contact),
                             campaign_dir), data)


def synthetic_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline.figures.synthetic_map import plot_downfall_map  # lazy: matplotlib, not imported by a run or after Ctrl-C
    result = column_outputs("synthetic")(specs, campaign_dir, failures, animations, figures)
    runs, _ = collect(specs, "synthetic", campaign_dir)
    if runs.empty or "source" not in runs.columns or runs_colonnade(specs):
        return result
    for source in sorted(runs["source"].dropna().unique()) if figures else []:
        path = Path(campaign_dir) / f"map_{source}.png"
        plot_downfall_map(runs, source, path)
        result["figures"].append(path.name)
    write_csv(Path(campaign_dir) / "direction_table.csv", direction_table(runs))
    centres = {s: rupture_centre(s) for s in runs["source"].dropna().unique()}
    write_csv(Path(campaign_dir) / "source_location.csv",
              locate_source_from_falls(runs, reference_points=centres))
    return result


register(Campaign("synthetic", "the twin model at synthetic sites around two sources",
                  synthetic_specs, run_column_spec, synthetic_outputs,
                  options=ColumnFileOptions))


# ---------------------------------------------------------------- real columns
def columns_specs(records, campaign_dir, column_files=None, column="both",
                  stiffness="matched", contact_file=None):
    """Every column description (default: the shipped examples) on the same records
    (default: the sweep record and the pulse record), each with a monolith of its
    outline beside it (``column`` both); ``stiffness`` "matched" gives each column the
    contact stiffness of :func:`matched_kn`, "paper" the paper's kn for all; a contact
    file's values (its kn too) go over them."""
    names = list(column_files) if column_files else example_names()
    for name in names:
        description(name, meshes=True)          # a colonnade refused in its own words
    geometries = [ColumnGeometry.load(name) for name in names]
    described = [g.to_dict() for g in geometries]
    for k, data in enumerate(described):
        if data in described[:k]:
            raise InputError(f"--column-file {names[described.index(data)]} and {names[k]} "
                             "describe one column: the same specimen twice")
    if column not in COLUMN_KINDS:
        raise InputError(f"--column must be both, monolithic or drums, got {column!r}")
    check_stiffness(stiffness)
    recs = _records_or(records, [paper.SWEEP_RECORD, pulse_record()])
    runs = []
    for g in geometries:
        kn = paper.COLUMN_KN_N_M if stiffness == "paper" else matched_kn(g)
        runs += [(r, twin(column=column, column_file=g.to_dict(), kn=kn)) for r in recs]
    runs = with_contact(runs, _contact(contact_file))
    return column_specs(runs, campaign_dir,
                        tags=[ColumnsTags(p["column_file"]["name"]) for _, p in runs])


COLUMNS_TABLE = ["description", "record_id", "column", "toppled", "downfall_azimuth_deg",
                 "impact_time_s", "first_to_strike", "first_to_strike_index",
                 "struck_bodies", "bodies", "max_tilt_deg", "base_slip_m", "uplift_ratio",
                 "height_m", "mass_kg", "kn", "back_azimuth_deg", "run_id"]


def columns_table(specs, campaign_dir):
    """One row per description, record and column (described or monolith): toppled,
    direction and which block struck the pedestal first, with the column's rocking
    threshold (g units, statics) beside them."""

    rows = []
    for spec, summary in finished_runs(campaign_dir, specs):
        geometry = ColumnGeometry.from_dict(spec.params.column.column_file)
        shapes = {"drums": geometry, "monolithic": geometry.monolithic()}
        for col in summary.columns:
            g = shapes[col.column]
            struck = sorted((b for b in col.bodies if b["struck"]),
                            key=lambda b: b["impact_time_s"])
            first = struck[0] if struck else None
            rows.append({
                "description": geometry.name, "record_id": spec.record_id,
                "column": col.column, "toppled": col.toppled,
                "downfall_azimuth_deg": col.downfall_azimuth_deg,
                "impact_time_s": col.impact_time_s,
                "first_to_strike": None if first is None else first.get(
                    "name", f"body {first['index']}"),
                "first_to_strike_index": None if first is None else first["index"],
                "struck_bodies": len(struck), "bodies": len(g.bodies()),
                "max_tilt_deg": col.max_tilt_deg, "base_slip_m": col.base_slip_m,
                "uplift_ratio": round(g.uplift_ratio(), 4), "height_m": g.height,
                "mass_kg": round(sum(b.mass for b in g.bodies())),
                "kn": spec.params.contact.kn,
                "back_azimuth_deg": summary.back_azimuth_deg, "run_id": spec.run_id})
    return pd.DataFrame(rows, columns=COLUMNS_TABLE)


def columns_outputs(specs, campaign_dir, failures, animations, figures=True):
    """runs.csv and impacts.csv like the other column campaigns, and columns.csv /
    columns.md: the descriptions side by side on each record."""
    campaign_dir = Path(campaign_dir)
    runs, impacts = collect(specs, "columns", campaign_dir)
    if not runs.empty:
        names = {s.run_id: s.tags.description for s in specs}
        runs.insert(1, "description", runs["run_id"].map(names))
    write_tables(campaign_dir, runs, impacts)
    table = columns_table(specs, campaign_dir)
    write_csv(campaign_dir / "columns.csv", table)
    shown = table.drop(columns=["run_id", "back_azimuth_deg", "first_to_strike_index"])
    text = shown.to_markdown(index=False, floatfmt=".3g") if not table.empty else "(no runs)"
    write_text(campaign_dir / "columns.md", "# Real columns on the same records\n\n"
               "uplift_ratio: rocking threshold / g from statics (d/h for a cylinder).\n\n"
               + text + "\n")
    log.info(text)
    written = []
    if figures and animations and not runs.empty:
        from pipeline.figures import animate_examples  # lazy: matplotlib, not imported by a run or after Ctrl-C
        written = animate_examples(runs, campaign_dir, animations)
    return {"code_version": run_code_version(),
            "figures": [str(p.relative_to(campaign_dir)) for p in written]}


@dataclass(frozen=True)
class ColumnsOptions(CampaignOptions):
    column_files: str = column_file_param(many=True, unset="all shipped")
    column: str = param("both", "", "both: each description and a monolith of its outline; "
                        "drums: the description only; monolithic: the monolith only",
                        flag="--column", choices=COLUMN_KINDS)
    stiffness: str = stiffness_param("")
    contact_file: str = contact_file_param("its kn replaces --stiffness's")

    def check(self):
        refuse_ignored_stiffness(self, contact_of(self))

    def kwargs(self):
        files = [f for f in (self.column_files or "").split(",") if f]
        return {"column_files": files or None, "column": self.column,
                "stiffness": self.stiffness, "contact_file": self.contact_file}


register(Campaign(
    "columns", "real columns from descriptions (shipped: the paper's two, a Doric peristyle "
    "column, a Roman granite column) compared on the same records: toppled, direction, "
    "which block falls first",
    columns_specs, run_column_spec, columns_outputs, options=ColumnsOptions))


# ---------------------------------------------------------------- verification
def verification_specs(records, campaign_dir):
    if records:
        raise InputError("the verification campaign takes no --records")
    return verification.campaign_checks(
        content_hash(run_code_version(), code_hash("verification", "rocking")))


def verification_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline.figures.verification import plot_verification  # lazy: matplotlib, not imported by a run or after Ctrl-C
    runs = Path(campaign_dir) / "runs"
    results = [(check, verification.CheckResult.load(runs / check.run_id))
               for check in specs if (runs / check.run_id / "summary.json").exists()]
    summary = verification.summarise_campaign(results)
    summary["figures"] = ([p.name for p in plot_verification(
        results, campaign_dir, summary.get("one_cosine"))] if figures else [])
    summary["failed_runs"] = [s.run_id for s, _ in failures]
    write_json(Path(campaign_dir) / "verification.json", summary)
    for line in summary["lines"]:
        log.info(line)
    return {"figures": summary["figures"]}


register(Campaign("verification", "Housner, one-sine pulse, sliding and one-cosine checks "
                  "over ranges",
                  verification_specs, verification.run_check, verification_outputs,
                  label="verification runs"))
