"""Toppling columns in archaeoseismology: records -> YADE scenarios -> downfall statistics.

Workflow of Hinzen (2009), BSSA 99(5). Units SI; axes x = East, y = North,
z = Up; azimuths in degrees clockwise from North in [0, 360).
"""
import signal
from pathlib import Path

__version__ = "0.1.0"

PROJECT_ROOT = Path(__file__).resolve().parent.parent
RECORDS_DIR = PROJECT_ROOT / "records"
RESULTS_DIR = PROJECT_ROOT / "results"
YADE_SCRIPTS_DIR = PROJECT_ROOT / "yade_scripts"
# the last line after Ctrl-C (exit status 130) or SIGTERM (143), whenever it comes
INTERRUPTED = "interrupted: finished results are kept"
_STOPPED_BY = [signal.SIGINT]       # the signal that interrupted this process


def stopped_by(signum):
    """Note the signal that stops this process (its exit status is 128 + it)."""
    _STOPPED_BY[0] = signum


def stop_on_sigterm():
    """Make SIGTERM (a plain ``kill``) stop this process as Ctrl-C does: a
    KeyboardInterrupt in the main thread (children killed, finished results kept)."""
    def stop(signum, frame):
        stopped_by(signum)
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, stop)


def interrupted_status():
    """Exit status of an interrupted command: 128 + its signal (130 Ctrl-C, 143 SIGTERM)."""
    return 128 + _STOPPED_BY[0]
