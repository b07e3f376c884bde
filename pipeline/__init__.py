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
_STOP_ASKED = []                    # signals received by stop(), kept even if swallowed
STOP_RETRY_S = 0.05                 # a stop asked inside an import comes this long after


def stopped_by(signum):
    """Note the signal that stops this process (its exit status is 128 + it)."""
    _STOPPED_BY[0] = signum


def stop(signum, frame=None):
    """The command's handler of Ctrl-C and SIGTERM: a KeyboardInterrupt in the main
    thread (children killed, finished results kept), and a note that outlives it: a
    KeyboardInterrupt raised where Python only prints it (a weakref callback, a
    ``__del__``) is lost, the note is not (:func:`stop_asked`).  Inside an import (where
    it would break the module, or become an ImportError) it comes STOP_RETRY_S after."""
    stopped_by(signum)
    _STOP_ASKED.append(signum)
    if _importing(frame):
        signal.signal(signal.SIGALRM, lambda _, later: stop(signum, later))
        signal.setitimer(signal.ITIMER_REAL, STOP_RETRY_S)
        return
    raise KeyboardInterrupt


def _importing(frame):
    """Whether ``frame`` runs inside Python's import machinery."""
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def stop_asked():
    """Whether Ctrl-C or SIGTERM reached :func:`stop` in this process."""
    return bool(_STOP_ASKED)


def raise_if_stop_asked():
    """Raise KeyboardInterrupt if a stop was asked (a loop's check for one swallowed)."""
    if _STOP_ASKED:
        raise KeyboardInterrupt


def stop_on_signals():
    """Make Ctrl-C and SIGTERM (a plain ``kill``) stop this process through :func:`stop`."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, stop)


def interrupted_status():
    """Exit status of an interrupted command: 128 + its signal (130 Ctrl-C, 143 SIGTERM)."""
    return 128 + _STOPPED_BY[0]
