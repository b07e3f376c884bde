"""The campaigns: the paper's experiments and the verification, one definition each."""
import dataclasses
import json
from pathlib import Path

from pipeline import RESULTS_DIR, paper
from pipeline.campaign import Campaign, register
from pipeline.campaign.tables import collect
from pipeline.files import InputError, code_hash, content_hash, write_csv
from pipeline.motion import Motion
from pipeline.records import catalog, catalog_row, processed_motion, resolve
from pipeline.scenario import Column, Contact, Numerics
from pipeline.simulate import simulate


NUMERICS_FIELDS = {f.name for f in dataclasses.fields(Numerics)}

# ---------------------------------------------------------------- column runs
def run_code_version():
    """Hash of the code that turns a motion and parameters into an outcome."""
    return code_hash("scenario", "outcome", "motion", "simulate", "yade_scripts")


def motion_cache(campaign_dir):
    """Where a campaign caches processed motions: results/cache/motions, or inside the
    campaign directory when it lies outside results/."""
    campaign_dir = Path(campaign_dir).resolve()
    if RESULTS_DIR.resolve() in campaign_dir.parents:
        return RESULTS_DIR / "cache" / "motions"
    return campaign_dir / "motions"


def column_specs(runs, campaign_dir):
    """Resolve (record, parameters) pairs into run specs: each record processed once,
    record ids unique, run id = hash(code, motion content, parameters)."""
    version = run_code_version()
    cache = motion_cache(campaign_dir)
    resolved, ids = {}, {}
    for record, _ in runs:
        if record in resolved:
            continue
        _, path = processed_motion(record, cache_dir=cache)
        source = resolve(record)
        record_id = source.id
        if source.row is None and catalog_row(record_id) is not None:
            record_id = f"{record_id}-{path.stem[:6]}"      # a file named like a catalogue id
        if ids.get(record_id, path) != path:
            record_id = f"{record_id}-{path.stem[:6]}"      # two files with one stem
        ids[record_id] = path
        resolved[record] = (record_id, path)
    specs = []
    for record, params in runs:
        record_id, path = resolved[record]
        specs.append({"record": str(record), "record_id": record_id, "motion_file": str(path),
                      "params": params, "run_id": content_hash(version, path, params)})
    return specs


def run_column_spec(spec, run_dir):
    """Worker: one twin-model (or single column) run of a spec."""
    p = dict(spec["params"])
    column = Column(kind=p.pop("column", "both"), **{k: p.pop(k) for k in
                                                     ("hd", "height", "n_drums", "density")
                                                     if k in p})
    contact = Contact(**{k: p.pop(k) for k in ("kn", "damping", "mu_s", "mu_k") if k in p})
    numerics = Numerics(**{k: p.pop(k) for k in list(p) if k in NUMERICS_FIELDS})
    simulate(Motion.load(spec["motion_file"]), run_dir, column=column, contact=contact,
             numerics=numerics, record=spec["record_id"], motion_file=spec["motion_file"], **p)


def twin(**params):
    """Parameters of a twin-model run (paper defaults for what is not given)."""
    return {"column": "both", "hd": paper.COLUMN_HD, "mu_s": paper.MU_STATIC,
            "mu_k": paper.MU_KINETIC, **params}


def pulse_record():
    """Catalogue id of the pulse-like record that stands in for the paper's GM23."""
    table = catalog()
    chosen = table[table["replaces_gm23"].astype(str).str.lower() == "true"]
    if chosen.empty:
        raise InputError("records/catalog.csv nominates no record with replaces_gm23 = True")
    return str(chosen["id"].iloc[0])


def column_outputs(name, size_by=None):
    """Outputs of a column campaign: runs.csv, impacts.csv, direction statistics, figures."""

    def outputs(specs, campaign_dir, failures, animations, figures=True):
        from pipeline import figures as figure_module
        from pipeline.stats.circular import direction_statistics
        campaign_dir = Path(campaign_dir)
        runs, impacts = collect(specs, name, campaign_dir)
        write_csv(campaign_dir / "runs.csv", runs)
        write_csv(campaign_dir / "impacts.csv", impacts)
        written = []
        if not runs.empty:
            write_csv(campaign_dir / "direction_statistics.csv", direction_statistics(runs))
            if figures:
                written = figure_module.campaign_figures(name, runs, impacts, campaign_dir,
                                                         size_by, animations)
        toppled = runs.groupby("column")["toppled"].agg(["sum", "count"]) if not runs.empty \
            else None
        print(f"wrote {campaign_dir / 'runs.csv'}" + (
            "" if toppled is None else "; toppled: " + ", ".join(
                f"{c} {int(r['sum'])}/{int(r['count'])}" for c, r in toppled.iterrows())))
        return {"code_version": run_code_version(),
                "figures": [str(p.relative_to(campaign_dir)) for p in written]}

    return outputs


def _records_or(records, default):
    return list(records) if records else list(default)


register(Campaign(
    "slenderness", f"h/d {paper.SLENDERNESS_HD[0]:g}-{paper.SLENDERNESS_HD[-1]:g} on the "
    "paper's sweep record and the pulse record",
    lambda records, d: column_specs(
        [(r, twin(hd=hd)) for r in _records_or(records, [paper.SWEEP_RECORD, pulse_record()])
         for hd in paper.SLENDERNESS_HD], d),
    run_column_spec, column_outputs("slenderness", "hd")))

register(Campaign(
    "friction", f"mu_s {paper.FRICTION_MU_S[0]:g}-{paper.FRICTION_MU_S[-1]:g} "
    f"(mu_k = {paper.MU_K_OVER_MU_S:g} mu_s)",
    lambda records, d: column_specs(
        [(r, twin(mu_s=mu, mu_k=round(paper.MU_K_OVER_MU_S * mu, 4)))
         for r in _records_or(records, [paper.SWEEP_RECORD, pulse_record()])
         for mu in paper.FRICTION_MU_S], d),
    run_column_spec, column_outputs("friction", "mu_s")))


def _nearsource_records():
    from pipeline.records import sets
    return sets.record_ids("nearsource")


register(Campaign(
    "records", "the twin model under the paper's record selection (record set nearsource; "
    "--set all / fema for the others)",
    lambda records, d: column_specs(
        [(r, twin()) for r in (list(records) if records else _nearsource_records())], d),
    run_column_spec, column_outputs("records")))


def synthetic_specs(records, campaign_dir):
    from pipeline.motion import synthetics
    paths = list(records) if records else [p for source in synthetics.SOURCES
                                           for p in synthetics.generate(source)]
    return column_specs([(str(p), twin()) for p in paths], campaign_dir)


def synthetic_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline.figures.synthetic_map import plot_downfall_map
    from pipeline.motion.synthetics import rupture_centre
    from pipeline.stats.circular import direction_table
    from pipeline.stats.location import locate_source_from_falls
    result = column_outputs("synthetic")(specs, campaign_dir, failures, animations, figures)
    runs, _ = collect(specs, "synthetic", campaign_dir)
    if runs.empty or "source" not in runs.columns:
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
                  synthetic_specs, run_column_spec, synthetic_outputs))


# ---------------------------------------------------------------- verification
def verification_specs(records, campaign_dir):
    from pipeline import verification
    if records:
        raise InputError("the verification campaign takes no --records")
    version = content_hash(run_code_version(), code_hash("verification", "rocking"))
    specs = verification.campaign_specs()
    for spec in specs:
        spec["run_id"] = content_hash(version, {k: v for k, v in spec.items() if k != "run_id"})
    return specs


def verification_outputs(specs, campaign_dir, failures, animations, figures=True):
    from pipeline import verification
    from pipeline.figures.verification import plot_verification
    from pipeline.files import write_json
    results = []
    for spec in specs:
        path = Path(campaign_dir) / "runs" / spec["run_id"] / "summary.json"
        if path.exists():
            results.append((spec, json.loads(path.read_text())))
    summary = verification.summarise_campaign(results)
    summary["figures"] = ([p.name for p in plot_verification(results, campaign_dir)]
                          if figures else [])
    summary["failed_runs"] = [s["run_id"] for s, _ in failures]
    write_json(Path(campaign_dir) / "verification.json", summary)
    for line in summary["lines"]:
        print(line)
    return {"figures": summary["figures"]}


def _verification_worker(spec, run_dir):
    from pipeline import verification
    verification.run_spec(spec, run_dir)


register(Campaign("verification", "Housner, one-sine pulse and sliding checks over ranges",
                  verification_specs, _verification_worker, verification_outputs,
                  label="verification runs"))


from pipeline.campaign import ensemble  # noqa: E402,F401  (registers the ensemble campaign)
