"""Processing of a raw 3-component acceleration: an ordered list of named steps.

Like gmprocess, the processing is configuration: ``DEFAULT_STEPS`` lists
``(name, parameters)`` pairs; each name is a function registered with
:func:`step`.  Every step returns what it actually did (e.g. the band used),
which becomes the motion's ``meta["processing"]["steps"]`` provenance.

Default (the order of gmprocess and PEER: offsets out, taper, band-pass, then a
baseline on the filtered record): cut the record to its signal window (0.1-99.5 % of
the Arias intensity of a high-passed copy, plus a margin as long as the band-pass
filter's transient, 1.5 x corners / freqmin: 60 s at 0.1 Hz; exact zeros at the file's
ends count as no data); remove an offset and linear trend fitted to the quiet samples
outside the Arias window (the pre-event mean of PEER, gmprocess's ``pre`` detrending;
with less than 1 s of quiet data, the mean of all samples): a pulse's own nonzero
mean is never taken for an offset; zeros where the window reaches beyond the data;
Hann taper of at most 2 s per end (inside the margins, so it never touches the strong
motion); zero-phase 4-pole Butterworth band-pass from max(0.1 Hz, the record's lowest
usable frequency) to min(25 Hz, its highest usable frequency, 0.8 x Nyquist) on a
zero-padded copy (1.5 x corners / freqmin seconds each side, Boore & Bommer 2005);
double integration and removal of a displacement baseline t^2..t^6 (ending at rest)
through its second derivative in the acceleration, so acceleration, velocity and
displacement are trapezoidal integrals of each other.  Because the window holds the
filter's whole transient, the band-passed displacement already returns to rest and
the baseline is a small correction over minutes: a pulse keeps its band-passed
acceleration and velocity, and a permanent displacement (fling) is removed only as
far as the band-pass removes it (tests/records/test_pulses.py).

No step's extent scales with the file's length: the same strong motion gives
the same processed motion however much quiet time surrounds it in the file
(tests/records/test_processing_invariance.py).
"""
import math

import numpy as np
from obspy import Stream, Trace
from scipy.integrate import cumulative_trapezoid

from pipeline.files import InputError
from scipy.signal import butter, sosfiltfilt

STEPS = {}

BAND = {"freqmin_hz": 0.1, "freqmax_hz": 25.0, "nyquist_fraction": 0.8, "corners": 4}


def filter_transient_s(freqmin_hz, corners):
    """Length (s) of a Butterworth filter's transient (Boore & Bommer 2005): the zero pad
    of the band-pass and the signal window's margin."""
    return 1.5 * corners / freqmin_hz


DEFAULT_STEPS = (
    ("trim_to_signal", {"arias_fractions": (0.001, 0.995),
                        "margin_s": filter_transient_s(BAND["freqmin_hz"], BAND["corners"]),
                        "highpass_hz": 0.1}),
    ("remove_offset", {"trend": "linear", "min_quiet_s": 1.0}),
    ("pad_to_window", {}),
    ("taper", {"max_percentage": 0.05, "max_length_s": 2.0, "type": "hann"}),
    ("bandpass", {**BAND, "pad": True}),
    ("integrate_baseline", {"max_power": 6}),
)


# A motion that is already processed (a synthetic, a shake-table record, an analytic
# pulse) runs as given: its acceleration untouched, velocity and displacement its
# trapezoidal integrals.
AS_GIVEN_STEPS = (("integrate", {}),)
MODES = {"default": DEFAULT_STEPS, "none": AS_GIVEN_STEPS}   # --processing choices


def steps_for(mode):
    """The processing steps of a ``--processing`` mode ("default" or "none")."""
    try:
        return MODES[mode]
    except KeyError:
        raise InputError(f"--processing must be one of {', '.join(MODES)}, got {mode!r}") \
            from None


def step(func):
    """Register a processing step under its function name."""
    STEPS[func.__name__] = func
    return func


class Work:
    """The record under processing: ``acc`` (n, 3) m/s^2 East/North/Up, ``dt`` s,
    ``band`` the usable band (lo, hi) in Hz from the record's metadata (None if unknown);
    ``vel`` and ``disp`` once integrated."""

    def __init__(self, acc, dt, band=(None, None), name="record"):
        self.acc, self.dt, self.band, self.name = np.array(acc, float), float(dt), band, name
        self.vel = self.disp = None
        self.start_s = 0.0          # time of the first sample in the original record
        self.pad = (0, 0)           # zero samples to add before and after (pad_to_window)
        self.signal = (0, len(self.acc))   # samples of acc inside the Arias window

    def stream(self):
        return Stream([Trace(np.array(self.acc[:, i]), header={"delta": self.dt})
                       for i in range(3)])

    def from_stream(self, stream):
        self.acc = np.column_stack([tr.data for tr in stream])


@step
def trim_to_signal(work, arias_fractions=(0.001, 0.995), margin_s=5.0, highpass_hz=0.1):
    """Cut the record to its signal window [t_lo - margin, t_hi + margin], t_lo and t_hi
    where the Arias intensity (all components) of a demeaned, high-passed copy reaches
    the given fractions.  Runs of exact zeros at either end (no data) are dropped first.
    Where the window reaches beyond the data, ``pad_to_window`` later adds zeros, so the
    processed motion spans the same window whatever surrounds the signal in the file."""
    npts = len(work.acc)
    nonzero = np.flatnonzero(np.any(work.acc != 0.0, axis=1))
    if nonzero.size == 0:
        return {"window_s": [0.0, work.dt * (npts - 1)], "trimmed": False}
    first, last = int(nonzero[0]), int(nonzero[-1]) + 1
    acc = work.acc[first:last] - work.acc[first:last].mean(axis=0)
    if highpass_hz and highpass_hz < 0.5 / work.dt and len(acc) > 12:
        sos = butter(2, highpass_hz, btype="highpass", fs=1.0 / work.dt, output="sos")
        acc = sosfiltfilt(sos, acc, axis=0)
    energy = np.cumsum((acc ** 2).sum(axis=1))
    lo, hi = np.searchsorted(energy, np.array(arias_fractions) * energy[-1]) + first
    margin = int(round(margin_s / work.dt))
    i0, i1 = lo - margin, hi + margin + 1                  # may reach beyond the data
    work.pad = (max(0, first - i0), max(0, i1 - last))
    work.acc = work.acc[max(i0, first):min(i1, last)]
    work.signal = (lo - max(i0, first), hi + 1 - max(i0, first))
    work.start_s = i0 * work.dt
    return {"window_s": [i0 * work.dt, (i1 - 1) * work.dt], "signal_s": [lo * work.dt, hi * work.dt],
            "arias_fractions": list(arias_fractions),
            "margin_s": margin_s, "data_s": [max(i0, first) * work.dt, (min(i1, last) - 1) * work.dt]}


SIGNAL_END_MARGIN_S = 5.0   # quiet simulated after a motion's signal (s)


def signal_end_in_motion_s(steps):
    """End (s, on the processed motion's clock) of the signal, SIGNAL_END_MARGIN_S after
    its 99.5 % Arias point, from the provenance of ``process``; None without a cut.  A
    run treats the motion as over there: what follows is the band-pass filter's
    transient, far below anything that moves a column."""
    trim = next((s for s in steps if s["step"] == "trim_to_signal"), None)
    if trim is None or "signal_s" not in trim:
        return None
    return float(trim["signal_s"][1] - trim["window_s"][0] + SIGNAL_END_MARGIN_S)


def signal_end_s(acc, dt):
    """End (s) of the signal window of a motion that does not pass through the
    processing (a synthetic): ``trim_to_signal`` with the default steps' Arias fractions
    and SIGNAL_END_MARGIN_S (no filter transient to hold), at most the last sample."""
    work = Work(acc, dt)
    trim = dict(DEFAULT_STEPS)["trim_to_signal"]
    window = trim_to_signal(work, **{**trim, "margin_s": SIGNAL_END_MARGIN_S})["window_s"]
    return min(window[1], dt * (len(acc) - 1))


@step
def pad_to_window(work):
    """Zeros before and after the data up to the signal window of ``trim_to_signal``."""
    before, after = getattr(work, "pad", (0, 0))
    work.acc = np.pad(work.acc, ((before, after), (0, 0)))
    return {"zeros_before_s": before * work.dt, "zeros_after_s": after * work.dt}


@step
def remove_offset(work, trend="linear", min_quiet_s=1.0):
    """Subtract an offset (``trend`` "mean") or offset and slope ("linear") fitted to the
    quiet samples outside the Arias window of ``trim_to_signal``; with less than
    ``min_quiet_s`` of them, the mean of all samples (zero for a whole pulse)."""
    if trend not in ("mean", "linear"):
        raise InputError(f"remove_offset: trend must be 'mean' or 'linear', got {trend!r}")
    n = len(work.acc)
    lo, hi = work.signal
    quiet = np.r_[0:max(0, min(lo, n)), max(0, hi):n]
    t = np.arange(n) * work.dt
    if len(quiet) * work.dt < min_quiet_s:
        work.acc = work.acc - work.acc.mean(axis=0)
        return {"trend": "mean", "fitted_to": "all samples", "quiet_s": len(quiet) * work.dt}
    design = np.column_stack([np.ones(len(quiet))] + ([t[quiet]] if trend == "linear" else []))
    coeffs = np.linalg.lstsq(design, work.acc[quiet], rcond=None)[0]
    full = np.column_stack([np.ones(n)] + ([t] if trend == "linear" else []))
    work.acc = work.acc - full @ coeffs
    return {"trend": trend, "fitted_to": "quiet samples", "quiet_s": len(quiet) * work.dt}


@step
def taper(work, max_percentage=0.05, type="hann", max_length_s=None):
    """obspy taper on both ends; records the length actually used (s)."""
    stream = work.stream()
    stream.taper(max_percentage=max_percentage, type=type, max_length=max_length_s)
    work.from_stream(stream)
    # obspy: per side, min(max_percentage * npts, max_length / dt) samples
    length = max_percentage * len(work.acc) * work.dt
    if max_length_s is not None:
        length = min(length, max_length_s)
    return {"type": type, "max_percentage": max_percentage, "max_length_s": max_length_s,
            "taper_s": float(length)}


@step
def bandpass(work, freqmin_hz=0.1, freqmax_hz=25.0, nyquist_fraction=0.8, corners=4, pad=False):
    """Zero-phase Butterworth band-pass within the record's usable band; with ``pad``,
    on a copy padded with 1.5 corners / freqmin seconds of zeros on each side (the
    filter's transient, Boore & Bommer 2005), removed afterwards."""
    low, high = work.band
    freqmin = max(freqmin_hz, low or 0.0)
    freqmax = min(freqmax_hz, high or np.inf, nyquist_fraction * 0.5 / work.dt)
    if freqmin >= freqmax:
        raise InputError(f"{work.name}: sampling too coarse for the {freqmin:g}-{freqmax:g} Hz "
                         "band")
    npad = int(round(1.5 * corners / freqmin / work.dt)) if pad else 0
    original = work.acc
    work.acc = np.pad(original, ((npad, npad), (0, 0)))
    stream = work.stream()
    stream.filter("bandpass", freqmin=freqmin, freqmax=freqmax, corners=corners, zerophase=True)
    work.from_stream(stream)
    work.acc = work.acc[npad:npad + len(original)]
    return {"freqmin_hz": float(freqmin), "freqmax_hz": float(freqmax), "corners": corners,
            "zerophase": True, "pad_s": npad * work.dt}


@step
def integrate_baseline(work, max_power=6):
    """Integrate twice, then remove a displacement baseline sum_{k=2..K} c_k (t/T)^k
    (pinned to end at rest) through its second derivative in the acceleration and
    integrate again, so acc, vel and disp stay consistent."""
    dt = work.dt
    vel = cumulative_trapezoid(work.acc, dx=dt, axis=0, initial=0.0)
    disp = cumulative_trapezoid(vel, dx=dt, axis=0, initial=0.0)
    work.acc = work.acc - baseline_acceleration(disp, vel, dt, max_power)
    work.vel = cumulative_trapezoid(work.acc, dx=dt, axis=0, initial=0.0)
    work.disp = cumulative_trapezoid(work.vel, dx=dt, axis=0, initial=0.0)
    return {"max_power": max_power, "fit_window_s": [0.0, dt * (len(work.acc) - 1)]}


@step
def integrate(work):
    """Velocity and displacement as trapezoidal integrals of the acceleration as given."""
    work.vel = cumulative_trapezoid(work.acc, dx=work.dt, axis=0, initial=0.0)
    work.disp = cumulative_trapezoid(work.vel, dx=work.dt, axis=0, initial=0.0)
    return {}


def baseline_acceleration(disp, vel, dt, max_power=6):
    """Second derivative of the least-squares baseline p(t) = sum_{k=2..K} c_k (t/T)^k of
    each displacement column, with p(T) = disp(T) and p'(T) = vel(T) enforced by
    heavily weighted rows; p(0) = p'(0) = 0 by construction."""
    n = disp.shape[0]
    duration = dt * (n - 1)
    tau = np.arange(n) * dt / duration
    powers = np.arange(2, max_power + 1)
    design = tau[:, None] ** powers
    end_value = np.ones_like(powers, dtype=float)              # tau = 1
    end_slope = powers / duration                              # d/dt of (t/T)^k at t = T
    weight = 1e3 * np.sqrt(n)
    curvature = powers * (powers - 1) * tau[:, None] ** (powers - 2) / duration ** 2
    result = np.zeros_like(disp)
    scale = np.max(np.abs(disp), axis=0)
    for i in range(disp.shape[1]):
        if scale[i] == 0:
            continue
        matrix = np.vstack([design, weight * end_value, weight * duration * end_slope])
        target = np.r_[disp[:, i], weight * disp[-1, i], weight * duration * vel[-1, i]]
        coeffs = np.linalg.lstsq(matrix, target, rcond=None)[0]
        result[:, i] = curvature @ coeffs
    return result


MAX_PROCESSED_SAMPLES = 4_000_000   # samples per component processing may hold (about
#                                     0.1 GB an array; a 10-min lab table at 3.3 kHz and
#                                     its margins: 2.8 million)


def held_samples(n, dt, steps):
    """The most samples per component ``steps`` may hold at once for a record of ``n``
    samples every ``dt`` s: the record, the signal window's margin and the band-pass's
    zero pad on each side (both a fixed time, so a fine time step makes them long)."""
    params = dict(steps)
    margin_s = params.get("trim_to_signal", {}).get("margin_s", 0.0)
    band = params.get("bandpass", {})
    pad_s = filter_transient_s(band.get("freqmin_hz", BAND["freqmin_hz"]),
                               band.get("corners", BAND["corners"])) if band.get("pad") else 0.0
    return n + 2 * math.ceil(round((margin_s + pad_s) / dt, 6)), margin_s + pad_s


def process(enz, dt, band=(None, None), steps=DEFAULT_STEPS, name="record"):
    """Run ``steps`` on an (n, 3) acceleration (m/s^2); return (acc, vel, disp, provenance).

    provenance: list of {"step": name, **what it did}.  The last step must integrate.
    A ``trim_to_signal`` step shortens the record: provenance gives its window.  A record
    whose processing would hold more than MAX_PROCESSED_SAMPLES per component is refused
    before any array is made.
    """
    unknown = [s for s, _ in steps if s not in STEPS]
    if unknown:
        raise InputError(f"unknown processing step(s): {', '.join(unknown)}")
    held, margins_s = held_samples(len(enz), dt, steps)
    if held > MAX_PROCESSED_SAMPLES:
        raise InputError(f"{name}: {len(enz)} samples every {dt:.3g} s and {margins_s:g} s of "
                         f"filter margins on each side make {held:,} samples, more than the "
                         f"{MAX_PROCESSED_SAMPLES:,} processing holds: is the time step in "
                         "seconds?")
    work = Work(enz, dt, band, name)
    provenance = []
    for name_, params in steps:
        provenance.append({"step": name_, **STEPS[name_](work, **params)})
    if work.vel is None:
        raise InputError("processing steps must end with an integration step")
    return work.acc, work.vel, work.disp, provenance
