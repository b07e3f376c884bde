"""Campaign stage: the paper's experiments as sets of runs, in parallel and resumable.

    python -m pipeline campaign slenderness --jobs 2

Each run lives in ``results/<campaign>/runs/<run_id>/`` where run_id is a
content hash of the processed motion, the run parameters and the code
version; a run whose ``summary.json`` exists is not run again, so a killed
campaign resumes where it stopped.  Runs are separate single-thread YADE
processes, ``--jobs`` at a time.  The campaign then writes ``runs.csv`` (one
row per run and column), ``impacts.csv`` (one row per struck body) and its
figures.
"""
import json
import math
import os
import traceback
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from pipeline import PROJECT_ROOT, RESULTS_DIR, records, run
from pipeline.files import InputError, content_hash, write_csv, write_json, write_text

CODE_FILES = ["yade_scripts/column_scene.py", "pipeline/scenario.py", "pipeline/outcome.py",
              "pipeline/run.py"]
SLENDERNESS_HD = [round(3.0 + 0.5 * i, 1) for i in range(13)]          # 3.0 .. 9.0
FRICTION_MU_S = [round(0.1 * i, 1) for i in range(1, 10)]               # 0.1 .. 0.9
MU_K_OVER_MU_S = 0.84
PAPER_RECORD = "GM20"                                                   # Kocaeli, Izmit
SYNTHETIC_SITE_KEYS = ("source", "station", "x_km", "y_km", "ring_km")  # from synthetic meta


def code_version():
    """Hash of the code that determines a run's outcome."""
    return content_hash(*[PROJECT_ROOT / f for f in CODE_FILES])


def pulse_record():
    """Catalogue id of the pulse-like record that stands in for the paper's GM23."""
    table = records.catalog()
    chosen = table[table["replaces_gm23"].astype(str).str.lower() == "true"]
    if chosen.empty:
        raise InputError("records/catalog.csv nominates no record with replaces_gm23 = True")
    return str(chosen["id"].iloc[0])


def column_spec(record, **params):
    """One twin-model run: record id or path plus keyword parameters of run.simulate."""
    return {"record": str(record), "params": {"column": "both", "hd": 6.0, "mu_s": 0.7,
                                              "mu_k": 0.6, **params}}


def campaign_specs(name, record_ids=None):
    """Run specs of a named campaign."""
    if name == "slenderness":
        recs = record_ids or [PAPER_RECORD, pulse_record()]
        return [column_spec(r, hd=hd) for r in recs for hd in SLENDERNESS_HD]
    if name == "friction":
        recs = record_ids or [PAPER_RECORD, pulse_record()]
        return [column_spec(r, mu_s=mu, mu_k=round(MU_K_OVER_MU_S * mu, 4))
                for r in recs for mu in FRICTION_MU_S]
    if name == "records":
        recs = record_ids or list(records.catalog()["id"])
        return [column_spec(r) for r in recs]
    if name == "synthetic":
        from pipeline import synthetics
        paths = []
        for source in synthetics.SOURCES:
            paths += synthetics.generate(source)
        return [column_spec(p) for p in paths]
    raise InputError(f"unknown campaign {name!r}")


def resolve_specs(specs):
    """Process each spec's record once and fix its run id (hash of motion, parameters, code)."""
    version = code_version()
    motion_files = {}
    for spec in specs:
        rec = spec["record"]
        if rec not in motion_files:
            motion_files[rec] = records.processed_motion_path(rec)
        spec["motion_file"] = str(motion_files[rec])
        spec["run_id"] = content_hash(version, Path(spec["motion_file"]), spec["params"])
    return specs


def run_column_spec(spec, run_dir):
    run.simulate(spec["motion_file"], run_dir, **spec["params"])


def execute(specs, campaign_dir, jobs, worker=run_column_spec, label="runs"):
    """Run every spec whose run directory has no summary.json; return the failures.

    worker(spec, run_dir) must write run_dir/summary.json atomically as its last act.
    """
    runs_dir = Path(campaign_dir) / "runs"
    todo = [s for s in specs if not (runs_dir / s["run_id"] / "summary.json").exists()]
    done = len(specs) - len(todo)
    print(f"{Path(campaign_dir).name}: {len(specs)} {label}, {done} already done, "
          f"{len(todo)} to run with {jobs} parallel YADE process(es)", flush=True)
    failures = []
    if not todo:
        return failures
    with ThreadPoolExecutor(max_workers=jobs) as pool, \
            tqdm(total=len(specs), initial=done, unit="run", dynamic_ncols=True) as bar:
        futures = {pool.submit(worker, spec, runs_dir / spec["run_id"]): spec for spec in todo}
        for future in as_completed(futures):
            spec = futures[future]
            try:
                future.result()
            except Exception as exc:   # keep going: one failed run must not lose the others
                failures.append((spec, exc))
                run_dir = runs_dir / spec["run_id"]
                run_dir.mkdir(parents=True, exist_ok=True)
                write_text(run_dir / "error.txt", "".join(traceback.format_exception(exc)))
                tqdm.write(f"run {spec['run_id']} ({spec['record']}) failed: {exc}")
            bar.update()
    return failures


def collect(specs, campaign, campaign_dir):
    """runs and impacts tables (DataFrames) from the summaries of finished runs."""
    runs_dir = Path(campaign_dir) / "runs"
    record_params = {}
    run_rows, impact_rows = [], []
    for spec in specs:
        path = runs_dir / spec["run_id"] / "summary.json"
        if not path.exists():
            continue
        summary = json.loads(path.read_text())
        if spec["motion_file"] not in record_params:
            motion = records.load_motion(spec["motion_file"])
            site = {k: motion["meta"][k] for k in SYNTHETIC_SITE_KEYS if k in motion["meta"]}
            if "station" in site:
                site["site_id"] = site.pop("station")
            record_params[spec["motion_file"]] = {**records.record_parameters(motion), **site}
        rp = record_params[spec["motion_file"]]
        p = summary["parameters"]
        base = {"campaign": campaign, "run_id": spec["run_id"], "record_id": summary["record"],
                "hd": p["hd"], "height_m": p["height_m"], "n_drums": p["n_drums"],
                "mu_s": p["mu_s"], "mu_k": p["mu_k"], "kn": p["kn"], "damping": p["damping"]}
        for col in summary["columns"]:
            point = col["impact_point_m"] or [math.nan, math.nan]
            run_rows.append({
                **base, "column": col["column"], "toppled": col["toppled"],
                "downfall_azimuth_deg": _nan(col["downfall_azimuth_deg"]),
                "impact_time_s": _nan(col["impact_time_s"]), "impact_x_m": point[0],
                "impact_y_m": point[1], "max_tilt_deg": col["max_tilt_deg"],
                "base_slip_m": col.get("base_slip_m"),
                **{k: v if isinstance(v, str) else _nan(v) for k, v in rp.items()},
                "back_azimuth_deg": _nan(summary["back_azimuth_deg"]),
                "motion_file": spec["motion_file"],
                "run_dir": os.path.relpath(runs_dir / spec["run_id"], campaign_dir)})
            for body in col["bodies"]:
                if body["struck"]:
                    impact_rows.append({
                        "run_id": spec["run_id"], "column": col["column"],
                        "body_index": body["index"], "impact_time_s": body["impact_time_s"],
                        "x_m": body["impact_point_m"][0], "y_m": body["impact_point_m"][1],
                        "hd": p["hd"], "mu_s": p["mu_s"], "record_id": summary["record"]})
    impact_columns = ["run_id", "column", "body_index", "impact_time_s", "x_m", "y_m", "hd",
                      "mu_s", "record_id"]
    return pd.DataFrame(run_rows), pd.DataFrame(impact_rows, columns=impact_columns)


def _nan(value):
    return math.nan if value is None else value


def figures(name, runs, impacts, campaign_dir):
    """The campaign's figures (paper Figs 9 and 10, roses, parameters, directions)."""
    from pipeline import analysis
    campaign_dir = Path(campaign_dir)
    written = []
    if runs.empty:
        return written
    if name in ("slenderness", "friction"):
        size_by = "hd" if name == "slenderness" else "mu_s"
        for record_id, group in runs.groupby("record_id"):
            motion = records.load_motion(group["motion_file"].iloc[0])
            path = campaign_dir / f"impact_map_{record_id}.png"
            analysis.plot_impact_map(group, impacts[impacts["run_id"].isin(group["run_id"])],
                                     motion, path, size_by=size_by,
                                     title=f"{name}: {record_id}")
            written.append(path)
    toppled = runs[runs["toppled"].astype(bool)]
    if not toppled.empty:
        path = campaign_dir / "rose.png"
        analysis.plot_rose(runs, path)
        written.append(path)
    if name in ("records", "synthetic"):
        for func, fname in ((analysis.plot_toppling_vs_parameters, "toppling_vs_parameters.png"),
                            (analysis.plot_downfall_vs_directions, "downfall_vs_directions.png")):
            func(runs, campaign_dir / fname)
            written.append(campaign_dir / fname)
    return written


def synthetic_outputs(runs, campaign_dir):
    """Per source: downfall map; tables of downfall minus back azimuth and of the
    source location inferred from the falls."""
    from pipeline import synthetics
    written = []
    for source in sorted(runs["source"].dropna().unique()):
        path = Path(campaign_dir) / f"map_{source}.png"
        synthetics.plot_downfall_map(runs, source, path)
        written.append(path)
    write_csv(Path(campaign_dir) / "direction_table.csv", synthetics.direction_table(runs))
    write_csv(Path(campaign_dir) / "source_location.csv",
              synthetics.locate_source_from_falls(runs))
    return written


def animate_examples(runs, campaign_dir, count=1):
    """GIF animations of the first toppled runs (the paper's online movies)."""
    from pipeline import animate
    campaign_dir = Path(campaign_dir)
    written = []
    toppled = runs[runs["toppled"].astype(bool)].drop_duplicates("run_id").head(count)
    for _, row in toppled.iterrows():
        path = campaign_dir / f"animation_{row['record_id']}_{row['run_id']}.gif"
        if not path.exists():
            animate.animate_run(campaign_dir / row["run_dir"], path, fps=10, max_frames=250)
        written.append(path)
    return written


def run_campaign(name, jobs=None, record_ids=None, campaign_dir=None, animations=1):
    """Run (or resume) a campaign and write its tables and figures; return the runs table."""
    if name == "verification":
        from pipeline import verify
        return verify.run_verification_campaign(jobs=jobs or os.cpu_count(),
                                                out_dir=campaign_dir)
    jobs = jobs or os.cpu_count() or 1
    if jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {jobs}")
    campaign_dir = Path(campaign_dir or RESULTS_DIR / name)
    specs = resolve_specs(campaign_specs(name, record_ids))
    failures = execute(specs, campaign_dir, jobs)
    runs, impacts = collect(specs, name, campaign_dir)
    write_csv(campaign_dir / "runs.csv", runs)
    write_csv(campaign_dir / "impacts.csv", impacts)
    written = figures(name, runs, impacts, campaign_dir)
    if name == "synthetic" and not runs.empty:
        written += synthetic_outputs(runs, campaign_dir)
    if animations:
        written += animate_examples(runs, campaign_dir, animations)
    if not runs.empty:
        from pipeline import analysis
        write_csv(campaign_dir / "direction_statistics.csv", analysis.direction_statistics(runs))
    write_json(campaign_dir / "campaign.json", {
        "campaign": name, "code_version": code_version(), "runs": len(specs),
        "failed": [{"run_id": s["run_id"], "record": s["record"], "error": str(e)}
                   for s, e in failures],
        "figures": [str(p.relative_to(campaign_dir)) for p in written]})
    toppled = runs.groupby("column")["toppled"].agg(["sum", "count"]) if not runs.empty else None
    print(f"wrote {campaign_dir / 'runs.csv'}" + (
        "" if toppled is None else "; toppled: " + ", ".join(
            f"{c} {int(r['sum'])}/{int(r['count'])}" for c, r in toppled.iterrows())))
    if failures:
        raise RuntimeError(f"{len(failures)} run(s) failed; see error.txt in their run "
                           "directories; rerun the campaign to retry them")
    return runs


def add_command(subparsers):
    p = subparsers.add_parser(
        "campaign", help="run one of the paper's experiments (resumable, parallel)",
        description="Run a campaign: verification, slenderness (h/d 3..9), friction "
        "(mu_s 0.1..0.9), records (every catalogued record) or synthetic. Finished runs "
        "are kept and skipped when the campaign is run again.")
    p.add_argument("name", choices=["verification", "slenderness", "friction", "records",
                                    "synthetic"])
    p.add_argument("--jobs", type=int, default=None,
                   help="parallel single-thread YADE processes (default: all cores)")
    p.add_argument("--records", default=None, metavar="ID,ID",
                   help="comma-separated record ids or paths instead of the campaign's own")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="campaign directory (default results/<name>)")
    p.add_argument("--animations", type=int, default=1,
                   help="number of toppled runs to animate as GIF (default 1)")
    p.set_defaults(func=campaign_command)


def campaign_command(args):
    record_ids = [r for r in args.records.split(",") if r] if args.records else None
    run_campaign(args.name, jobs=args.jobs, record_ids=record_ids, campaign_dir=args.out,
                 animations=args.animations)
    return 0
