"""``python -m pipeline`` and the ``toppling`` console script.

Ctrl-C at any moment from the command's first line on, during the imports of start-up
too, ends with one line and exit status 130 (after finished results are written); SIGTERM
(a plain ``kill``) the same way with exit status 143.  (Before that line, in the first
tens of milliseconds, Python starts itself and a Ctrl-C is its own.)"""
import os
import signal
import sys

from pipeline import INTERRUPTED, interrupted_status, stop_asked, stop_on_signals, stopped_by


def console():
    # a KeyboardInterrupt raised inside an extension module's import becomes an
    # ImportError with a traceback: during the imports, a stop is noted and acted on after
    pending = []
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda signum, frame: pending.append(signum))
    from pipeline.cli import main  # lazy: after the signal handlers are set (a stop during imports is acted on later)
    stop_on_signals()
    try:
        if pending:
            stopped_by(pending[0])
            raise KeyboardInterrupt
        code = main()
        if stop_asked() and code != interrupted_status():
            raise KeyboardInterrupt            # a stop a library swallowed, unseen by main()
    except KeyboardInterrupt:                  # during start-up, before main() handles it
        print(INTERRUPTED, file=sys.stderr)
        code = interrupted_status()
    if code == interrupted_status():    # results are written; skip the slow shutdown
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    raise SystemExit(code)


if __name__ == "__main__":
    console()
