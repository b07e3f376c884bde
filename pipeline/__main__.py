"""``python -m pipeline`` and the ``toppling`` console script.

Ctrl-C at any moment, during the imports of start-up too, ends with one line and exit
status 130 (after finished results are written)."""
import os
import sys

from pipeline import INTERRUPTED


def console():
    try:
        from pipeline.cli import main
        code = main()
    except KeyboardInterrupt:                  # during start-up, before main() handles it
        print(INTERRUPTED, file=sys.stderr)
        code = 130
    if code == 130:         # Ctrl-C: results are written; skip the slow interpreter shutdown
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    raise SystemExit(code)


if __name__ == "__main__":
    console()
