"""``campaign``: run one of the paper's experiments (resumable, parallel).

    python -m pipeline campaign slenderness --jobs 2
"""
from pathlib import Path

from pipeline import campaign
from pipeline.cli._fields import add_arguments, from_args
from pipeline.files import LONG_RUN_S, InputError, check_jobs, check_long
from pipeline.records import sets

NAME = "campaign"
ORDER = 40
HELP = "run one of the paper's experiments (resumable, parallel)"
DESCRIPTION = ("Run a campaign. Finished runs are kept and skipped when the campaign is run "
               "again; Ctrl-C stops within seconds and keeps what finished.")


def setup(p):
    sub = p.add_subparsers(dest="name", metavar="NAME", required=True)
    for name in campaign.names():
        definition = campaign.get(name)
        q = sub.add_parser(name, help=definition.help, description=definition.help)
        q.add_argument("--jobs", type=int, default=None,
                       help="parallel single-thread YADE processes (default: all cores; "
                       "with --scheduler: every worker thread of the cluster)")
        q.add_argument("--executor", choices=("threads", "dask"), default=None,
                       help="threads (default): a thread pool, no start-up cost, no port; "
                       "dask: a local Dask cluster of --jobs worker processes on 127.0.0.1")
        q.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="run on an existing Dask cluster (e.g. tcp://10.0.0.5:8786; "
                       "workers: 'dask worker ADDRESS --nthreads 1' with this project "
                       "and YADE installed)")
        q.add_argument("--records", default=None, metavar="ID,ID",
                       help="comma-separated record ids or paths instead of the campaign's own")
        if name != "verification":
            q.add_argument("--set", dest="record_set", choices=sets.names(), default=None,
                           help="the records of a record set instead of the campaign's own ("
                           + "; ".join(f"{k}: {v}" for k, v in sets.SETS.items()) + ")")
        q.add_argument("--out", type=Path, default=None, metavar="DIR",
                       help=f"campaign directory (default results/{name})")
        q.add_argument("--animations", type=int, default=1,
                       help="number of toppled runs to animate as GIF (default 1; 0: none)")
        q.add_argument("--allow-long", action="store_true",
                       help=f"start a campaign estimated to take over "
                       f"{LONG_RUN_S / 3600:g} h on --jobs cores (refused otherwise, before "
                       "any run)")
        if definition.options:
            add_arguments(q, definition.options)


def run(args):
    if args.animations < 0:
        raise InputError(f"--animations {args.animations}: the number of toppled runs to "
                         "animate is 0 or more")
    records = [r for r in args.records.split(",") if r] if args.records else None
    repeated = sorted({r for r in records or [] if records.count(r) > 1})
    if repeated:
        raise InputError(f"--records names {', '.join(repeated)} more than once: a record is "
                         "run and counted once")
    record_set = getattr(args, "record_set", None)
    if record_set:
        if records:
            raise InputError("give either --records or --set, not both")
        records = sets.record_ids(record_set)
    definition = campaign.get(args.name)
    options = {}
    if definition.options:
        options = from_args(definition.options, args).kwargs()
        if definition.options.TAKES_JOBS:
            options["jobs"] = args.jobs
    gated = []          # a driver that asked the gate for all its runs at once

    def run_once(opts):
        return campaign.run_campaign(args.name, jobs=args.jobs, records=records,
                                     campaign_dir=args.out, animations=args.animations,
                                     options=opts, executor=args.executor,
                                     scheduler=args.scheduler,
                                     allow_long=None if gated else args.allow_long)

    def gate(what, runs, run_core_s, advice=""):
        """The long-run gate for a driver's own estimate of all its runs, before the first
        (none on a cluster of unknown size); its runs are then not asked again."""
        if args.jobs is not None or not args.scheduler:
            check_long(what, runs, run_core_s, check_jobs(args.jobs), args.allow_long, advice)
        gated.append(what)

    if definition.driver is None:
        run_once(options)
    else:
        given = list(records or []) + ([options["record"]] if options.get("record") else [])
        definition.driver(run_once, given, args.out or campaign.RESULTS_DIR / args.name,
                          options, gate=gate)
    return 0
