"""Command line: ``python -m pipeline <command>`` (or ``toppling <command>``).

Each module of this package is one command and defines ``NAME``, ``HELP``,
``setup(parser)`` and ``run(args) -> int``; commands are found with pkgutil, so
a new command is one new module.  A :class:`~pipeline.files.ToolError` becomes
one line on stderr: exit status 2 for bad input, 1 for other failures; Ctrl-C
exits 130 (SIGTERM 143) after finished results are written.  The stages say what they do
through :mod:`logging` (logger ``pipeline``); :func:`setup_logging` prints it as lines.
"""
import argparse
import errno
import importlib
import logging
import pkgutil
import sys

from pipeline import INTERRUPTED, interrupted_status
from pipeline.files import InputError, ToolError


class TerminalHandler(logging.Handler):
    """The stages' log messages as plain lines: on stdout, or on stderr when logged with
    ``extra={"stderr": True}``; a warning as ``warning: ...``.  The stream is looked up
    at each message (a redirected ``sys.stdout`` is followed)."""

    def emit(self, record):
        try:
            text = record.getMessage()
            if record.levelno >= logging.WARNING:
                text = f"warning: {text}"
            stream = sys.stderr if getattr(record, "stderr", False) else sys.stdout
            stream.write(text + "\n")
            stream.flush()
        except Exception:                   # logging's own convention: never raise
            self.handleError(record)


def setup_logging():
    """Print the ``pipeline`` logger's messages (INFO and above) on the terminal, once."""
    logger = logging.getLogger("pipeline")
    logger.setLevel(logging.INFO)
    logger.propagate = False
    if not any(isinstance(h, TerminalHandler) for h in logger.handlers):
        logger.addHandler(TerminalHandler())


def commands():
    """Command modules, in the order they are listed."""
    modules = [importlib.import_module(f"{__name__}.{m.name}")
               for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    return sorted(modules, key=lambda m: getattr(m, "ORDER", 50))


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python -m pipeline",
        description="Simulate toppling columns (Hinzen 2009) with YADE: records, runs, "
        "verification, campaigns, synthetics and the report.")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in commands():
        sub = subparsers.add_parser(module.NAME, help=module.HELP,
                                    description=getattr(module, "DESCRIPTION", module.HELP))
        module.setup(sub)
        sub.set_defaults(func=module.run)
    return parser


def empty_path_option(argv):
    """The first option given an empty value (``--out ''``), or None: an empty path would
    mean the current directory."""
    argv = list(sys.argv[1:] if argv is None else argv)
    for k, arg in enumerate(argv):
        if arg.startswith("--") and "=" in arg and arg.split("=", 1)[1] == "":
            return arg.split("=", 1)[0]
        if arg.startswith("--") and k + 1 < len(argv) and argv[k + 1] == "":
            return arg
    return None


def main(argv=None):
    setup_logging()
    parser = build_parser()
    empty = empty_path_option(argv)
    if empty:
        print(f"error: {empty} is empty (give a value; for a path, '.' is the current "
              "directory)", file=sys.stderr)
        return 2
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ToolError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(INTERRUPTED, file=sys.stderr)
        return interrupted_status()
    except OSError as exc:
        what = "disk full" if exc.errno == errno.ENOSPC else exc.strerror or str(exc)
        where = f": {exc.filename}" if exc.filename else ""
        print(f"error: {what}{where} (nothing partial was written)", file=sys.stderr)
        return 1
