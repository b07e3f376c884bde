"""Command line: ``python -m pipeline <command> [options]``.

Each stage module exposes ``add_command(subparsers)`` which registers its
sub-command and sets ``func(args) -> int``.  Bad input raises
:class:`pipeline.files.InputError`, reported here as one line on stderr with
exit status 2.
"""
import argparse
import importlib
import sys

from pipeline.files import InputError

COMMAND_MODULES = [
    "pipeline.records",
    "pipeline.run",
    "pipeline.verify",
    "pipeline.campaign",
    "pipeline.synthetics",
    "pipeline.report",
    "pipeline.animate",
]


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python -m pipeline",
        description="Simulate toppling columns (Hinzen 2009) with YADE: records, runs, "
        "verification, campaigns, synthetics and the report.")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # stage not written yet
                continue
            raise
        module.add_command(subparsers)
    return parser


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted: finished results are kept", file=sys.stderr)
        return 130
