"""A generous hang bound for tests (a bound, never a timing): a regression that blocks fails
instead of hanging the suite."""
import signal
from contextlib import contextmanager


@contextmanager
def hang_bound(seconds, error=TimeoutError, note=""):
    """Raise ``error`` in the main thread once ``seconds`` (s) pass; a blocked open of a named
    pipe is interrupted by the signal.  ``note`` follows the message."""
    def stop(*_):
        raise error(f"no answer within {seconds} s{note}")
    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
