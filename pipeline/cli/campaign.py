"""``campaign``: run one of the paper's experiments (resumable, parallel).

    python -m pipeline campaign slenderness --jobs 2
"""
from pathlib import Path

from pipeline import campaign

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
                       help="parallel single-thread YADE processes (default: all cores)")
        q.add_argument("--records", default=None, metavar="ID,ID",
                       help="comma-separated record ids or paths instead of the campaign's own")
        q.add_argument("--out", type=Path, default=None, metavar="DIR",
                       help=f"campaign directory (default results/{name})")
        q.add_argument("--animations", type=int, default=1,
                       help="number of toppled runs to animate as GIF (default 1)")


def run(args):
    records = [r for r in args.records.split(",") if r] if args.records else None
    campaign.run_campaign(args.name, jobs=args.jobs, records=records, campaign_dir=args.out,
                          animations=args.animations)
    return 0
