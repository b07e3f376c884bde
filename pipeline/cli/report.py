"""``report``: results/REPORT.md from the campaigns' tables and figures."""
from pathlib import Path

from pipeline import RESULTS_DIR

NAME = "report"
ORDER = 60
HELP = "write results/REPORT.md from the campaigns"


def setup(p):
    p.add_argument("--results", type=Path, default=RESULTS_DIR, help="results directory")


def run(args):
    from pipeline.report import build_report  # lazy: the stage runs only with the command (light start-up and --help)
    print(f"wrote {build_report(args.results)}")
    return 0
