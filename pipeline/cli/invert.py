"""``invert``: a posterior over earthquake sources from fallen and standing columns.

    python -m pipeline invert OBSERVATIONS.json [--out DIR] [--quick] [--scheduler ADDRESS]
    python -m pipeline invert --demo [--grid demo]          # make invert-demo
    python -m pipeline invert --member-study                # make invert-study
    python -m pipeline invert --hidden-truth TRUTH.json --table FILE
"""
import math
import time
from pathlib import Path

from pipeline.constants import COLUMN_TYPES
from pipeline import RESULTS_DIR
from pipeline.campaign.executor import RUN_CORE_S as FORWARD_RUN_CORE_S
from pipeline.files import LONG_RUN_S, InputError, check_jobs, check_long

NAME = "invert"
ORDER = 45
HELP = "invert fallen columns for the earthquake source (posterior map, back azimuth)"
DESCRIPTION = (
    "Bayesian source inversion: candidate epicentres on a grid around the sites, mechanisms "
    "(strike sampled), depths and magnitudes; the likelihood of each observed column (fallen "
    "toward an azimuth, or standing) from a forward table of twin-model ensembles shaken by "
    "pyprop8 synthetics (campaign inversion-forward, cached by content: a second inversion "
    "reuses every run). Writes posterior.csv, inversion_summary.json, posterior_map.png and "
    "marginals.png. Observations schema: docs/inversion.md.")


def _floats(name):
    def parse(text):
        try:
            values = tuple(float(v) for v in text.split(",") if v.strip())
        except ValueError:
            raise InputError(f"--{name}: not a comma-separated list of numbers: {text!r}") \
                from None
        if not values or not all(math.isfinite(v) for v in values):
            raise InputError(f"--{name}: give finite numbers, got {text!r}")
        return values
    return parse


def _weights(text):
    out = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"--mechanism-prior {item!r}: expected NAME=WEIGHT") from None
        if not (math.isfinite(out[name.strip()]) and out[name.strip()] >= 0):
            raise InputError(f"--mechanism-prior {item!r}: weights must be >= 0")
    if not any(out.values()):
        raise InputError("--mechanism-prior: at least one weight must be positive")
    return out


def setup(p):
    from pipeline.inversion.grid import GRIDS, MECHANISMS
    from pipeline.inversion.likelihood import DEFAULT_FLOOR, DEFAULT_KERNEL_DEG
    _what_to_run(p, GRIDS)
    _forward_grid(p.add_argument_group("forward grid (the table: one ensemble per node)"),
                  GRIDS["full"], MECHANISMS)
    _candidates(p.add_argument_group("candidates and prior"), DEFAULT_KERNEL_DEG,
                DEFAULT_FLOOR)


def _what_to_run(p, grids):
    """The observations, the modes (--demo, --hidden-truth, --member-study), the table and
    where runs go."""
    quick = grids["quick"]
    p.add_argument("observations", nargs="?", type=Path, metavar="OBSERVATIONS.json",
                   help="sites with their fallen and standing columns (schema: docs/inversion.md)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="output directory (default results/inversion/<file stem>; "
                   "--demo: results/inversion)")
    p.add_argument("--quick", action="store_true",
                   help=f"coarse smoke run (a few minutes): {len(quick.slices())} slices, "
                   f"rings {','.join(f'{v:g}' for v in quick.distances_km)} km every "
                   f"{quick.azimuth_step_deg:g} deg, {quick.members} members, "
                   f"{quick.duration_s:g} s motions to {quick.fmax_hz:g} Hz; candidates "
                   "within 12 km, strike every 90 deg")
    p.add_argument("--grid", choices=sorted(grids), default=None,
                   help="forward-grid preset (default full; --quick = quick; the demo "
                   "machine ran 'demo'); the options below override it")
    p.add_argument("--demo", action="store_true",
                   help="synthetic truth tests and the paper's scenario (make invert-demo)")
    p.add_argument("--hidden-truth", type=Path, default=None, metavar="TRUTH.json",
                   help="a hidden-truth test: the source you choose, twin models simulated "
                   "at your sites (members no table uses), inverted with the forward table; "
                   "writes observations.json and the inversion with the truth checked "
                   "(schema: docs/inversion.md)")
    p.add_argument("--member-study", action="store_true",
                   help="truth tests at 3, 6, 12, 24 and 48 likelihood members per node "
                   "(observed columns from 16 members no likelihood uses): how many fallen "
                   "columns bound the back azimuth, the epicentre and the magnitude (default "
                   "--grid study: 2,304 runs; make invert-study)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run the forward campaign on an existing Dask cluster")
    p.add_argument("--jobs", type=int, default=None,
                   help="parallel YADE runs / pyprop8 processes (default: all cores)")
    p.add_argument("--allow-long", action="store_true",
                   help=f"start a forward table estimated to take over "
                   f"{LONG_RUN_S / 3600:g} h on this machine (refused otherwise; the "
                   "estimate is printed before any run)")
    p.add_argument("--table", type=Path, default=None, metavar="FILE",
                   help="use this forward table file (tables/forward_table_<key>.npz) as it "
                   "is: no pyprop8, no YADE (its code version is reported, not checked)")
    p.add_argument("--forward-dir", type=Path, default=None, metavar="DIR",
                   help="campaign directory of the forward runs (default "
                   "results/inversion-forward)")


def _forward_grid(g, full, mechanisms):
    """The forward grid's options; their defaults from the ``full`` preset."""
    g.add_argument("--mechanisms", default=None, metavar="LIST",
                   help="comma-separated, of " + ", ".join(
                       f"{k} (dip {v[0]:g}, rake {v[1]:g})" for k, v in mechanisms.items())
                   + " or NAME:DIP:RAKE (default: " + ",".join(m[0] for m in full.mechanisms)
                   + ")")
    g.add_argument("--depths", default=None, metavar="KM,KM",
                   help="hypocentre depths (default "
                   + ",".join(f"{v:g}" for v in full.depths_km) + ")")
    g.add_argument("--magnitudes", default=None, metavar="MW,MW",
                   help="moment magnitudes 4.5-7.5 (default "
                   + ",".join(f"{v:g}" for v in full.magnitudes) + ")")
    g.add_argument("--distances", default=None, metavar="KM,KM",
                   help="table rings: epicentral distances (default "
                   + ",".join(f"{v:g}" for v in full.distances_km) + ")")
    g.add_argument("--azimuth-step", type=float, default=None, metavar="DEG",
                   help=f"table node spacing in azimuth from strike (default "
                   f"{full.azimuth_step_deg:g})")
    g.add_argument("--members", type=int, default=None,
                   help=f"ensemble members per node (default {full.members}; plus the "
                   "nominal run)")
    g.add_argument("--seed", type=int, default=None, help="Latin-hypercube seed")
    g.add_argument("--fmax", type=float, default=None, metavar="HZ",
                   help=f"synthetics up to this frequency (default {full.fmax_hz:g})")
    g.add_argument("--duration", type=float, default=None, metavar="S",
                   help=f"motion duration (default {full.duration_s:g} s)")


def _candidates(c, kernel_deg, floor):
    """The candidate sources, the prior and the likelihood's options."""
    c.add_argument("--radius", type=float, default=None, metavar="KM",
                   help="epicentres within this distance of a site (default 30; quick 12; "
                   "demo 25) and within the forward table's last ring of every site")
    c.add_argument("--step", type=float, default=None, metavar="KM",
                   help="epicentre grid spacing (default 1)")
    c.add_argument("--strike-step", type=float, default=None, metavar="DEG",
                   help="strikes sampled every DEG from 0 (default 30; quick 90)")
    c.add_argument("--mechanism-prior", default=None, metavar="NAME=W,...",
                   help="prior weights of the mechanisms (default: equal)")
    c.add_argument("--gr-b", type=float, default=None, metavar="B",
                   help="Gutenberg-Richter prior on magnitude, 10^(-B M) (default uniform)")
    c.add_argument("--kernel-deg", type=float, default=kernel_deg,
                   help=f"width of the von Mises kernel on ensemble falls (default "
                   f"{kernel_deg:g})")
    c.add_argument("--floor", type=float, default=floor,
                   help=f"fraction of uniform density mixed into every direction density "
                   f"(default {floor:g})")
    c.add_argument("--likelihood", choices=("independent", "predictive"),
                   default="independent",
                   help="independent (default): product over columns; predictive: columns "
                   "of one site share its motion and the ensemble is finite (Polya urn: a "
                   "site's own falls inform its next column; calibrated when there are many "
                   "more columns per site than members per node)")
    c.add_argument("--trials", type=int, default=None,
                   help="trials per configuration (--demo: default 20; --member-study: "
                   "default 200)")


CANDIDATE_PRESETS = {"quick": {"radius_km": 12.0, "step_km": 1.0, "strike_step_deg": 90.0},
                     "study": {"radius_km": 15.0, "step_km": 1.0, "strike_step_deg": 30.0},
                     "demo": {"radius_km": 25.0, "step_km": 1.0, "strike_step_deg": 30.0},
                     "full": {"radius_km": 30.0, "step_km": 1.0, "strike_step_deg": 30.0}}


def build_grids(args):
    """(preset name, TableGrid, CandidateGrid) from the options; InputError if impossible."""
    from pipeline.inversion.grid import GRIDS, parse_mechanisms
    from pipeline.campaign.ensemble import check_seed
    from pipeline.inversion.posterior import CandidateGrid
    if args.quick and args.grid not in (None, "quick"):
        raise InputError("--quick is --grid quick: give one of them")
    preset = "quick" if args.quick else (
        args.grid or ("study" if getattr(args, "member_study", False) else "full"))
    mechanisms = parse_mechanisms(args.mechanisms) if args.mechanisms else None
    depths = _floats("depths")(args.depths) if args.depths else None
    magnitudes = _floats("magnitudes")(args.magnitudes) if args.magnitudes else None
    distances = _floats("distances")(args.distances) if args.distances else None
    prior = _weights(args.mechanism_prior) if args.mechanism_prior else None
    grid = GRIDS[preset].replace(
        mechanisms=mechanisms, depths_km=depths, magnitudes=magnitudes,
        distances_km=distances, azimuth_step_deg=args.azimuth_step,
        members=args.members, seed=check_seed(args.seed), fmax_hz=args.fmax,
        duration_s=args.duration)
    values = dict(CANDIDATE_PRESETS[preset])
    for key, option in (("radius_km", args.radius), ("step_km", args.step),
                        ("strike_step_deg", args.strike_step)):
        if option is not None:
            values[key] = option
    candidates = CandidateGrid(
        **values, mechanisms=None if mechanisms is None else tuple(m[0] for m in mechanisms),
        depths_km=depths, magnitudes=magnitudes, mechanism_prior=prior, gr_b=args.gr_b)
    return preset, grid, candidates


def described_columns(observations, base_dir="."):
    """{column name in the observations: its description dict} for every column that is a
    column file (a shipped example's name, or a file, relative to ``base_dir`` (the
    observations file's folder) when it is there); one-line errors before anything runs."""
    from pipeline.campaign.column_file import description
    from pipeline.scenario.column_format import example_names
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


def finished_runs(campaign_dir):
    """How many runs a campaign directory holds finished (0 when there is none)."""
    runs_dir = Path(campaign_dir) / "runs"
    return sum(1 for _ in runs_dir.glob("*/summary.json")) if runs_dir.is_dir() else 0


def preflight(grid, forward_dir, jobs, allow_long, more_runs=0):
    """Say how many runs the forward table needs, how many may be cached and roughly how
    long the rest (and ``more_runs`` twin runs of the same cost) take on ``jobs`` cores;
    the long-run gate (:func:`pipeline.files.check_long`: InputError past LONG_RUN_S
    without ``allow_long``).  Returns the estimate (s)."""
    from pipeline.inversion.forward import DEFAULT_FORWARD_DIR
    forward_dir = Path(forward_dir or DEFAULT_FORWARD_DIR)
    done = finished_runs(forward_dir)
    needed = grid.n_runs()
    rest = max(0, needed - done)
    print(f"forward table: {needed} YADE runs, up to {min(done, needed)} of them cached in "
          f"{forward_dir}; the rest takes about {rest * FORWARD_RUN_CORE_S / jobs / 60:.0f} "
          f"min on {jobs} core(s) ({FORWARD_RUN_CORE_S:g} s a run)", flush=True)
    what = "this forward table" + (" and the hidden truth's runs" if more_runs else "")
    return check_long(what, rest + more_runs, FORWARD_RUN_CORE_S, jobs, allow_long,
                      "choose --grid demo or quick, or give a computed --table")


def forward_table(args, grid, sibling_of=None, more_runs=0):
    """(ForwardTable, info dict): the --table file (``sibling_of``: the table of ``grid``
    beside that file), or the campaign's (run or reused); ``more_runs``: twin runs the
    command starts after the table, counted by the long-run gate with it."""
    from pipeline.inversion.forward import run_forward, table_path
    from pipeline.inversion.table import ForwardTable
    path = args.table if sibling_of is None else \
        Path(sibling_of).parent / table_path(".", grid).name
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
    if not args.scheduler:
        preflight(grid, args.forward_dir, check_jobs(args.jobs), args.allow_long, more_runs)
    table, cost = run_forward(grid, args.forward_dir, check_jobs(args.jobs), args.scheduler)
    return table, {**cost, "grid": grid.as_dict(), "grid_key": grid.key(),
                   "code_version": table.info.get("code_version"), "reused_file": False}


def run(args):
    from pipeline.inversion import run_inversion
    from pipeline.inversion.observations import load_observations
    if (args.demo + args.member_study + (args.observations is not None)
            + (args.hidden_truth is not None)) != 1:
        raise InputError("give one of an OBSERVATIONS.json file, --demo, --member-study or "
                         "--hidden-truth TRUTH.json")
    if args.trials is not None and not ((args.demo or args.member_study)
                                        and 1 <= args.trials <= 1000):
        raise InputError("--trials (1-1000) goes with --demo or --member-study")
    from pipeline.inversion.likelihood import check_model_options
    check_model_options(args.kernel_deg, args.floor, getattr(args, "likelihood", "independent"))
    check_jobs(args.jobs)
    preset, grid, candidates = build_grids(args)
    if args.demo:
        return _run_demo(args, preset, grid, candidates)
    if args.member_study:
        return _run_member_study(args, grid, candidates)
    if args.hidden_truth is not None:
        return _run_hidden_truth(args, grid, candidates)
    observations = load_observations(args.observations)
    described = described_columns(observations, args.observations.parent)
    out = args.out or RESULTS_DIR / "inversion" / args.observations.stem
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(args, grid)
    if args.table is not None and described and table.info.get("grid"):
        from pipeline.inversion.grid import TableGrid          # the --table file's grid
        grid = TableGrid(**table.info["grid"])
    for name, data in described.items():
        column_table, column_info = forward_table(args, grid.replace(column_file=data),
                                                  sibling_of=args.table)
        table = table.with_column(name, column_table)
        info.setdefault("described_columns", {})[name] = column_info
    summary = run_inversion(observations, out, table, candidates, args.kernel_deg,
                            args.floor, forward_info=info, likelihood=args.likelihood)
    lo, hi = summary["back_azimuth_ci95_deg"]
    mech = max(summary["mechanism_posterior"], key=summary["mechanism_posterior"].get)
    print(f"{observations.n_fallen} fallen of {observations.n_columns} columns at "
          f"{len(observations.sites)} site(s); {summary['candidates']} candidates")
    print(f"back azimuth from {summary['first_site']}: MAP {summary['back_azimuth_map_deg']:.0f}"
          f" deg, 95 % arc [{lo:.0f}, {hi:.0f}] ({summary['back_azimuth_ci95_width_deg']:.0f} "
          f"deg); distance 95 % {summary['distance_ci95_km'][0]:.1f}-"
          f"{summary['distance_ci95_km'][1]:.1f} km; 95 % area "
          f"{summary['credible_area_95_km2']:.0f} km^2; most probable mechanism {mech} "
          f"({summary['mechanism_posterior'][mech]:.2f})")
    _say_reach(summary)
    print(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0


def _say_reach(summary):
    """What the forward table's reach left out of the candidates asked for, and a warning
    line when the posterior piles against the edge of the reach."""
    if summary.get("beyond_table_fraction"):
        print(f"candidates: within {summary['table_last_ring_km']:g} km of every site, where "
              f"the forward table's rings end; {summary['beyond_table_fraction']:.0%} of the "
              f"epicentres within --radius {summary['candidate_grid']['radius_km']:g} km of "
              "a site lie beyond and are left out")
    if summary.get("reach_warning"):
        print(f"warning: {summary['reach_warning']}")


def _run_demo(args, preset, grid, candidates):
    from pipeline.inversion import EXAMPLES_DIR, run_inversion
    from pipeline.inversion.demo import (BOUND_ANSWER_KEY, BOUND_TEXT, DEFAULT_TRIALS, paper_grid,
                                         paper_nodes, run_demo)
    from pipeline.inversion.forward import run_forward, table_path
    from pipeline.inversion.table import ForwardTable
    from pipeline.inversion.observations import load_observations
    out = args.out or RESULTS_DIR / "inversion"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(args, grid)
    costs = {"main": info}
    paper_tables = {}
    for source in ("strike_slip", "thrust"):
        if paper_nodes(table, source) is not None:
            paper_tables[source] = table
            continue
        pgrid = paper_grid(grid, source, quick=preset == "quick")
        if args.table is not None:      # a table file: its siblings, else nothing is run
            sibling = Path(args.table).parent / table_path(".", pgrid).name
            if sibling.is_file():
                paper_tables[source] = ForwardTable.load(sibling)
                costs[f"paper_{source}"] = {"table": str(sibling), "reused_file": True,
                                            "yade_wall_s": paper_tables[source].info.get(
                                                "yade_wall_s"),
                                            "runs": paper_tables[source].info.get("runs")}
            else:
                print(f"paper scenario, {source}: no {sibling.name} beside --table: skipped")
            continue
        paper_tables[source], cost = run_forward(pgrid, args.forward_dir,
                                                 check_jobs(args.jobs), args.scheduler)
        costs[f"paper_{source}"] = {**cost, "grid": pgrid.as_dict()}
    summary = run_demo(table, out, candidates, paper_tables, DEFAULT_TRIALS if args.trials is None else args.trials,
                       args.kernel_deg, args.floor, forward_info={**info, "costs": costs,
                                                                  "preset": preset})
    example = EXAMPLES_DIR / "two_sites.json"
    observations = load_observations(example)
    if set(observations.column_types()) <= set(table.columns):
        ex = run_inversion(observations, out / "example_two_sites", table, candidates,
                           args.kernel_deg, args.floor, forward_info=info,
                           likelihood=args.likelihood)
        summary["example"] = {"file": f"pipeline/inversion/examples/{example.name}",
                              **{k: ex[k] for k in ("map_epicentre_km", "back_azimuth_map_deg",
                                                    "back_azimuth_ci95_deg",
                                                    "back_azimuth_ci68_deg",
                                                    "distance_ci95_km", "mechanism_posterior",
                                                    "credible_area_95_km2", "reach_km",
                                                    "reach_limit", "reach_edge_fraction",
                                                    "reach_warning")}}
    summary["elapsed_s"] = round(time.monotonic() - started, 1)
    from pipeline.files import write_json
    write_json(out / "demo_summary.json", summary)
    for kind, cov in summary["coverage"].items():
        print(f"truth tests, {kind} likelihood: {cov['trials']} inversions; the 95 % "
              f"back-azimuth arc holds the truth in {cov['back_azimuth_95']:.0%}, the 95 % "
              f"epicentre region in {cov['epicentre_95']:.0%}")
    for row in summary[BOUND_ANSWER_KEY]:
        k = row["fallen_per_site"]
        print(f"  {row['likelihood']}, {row['mechanism']}, {row['sites']} site(s): " +
              (f"{BOUND_TEXT} from {k} fallen column(s) per site" if k else
               f"not within {BOUND_TEXT} (median {row['largest_tested_width_median_deg']:.0f} deg "
               "at the most columns tried)"))
    print(f"wrote {out / 'demo_summary.json'} ({summary['elapsed_s']:.0f} s)")
    return 0


def _run_member_study(args, grid, candidates):
    """invert --member-study: the forward table (run, reused or --table), then the study's
    truth tests; writes member_study.csv (one row per trial), member_study_summary.csv,
    member_study.json (the answer per likelihood), member_study.png (the back azimuth) and
    member_study_source.png (the epicentre and the magnitude)."""
    from pipeline.files import write_csv, write_json
    from pipeline.figures.inversion import plot_member_study, plot_member_study_source
    from pipeline.inversion.demo import BOUND_DEG
    from pipeline.inversion.study import (LIKELIHOOD_MEMBERS, OBSERVATION_MEMBERS,
                                          STUDY_TRIALS, member_study, study_answer,
                                          study_summary)
    out = args.out or RESULTS_DIR / "inversion" / "member-study"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    table, info = forward_table(args, grid)
    trials = STUDY_TRIALS if args.trials is None else args.trials

    jobs = check_jobs(args.jobs)
    print(f"member study: {trials} trials per configuration on {jobs} process(es)",
          flush=True)

    def progress(kind, size):
        print(f"  {kind} likelihood, {size} members: done "
              f"({time.monotonic() - started:.0f} s)", flush=True)

    rows = member_study(table, candidates, trials=trials, kernel_deg=args.kernel_deg,
                        floor=args.floor, jobs=jobs, progress=progress)
    if rows.empty:
        raise InputError("no column of the observed members ever fell: nothing to test "
                         "(a grid with stronger shaking: closer rings, higher Mw)")
    summary = study_summary(rows)
    answer = study_answer(summary)
    write_csv(out / "member_study.csv", rows)
    write_csv(out / "member_study_summary.csv", summary)
    figure = plot_member_study(summary, out / "member_study.png", BOUND_DEG)
    source_figure = plot_member_study_source(summary, out / "member_study_source.png")
    write_json(out / "member_study.json", {
        "answer": answer, "likelihood_members": sorted(summary["likelihood_members"].unique()
                                                       .tolist()),
        "requested_likelihood_members": list(LIKELIHOOD_MEMBERS),
        "observation_members": OBSERVATION_MEMBERS, "trials": trials,
        "forward_table": info, "figure": figure.name, "source_figure": source_figure.name,
        "toppled_fraction_by_slice": table.toppled_fraction_by_slice(),
        "elapsed_s": round(time.monotonic() - started, 1)})
    for text in answer.values():
        print(text)
    print(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0


def _run_hidden_truth(args, grid, candidates):
    """invert --hidden-truth: the forward table, the hidden members' runs at the truth's
    sites (campaign inversion-truth in OUT/truth-runs), observations.json from them, and
    the inversion with the truth marked and checked (inversion_summary.json: truth)."""
    from pipeline.campaign import run_campaign
    from pipeline.files import write_json
    from pipeline.inversion import run_inversion
    from pipeline.inversion.grid import TableGrid
    from pipeline.inversion.observations import parse_observations
    from pipeline.inversion.truth import check_hidden, load_truth
    truth = load_truth(args.hidden_truth)
    out = args.out or RESULTS_DIR / "inversion" / f"truth-{args.hidden_truth.stem}"
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} is a file, not a directory")
    started = time.monotonic()
    truth_runs = max(0, sum(s[3] for s in truth.sites) - finished_runs(out / "truth-runs"))
    if args.table is not None and not args.scheduler:
        check_long("the hidden truth's runs", truth_runs, FORWARD_RUN_CORE_S,
                   check_jobs(args.jobs), args.allow_long, "fewer sites or twins")
    table, info = forward_table(args, grid, more_runs=truth_runs)
    table_grid = TableGrid(**table.info["grid"]) if table.info.get("grid") else grid
    check_hidden(truth, table_grid)
    from pipeline.inversion.posterior import check_reach
    check_reach(truth.sites, table.distances_km[-1], candidates)     # before any run
    print(f"hidden truth: {sum(s[3] for s in truth.sites)} twin runs at "
          f"{len(truth.sites)} site(s)", flush=True)
    result = run_campaign("inversion-truth", jobs=check_jobs(args.jobs),
                          campaign_dir=out / "truth-runs", animations=0,
                          options={"truth": truth, "grid": table_grid, "jobs": args.jobs},
                          scheduler=args.scheduler)
    data = {"sites": [{"name": name, "east_km": e, "north_km": n,
                       "columns": result["sites"][name]}
                      for name, e, n, _ in truth.sites]}
    write_json(out / "observations.json", data)
    observations = parse_observations(data, "observations.json")
    summary = run_inversion(observations, out, table, candidates, args.kernel_deg, args.floor,
                            forward_info=info, likelihood=args.likelihood,
                            truth=truth.as_truth())
    check = summary["truth"]["check"]
    print(f"{observations.n_fallen} of {observations.n_columns} simulated columns fell; the "
          f"95 % regions hold the true epicentre: {check['epicentre_in_95']}, back azimuth: "
          f"{check['back_azimuth_in_95']}, distance: {check['distance_in_95']}, magnitude: "
          f"{check['mw_in_95']}; MAP epicentre {check['map_epicentre_error_km']:.1f} km off")
    _say_reach(summary)
    print(f"wrote {out} ({time.monotonic() - started:.0f} s)")
    return 0

