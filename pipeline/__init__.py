"""Toppling columns in archaeoseismology: records -> YADE scenarios -> downfall statistics.

Workflow of Hinzen (2009), BSSA 99(5). Units SI; axes x = East, y = North,
z = Up; azimuths in degrees clockwise from North in [0, 360).
"""
from pathlib import Path

__version__ = "0.1.0"

PROJECT_ROOT = Path(__file__).resolve().parent.parent
RECORDS_DIR = PROJECT_ROOT / "records"
RESULTS_DIR = PROJECT_ROOT / "results"
YADE_SCRIPTS_DIR = PROJECT_ROOT / "yade_scripts"
# the last line after Ctrl-C (exit status 130), whenever it comes
INTERRUPTED = "interrupted: finished results are kept"
