"""``records``: process strong-motion records into npz, Table 1 (records.csv) and figures."""
import os
from multiprocessing import Pool
from pathlib import Path

import pandas as pd

from pipeline import RESULTS_DIR, files
from pipeline.cli._fields import add_arguments, from_args
from pipeline.cli._record_options import RecordsOptions
from pipeline.files import InputError, check_jobs, die_with_parent
from pipeline.motion import Motion
from pipeline.motion.measures import record_parameters
from pipeline.records import CACHE_DIR, build_motion, peer_check, processed_motion, resolve, sets

NAME = "records"
ORDER = 10
HELP = "process strong-motion records: npz, Table 1 (records.csv), figures"
DESCRIPTION = ("Process strong-motion records (catalogue ids from records/catalog.csv, a record "
               "set, or record files: PEER AT2, DMG V1, ASDF, MiniSEED, SAC, ...) into "
               "<out>/<id>.npz, records.csv (Table 1) and <id>.png.  Sets: " + "; ".join(
                   f"{name}: {text}" for name, text in sets.SETS.items()) + ".")
DEFAULT_OUT = RESULTS_DIR / "records"


def setup(parser):
    parser.add_argument("records", nargs="*", metavar="ID_OR_PATH",
                        help="catalogue id (e.g. GM20) or record file")
    parser.add_argument("--all", action="store_true",
                        help="process every usable catalogued record (= --set all)")
    parser.add_argument("--set", dest="record_set", choices=sets.names(), default=None,
                        help="process a record set: " + ", ".join(sets.names()))
    add_arguments(parser, RecordsOptions)
    parser.add_argument("--out", type=Path, default=None,
                        help="output directory (default results/records)")
    parser.add_argument("--no-figures", action="store_true", help="skip the per-record figures")
    parser.add_argument("--jobs", type=int, default=None,
                        help="processes drawing the figures (default: all cores)")


def parameters_table(motions):
    """Table 1 rows (DataFrame) for a list of (record id, Motion)."""
    rows = []
    for record_id, motion in motions:
        meta = motion.meta
        row = {"id": record_id, "label": meta.get("label"), "event": meta.get("event"),
               "station": meta.get("station"), "magnitude": meta.get("magnitude"),
               "mechanism": meta.get("mechanism"), "has_vertical": meta.get("has_vertical"),
               "horizontals_compass": meta.get("horizontals_compass")}
        row.update(record_parameters(motion))
        rows.append(row)
    return pd.DataFrame(rows)


def run(args):
    back_azimuth = from_args(RecordsOptions, args).back_azimuth
    specs = sets.record_ids("all") if args.all else []
    if args.record_set:
        specs += [i for i in sets.record_ids(args.record_set) if i not in specs]
    specs += [spec for spec in args.records if spec not in specs]
    if not specs:
        raise InputError("name records (ids or files) or use --all or --set NAME")
    jobs = check_jobs(args.jobs)
    out_dir = args.out if args.out is not None else DEFAULT_OUT
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"--out {out_dir} exists and is not a directory")

    # read and process everything in memory first: a bad input writes nothing
    motions, seen = [], {}
    for spec in specs:
        source = resolve(spec)
        key = None if source.processed else source.key(back_azimuth)
        record_id = source.id
        if seen.get(record_id, key) != key:
            record_id = f"{record_id}-{key[:6]}"          # two inputs with one name
        seen[record_id] = key
        out_path = out_dir / f"{record_id}.npz"
        if source.processed:
            motions.append((record_id, Motion.load(source.path), out_path, True))
            continue
        current = _load_current(out_path, key)
        if current is not None:
            motions.append((record_id, current, out_path, False))
            print(f"{record_id}: up to date", flush=True)
        else:
            motions.append((record_id, _motion(spec, source, back_azimuth, key, out_dir),
                            out_path, True))
            print(f"{record_id}: processed", flush=True)

    figures = []
    for record_id, motion, out_path, fresh in motions:
        if fresh:
            motion.save(out_path)
        figure = out_path.with_suffix(".png")
        if not args.no_figures and (fresh or not figure.is_file()):
            figures.append((motion, figure))
    plot_motions(figures, jobs)
    table = parameters_table([(rid, motion) for rid, motion, _, _ in motions])
    _update_table(Path(out_dir) / "records.csv", table)
    sources = {rid: spec for spec, (rid, _, _, _) in zip(specs, motions)}
    peer = peer_check.peer_table([(rid, motion) for rid, motion, _, _ in motions],
                                 lambda rid: processed_motion(sources[rid], cache_dir=None,
                                                              mode="none")[0])
    if not peer.empty:
        _update_table(Path(out_dir) / "peer_check.csv", peer)
        report_peer_check(pd.read_csv(Path(out_dir) / "peer_check.csv", dtype={"id": str}))
    print(f"wrote {len(motions)} records to {out_dir}", flush=True)
    return 0


def plot_motions(figures, jobs):
    """Draw each (motion, png path) of ``figures`` (:func:`~pipeline.figures.records.
    plot_motion`), in ``jobs`` processes when there are several."""
    if jobs < 2 or len(figures) < 2:
        for figure in figures:
            _plot_motion(figure)
        return
    with Pool(min(jobs, len(figures)), initializer=die_with_parent,
              initargs=(os.getpid(),)) as pool:          # leaving it (Ctrl-C too) kills it
        for _ in pool.imap_unordered(_plot_motion, figures, chunksize=4):
            pass


def _plot_motion(figure):
    from pipeline.figures.records import plot_motion  # lazy: the stage runs only with the command (light start-up and --help)
    plot_motion(*figure)


def report_peer_check(table):
    """Print the PEER check's medians and worst cases (ours / PEER's, RotD50)."""
    for label, stats in peer_check.summary(table).items():
        for key, s in stats.items():
            if key != "records":
                print(f"PEER check, {label.replace('_', '-')} records, {key}: median "
                      f"{s['median']:.3f}, worst {s['worst']:.3f} ({s['worst_id']}; "
                      f"{s['records']} records)")


def _motion(spec, source, back_azimuth, key, out_dir):
    """The processed motion: through the content-keyed motion cache (results/cache/motions)
    when the output lies inside results/, else from the cache if there, else built here."""
    if _inside_results(out_dir):
        return processed_motion(spec, back_azimuth)[0]
    cached = _load_current(CACHE_DIR / f"{key}.npz", key)
    return cached if cached is not None else build_motion(source, back_azimuth, key)


def _inside_results(path):
    results = RESULTS_DIR.resolve()
    path = Path(path).resolve()
    return path == results or results in path.parents


def _load_current(path, key):
    if not path.is_file():
        return None
    try:
        motion = Motion.load(path)
    except InputError:
        return None
    return motion if motion.meta.get("processing", {}).get("input_hash") == key else None


def _update_table(path, table):
    """Write records.csv: these rows replace same-id rows of an existing table."""
    if path.is_file():
        old = pd.read_csv(path, dtype={"id": str})
        table = pd.concat([old[~old["id"].isin(table["id"])], table], ignore_index=True)
    files.write_csv(path, table)
