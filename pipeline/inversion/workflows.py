"""The inversion's workflows, as the ``invert`` command runs them: a forward table (run,
reused or read from a file, after a cost estimate and the long-run gate), then an
inversion of an observations file, the demo, the member study or a hidden truth.  Each
writes its files under ``options.out`` and returns the command's exit status."""
import json
import logging
import time
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.campaign import run_campaign
from pipeline.campaign.column_file import description
from pipeline.campaign.executor import RUN_CORE_S as FORWARD_RUN_CORE_S
from pipeline.campaign.run_dirs import count_finished
from pipeline.constants import COLUMN_TYPES
from pipeline.figures.inversion import plot_member_study, plot_member_study_source
from pipeline.files import InputError, check_jobs, check_long, write_csv, write_json
from pipeline.hazard.site_motion import site_motion
from pipeline.inversion import EXAMPLES_DIR, run_inversion, study
from pipeline.inversion.candidates import check_reach
from pipeline.inversion.demo import BOUND_ANSWER_KEY, BOUND_DEG, BOUND_TEXT, DEFAULT_TRIALS, \
    run_demo
from pipeline.inversion import forward
from pipeline.inversion.grid import TableGrid
from pipeline.inversion.likelihood import SITE_COLUMNS
from pipeline.inversion.observations import load_observations, parse_observations
from pipeline.inversion.paper_scenario import paper_grid, paper_nodes
from pipeline.inversion.study_summary import beyond_hypothesis, placement_summary, \
    study_answer, study_summary, warning_rates
from pipeline.inversion.table import ForwardTable
from pipeline.inversion.truth import check_hidden, load_truth
from pipeline.scenario.column_format import example_names

log = logging.getLogger(__name__)


def described_columns(observations, base_dir="."):
    """{column name in the observations: its description dict} for every column that is a
    column file (a shipped example's name, or a file, relative to ``base_dir`` (the
    observations file's folder) when it is there); one-line errors before anything runs."""
    out = {}
    for name in observations.column_types():
        if name in COLUMN_TYPES:
            continue
        beside = Path(base_dir) / name          # an absolute name stays itself
        if name in example_names():
            source = name
        elif beside.is_file():
            source = str(beside)
        else:                                   # never the current directory's file
            raise InputError(f"column {name!r}: no such file or shipped example (looked for "
                             f"{beside} beside the observations; shipped: "
                             f"{', '.join(example_names())})")
        try:
            out[name] = description(source)
        except InputError as exc:
            message = str(exc).removeprefix(f"--column-file {source}: ")
            raise InputError(f"column {name!r}: {message}") from None
    return out


def preflight(grid, forward_dir, jobs, allow_long, more_runs=0):
    """Say how many runs the forward table needs, how many may be cached and roughly how
    long the rest (and ``more_runs`` twin runs of the same cost) take on ``jobs`` cores;
    the long-run gate (:func:`pipeline.files.check_long`: InputError past LONG_RUN_S
    without ``allow_long``).  Returns the estimate (s)."""
    forward_dir = Path(forward_dir or forward.DEFAULT_FORWARD_DIR)
    done = count_finished(forward_dir)
    needed = grid.n_runs()
    rest = max(0, needed - done)
    log.info(f"forward table: {needed} YADE runs, up to {min(done, needed)} of them cached in "
             f"{forward_dir}; the rest takes about {rest * FORWARD_RUN_CORE_S / jobs / 60:.0f} "
             f"min on {jobs} core(s) ({FORWARD_RUN_CORE_S:g} s a run)")
    what = "this forward table" + (" and the hidden truth's runs" if more_runs else "")
    return check_long(what, rest + more_runs, FORWARD_RUN_CORE_S, jobs, allow_long,
                      "choose --grid demo or quick, or give a computed --table")


def forward_table(options, grid, sibling_of=None, more_runs=0):
    """(ForwardTable, info dict): the --table file (``sibling_of``: the table of ``grid``
    beside that file), or the campaign's (run or reused); ``more_runs``: twin runs the
    command starts after the table, counted by the long-run gate with it."""
    path = options.table if sibling_of is None else \
        Path(sibling_of).parent / forward.table_path(".", grid).name
    if sibling_of is not None and not path.is_file():
        raise InputError(f"--table: no forward table of the described column "
                         f"{grid.column_file['name']!r} ({path.name}) beside {sibling_of}")
    if path is not None:
        table = ForwardTable.load(path)
        info = {"table": str(path), "grid": table.info.get("grid"),
                "grid_key": table.info.get("grid_key"),
                "code_version": table.info.get("code_version"),
                "yade_wall_s": table.info.get("yade_wall_s"), "runs": table.info.get("runs"),
                "reused_file": True}
        return table, info
    if options.extend_table is not None:
        return _extended_table(options, grid, more_runs)
    if not options.scheduler:
        preflight(grid, options.forward_dir, check_jobs(options.jobs), options.allow_long, more_runs)
    table, cost = forward.run_forward(grid, options.forward_dir, check_jobs(options.jobs),
                                      options.scheduler)
    return table, {**cost, "grid": grid.as_dict(), "grid_key": grid.key(),
                   "code_version": table.info.get("code_version"), "reused_file": False}


def _extended_table(options, grid, more_runs):
    """(ForwardTable, info dict) of ``grid``: the --extend-table file's rings and the rings
    it lacks, run as a table of their own and joined to it."""
    base = ForwardTable.load(options.extend_table)
    stated = dict(base.info.get("grid") or {})
    wanted = json.loads(json.dumps(grid.as_dict()))
    if {k: v for k, v in stated.items() if k != "distances_km"} != \
            {k: v for k, v in wanted.items() if k != "distances_km"}:
        raise InputError(f"--extend-table {options.extend_table}: its grid differs from the "
                         "chosen one in more than its rings (--grid, --mechanisms, --depths, "
                         "--magnitudes, --azimuth-step, --members, --seed, --fmax, "
                         "--duration)")
    extra = sorted(set(base.distances_km.tolist()) - set(grid.distances_km))
    if extra:
        raise InputError(f"--extend-table {options.extend_table}: its rings {extra} km are "
                         "not among the chosen --distances")
    missing = tuple(d for d in grid.distances_km if d not in base.distances_km)
    info = {"table": str(options.extend_table), "grid": wanted, "reused_file": True,
            **{k: base.info.get(k) for k in ("grid_key", "code_version", "yade_wall_s",
                                              "runs")}}
    if not missing:
        return base, info
    rings = grid.replace(distances_km=missing)
    log.info(f"--extend-table: running the rings {', '.join(f'{d:g}' for d in missing)} km "
             f"and joining them to {options.extend_table}")
    if not options.scheduler:
        preflight(rings, options.forward_dir, check_jobs(options.jobs), options.allow_long,
                  more_runs)
    ring_table, cost = forward.run_forward(rings, options.forward_dir,
                                           check_jobs(options.jobs), options.scheduler)
    table = base.with_rings(ring_table, grid)
    path = table.save(forward.table_path(options.forward_dir, grid))
    log.info(f"wrote {path} (the joined table)")
    return table, {**cost, "table": str(path), "grid": wanted, "grid_key": grid.key(),
                   "code_version": table.info["code_version"], "reused_file": False,
                   "extended": str(options.extend_table)}


def _say_reach(summary):
    """What the forward table's reach left out of the candidates asked for, and a warning
    line when the posterior piles against the edge of the reach."""
    if summary.get("beyond_table_fraction"):
        log.info(f"candidates: within {summary['table_last_ring_km']:g} km of every site, where "
                 f"the forward table's rings end; {summary['beyond_table_fraction']:.0%} of the "
                 f"epicentres within --radius {summary['candidate_grid']['radius_km']:g} km of "
                 "a site lie beyond and are left out")
    if summary.get("reach_warning"):
        log.warning(f"{summary['reach_warning']}")
    if summary.get("reach_note"):
        log.info(f"note: {summary['reach_note']}")


def demo(options, preset, grid, candidates):
    """invert --demo: the forward table, the paper scenario's tables, the truth tests
    (demo_summary.json) and the two-site example."""
    out = options.out or RESULTS_DIR / "inversion"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(options, grid)
    costs = {"main": info}
    paper_tables = {}
    for source in ("strike_slip", "thrust"):
        if paper_nodes(table, source) is not None:
            paper_tables[source] = table
            continue
        pgrid = paper_grid(grid, source, quick=preset == "quick")
        if options.table is not None:      # a table file: its siblings, else nothing is run
            sibling = Path(options.table).parent / forward.table_path(".", pgrid).name
            if sibling.is_file():
                paper_tables[source] = ForwardTable.load(sibling)
                costs[f"paper_{source}"] = {"table": str(sibling), "reused_file": True,
                                            "yade_wall_s": paper_tables[source].info.get(
                                                "yade_wall_s"),
                                            "runs": paper_tables[source].info.get("runs")}
            else:
                log.info(f"paper scenario, {source}: no {sibling.name} beside --table: skipped")
            continue
        paper_tables[source], cost = forward.run_forward(pgrid, options.forward_dir,
                                                 check_jobs(options.jobs), options.scheduler)
        costs[f"paper_{source}"] = {**cost, "grid": pgrid.as_dict()}
    summary = run_demo(table, out, candidates, paper_tables, DEFAULT_TRIALS if options.trials is None else options.trials,
                       options.kernel_deg, options.floor, forward_info={**info, "costs": costs,
                                                                  "preset": preset})
    example = EXAMPLES_DIR / "two_sites.json"
    observations = load_observations(example)
    if set(observations.column_types()) <= set(table.columns):
        ex = run_inversion(observations, out / "example_two_sites", table, candidates,
                           options.kernel_deg, options.floor, forward_info=info,
                           likelihood=options.likelihood)
        summary["example"] = {"file": f"pipeline/inversion/examples/{example.name}",
                              **{k: ex[k] for k in ("map_epicentre_km", "back_azimuth_map_deg",
                                                    "back_azimuth_ci95_deg",
                                                    "back_azimuth_ci68_deg",
                                                    "distance_ci95_km", "mechanism_posterior",
                                                    "credible_area_95_km2", "reach_km",
                                                    "reach_limit", "reach_edge_fraction",
                                                    "reach_warning")}}
    summary["elapsed_s"] = round(time.monotonic() - started, 1)
    write_json(out / "demo_summary.json", summary)
    for kind, cov in summary["coverage"].items():
        log.info(f"truth tests, {kind} likelihood: {cov['trials']} inversions; the 95 % "
                 f"back-azimuth arc holds the truth in {cov['back_azimuth_95']:.0%}, the 95 % "
                 f"epicentre region in {cov['epicentre_95']:.0%}")
    for row in summary[BOUND_ANSWER_KEY]:
        k = row["fallen_per_site"]
        log.info(f"  {row['likelihood']}, {row['mechanism']}, {row['sites']} site(s): " +
                 (f"{BOUND_TEXT} from {k} fallen column(s) per site" if k else
               f"not within {BOUND_TEXT} (median {row['largest_tested_width_median_deg']:.0f} deg "
               "at the most columns tried)"))
    log.info(f"wrote {out / 'demo_summary.json'} ({summary['elapsed_s']:.0f} s)")
    return 0


def member_study(options, grid, candidates):
    """invert --member-study: the forward table (run, reused or --table), then the study's
    truth tests; writes member_study.csv (one row per trial), member_study_summary.csv,
    member_study_placements.csv (per placement of the source), member_study.json (the answer per likelihood), member_study.png (the back azimuth) and
    member_study_source.png (the epicentre and the magnitude)."""
    out = options.out or RESULTS_DIR / "inversion" / "member-study"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(options, grid)
    trials = study.STUDY_TRIALS if options.trials is None else options.trials

    jobs = check_jobs(options.jobs)
    log.info(f"member study: {trials} trials per configuration on {jobs} process(es)")

    def progress(kind, size):
        log.info(f"  {kind} likelihood, {size} members: done "
                 f"({time.monotonic() - started:.0f} s)")

    rows = study.member_study(table, candidates, trials=trials, kernel_deg=options.kernel_deg,
                        floor=options.floor, jobs=jobs, progress=progress)
    if rows.empty:
        raise InputError("no column of the observed members ever fell: nothing to test "
                         "(a grid with stronger shaking: closer rings, higher Mw)")
    summary = study_summary(rows)
    answer = study_answer(summary)
    placements = placement_summary(rows)
    write_csv(out / "member_study.csv", rows)
    write_csv(out / "member_study_summary.csv", summary)
    write_csv(out / "member_study_placements.csv", placements)
    figure = plot_member_study(summary, out / "member_study.png", BOUND_DEG)
    source_figure = plot_member_study_source(summary, out / "member_study_source.png")
    write_json(out / "member_study.json", {
        "answer": answer, "likelihood_members": sorted(summary["likelihood_members"].unique()
                                                       .tolist()),
        "requested_likelihood_members": list(study.LIKELIHOOD_MEMBERS),
        "observation_members": study.OBSERVATION_MEMBERS, "trials": trials,
        "site_columns": SITE_COLUMNS, "seed": study.STUDY_SEED,
        "forward_table": info, "figure": figure.name, "source_figure": source_figure.name,
        "toppled_fraction_by_slice": table.toppled_fraction_by_slice(),
        "reach_warning": warning_rates(placements),
        "beyond_hypothesis": beyond_hypothesis(rows),
        "elapsed_s": round(time.monotonic() - started, 1)})
    for text in answer.values():
        log.info(text)
    log.info(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0


def hidden_truth(truth_file, options, grid, candidates):
    """invert --hidden-truth: the forward table, the hidden members' runs at the truth's
    sites (campaign inversion-truth in OUT/truth-runs), observations.json from them, and
    the inversion with the truth marked and checked (inversion_summary.json: truth)."""
    truth = load_truth(truth_file)
    out = options.out or RESULTS_DIR / "inversion" / f"truth-{truth_file.stem}"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    truth_runs = max(0, sum(s[3] for s in truth.sites) - count_finished(out / "truth-runs"))
    if options.table is not None and not options.scheduler:
        check_long("the hidden truth's runs", truth_runs, FORWARD_RUN_CORE_S,
                   check_jobs(options.jobs), options.allow_long, "fewer sites or twins")
    table, info = forward_table(options, grid, more_runs=truth_runs)
    table_grid = TableGrid(**table.info["grid"]) if table.info.get("grid") else grid
    check_hidden(truth, table_grid)
    check_reach(truth.sites, table.distances_km[-1], candidates)     # before any run
    log.info(f"hidden truth: {sum(s[3] for s in truth.sites)} twin runs at "
             f"{len(truth.sites)} site(s)")
    result = run_campaign("inversion-truth", jobs=check_jobs(options.jobs),
                          campaign_dir=out / "truth-runs", animations=0,
                          options={"truth": truth, "grid": table_grid, "jobs": options.jobs},
                          scheduler=options.scheduler)
    data = {"sites": [{"name": name, "east_km": e, "north_km": n,
                       "columns": result["sites"][name]}
                      for name, e, n, _ in truth.sites]}
    write_json(out / "observations.json", data)
    observations = parse_observations(data, "observations.json")
    summary = run_inversion(observations, out, table, candidates, options.kernel_deg, options.floor,
                            forward_info=info, likelihood=options.likelihood,
                            truth=truth.as_truth())
    check = summary["truth"]["check"]
    log.info(f"{observations.n_fallen} of {observations.n_columns} simulated columns fell; the "
             f"95 % regions hold the true epicentre: {check['epicentre_in_95']}, back azimuth: "
             f"{check['back_azimuth_in_95']}, distance: {check['distance_in_95']}, magnitude: "
             f"{check['mw_in_95']}; MAP epicentre {check['map_epicentre_error_km']:.1f} km off")
    _say_reach(summary)
    log.info(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0


def site_motions(observations, fragility_for, pgv_pga_s=None):
    """site_motion.json's content: the PGA range each site's standing and fallen columns
    allow (:func:`pipeline.hazard.site_motion.site_motion`), every site with columns."""
    sites = [site_motion(observations, site.name, fragility_for, pgv_pga_s)
             for site in observations.sites if site.columns]
    return {"sites": sites,
            "pga_measure": "RotD50: each column type's fragility put on it "
                           "(sites.*.fragilities.*.pga_measure)",
            "assumption": "each site's columns decided by one event, independent given its "
                          "motion; the sites' bounds are separate (the source's posterior "
                          "ties them together)"}


def invert_file(observations_file, options, grid, candidates, site_fragility=None):
    """invert OBSERVATIONS.json: the forward table (run, reused or ``options.table``) and
    the described columns' tables, then the inversion (``options.out``, default
    results/inversion/<file stem>).  ``site_fragility`` ((fragility_for(column type),
    PGV/PGA) or None): the PGA range at each site too (site_motion.json)."""
    observations = load_observations(observations_file)
    motions = None if site_fragility is None else site_motions(observations, *site_fragility)
    described = described_columns(observations, observations_file.parent)
    out = options.out or RESULTS_DIR / "inversion" / observations_file.stem
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(options, grid)
    if options.table is not None and described and table.info.get("grid"):
        grid = TableGrid(**table.info["grid"])
    for name, data in described.items():
        column_table, column_info = forward_table(options, grid.replace(column_file=data),
                                                  sibling_of=options.table)
        table = table.with_column(name, column_table)
        info.setdefault("described_columns", {})[name] = column_info
    summary = run_inversion(observations, out, table, candidates, options.kernel_deg,
                            options.floor, forward_info=info, likelihood=options.likelihood,
                            site_motion=motions)
    lo, hi = summary["back_azimuth_ci95_deg"]
    mech = max(summary["mechanism_posterior"], key=summary["mechanism_posterior"].get)
    log.info(f"{observations.n_fallen} fallen of {observations.n_columns} columns at "
             f"{len(observations.sites)} site(s); {summary['candidates']} candidates")
    direction = ("not known (the source may lie beyond the reach)"
                 if summary["back_azimuth_map_deg"] is None else
                 f"MAP {summary['back_azimuth_map_deg']:.0f} deg, 95 % arc [{lo:.0f}, {hi:.0f}] "
                 f"({summary['back_azimuth_ci95_width_deg']:.0f} deg)")
    lo_km, hi_km = summary["distance_ci95_km"]
    far = "unbounded" if hi_km is None else f"{hi_km:.1f} km"
    more = " or more (extrapolated)" if summary["magnitude_ci95_open_above"] else ""
    log.info(f"back azimuth from {summary['first_site']}: {direction}; distance 95 % "
             f"{lo_km:.1f} km to {far}; 95 % area {summary['credible_area_95_km2']:.0f} km^2; "
             f"Mw 95 % {summary['magnitude_ci95'][0]:g}-{summary['magnitude_ci95'][1]:g}"
             f"{more} (the table's {summary['magnitude_range'][0]:g}-"
             f"{summary['magnitude_range'][1]:g}); P(beyond the reach) "
             f"{summary['p_beyond']:.2f}; most probable mechanism {mech} "
             f"({summary['mechanism_posterior'][mech]:.2f})")
    _say_reach(summary)
    for site in (motions or {}).get("sites", []):
        lo_g, hi_g = site["pga_interval95_g"]
        log.info(f"site {site['site']}: {site['fallen']} of {site['columns']} columns fell; "
                 f"PGA (RotD50) 95 % [{'-' if lo_g is None else f'{lo_g:.3g}'}, "
                 f"{'-' if hi_g is None else f'{hi_g:.3g}'}] g"
                 + ("" if site["note"] is None else f" ({site['note']})"))
    log.info(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0
