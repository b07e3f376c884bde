"""``python -m pipeline`` and the ``toppling`` console script.

Ctrl-C at any moment, during the imports of start-up too, ends with one line and exit
status 130 (after finished results are written); SIGTERM (a plain ``kill``) the same way
with exit status 143."""
import os
import sys

from pipeline import INTERRUPTED, interrupted_status, stop_on_sigterm


def console():
    stop_on_sigterm()
    try:
        from pipeline.cli import main
        code = main()
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
