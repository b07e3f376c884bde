import os
import sys

from pipeline.cli import main

code = main()
if code == 130:             # Ctrl-C: results are written; skip the slow interpreter shutdown
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
raise SystemExit(code)
