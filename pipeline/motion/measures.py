"""Ground-motion measures of Hinzen (2009) Table 1 and the directions of the largest motions.

Arias intensity uses standard gravity (its definition); the mean period follows
Rathje et al. (1998); durations are 5-95 % Arias significant durations.
"""
import numpy as np
from scipy.integrate import cumulative_trapezoid, trapezoid

from pipeline.constants import STANDARD_GRAVITY

TM_BAND_HZ = (0.25, 20.0)       # Rathje et al. (1998) mean-period band
COMPONENTS = ("e", "n", "z")


def record_parameters(motion):
    """Table 1 numbers of one :class:`~pipeline.motion.Motion`, SI units.

    Per component c in e, n, z: ``pga_c`` (m/s^2), ``pgv_c`` (m/s), ``pgd_c`` (m),
    ``pgv_pga_c`` (s), ``arias_c`` (m/s), ``tm_c`` (s, Rathje et al. 1998 mean
    period over 0.25-20 Hz), ``ts_c`` (s, 5-95 % Arias significant duration);
    None where a component is all zero (no vertical).  Horizontal vector:
    ``pga_h``, ``pgv_h``, ``pgd_h``, ``pgv_pga_h``, ``arias_h`` (sum of E and N)
    and ``az_max_acc_deg``, ``az_max_vel_deg``, ``az_max_disp_deg``: azimuth in
    [0, 360) of the horizontal vector at the time of its peak.  Directionality of
    the displacement: ``disp_perp_ratio`` = peak displacement along
    ``az_max_disp_deg`` / peak perpendicular to it, and ``disp_pulses`` = number of
    half cycles along that azimuth exceeding half the peak.  Also
    ``back_azimuth_deg``, ``epicentral_distance_km``, ``station_latitude``,
    ``station_longitude``, ``event_latitude``, ``event_longitude`` (None when unknown),
    ``duration_s`` and ``dt_s``.
    """
    dt = motion.dt
    params = {}
    for i, comp in enumerate(COMPONENTS):
        acc, vel, disp = (getattr(motion, k)[:, i] for k in ("acc", "vel", "disp"))
        silent = not np.any(acc)
        params[f"pga_{comp}"] = float(np.max(np.abs(acc)))
        params[f"pgv_{comp}"] = float(np.max(np.abs(vel)))
        params[f"pgd_{comp}"] = float(np.max(np.abs(disp)))
        params[f"pgv_pga_{comp}"] = None if silent else params[f"pgv_{comp}"] / params[f"pga_{comp}"]
        params[f"arias_{comp}"] = arias_intensity(acc, dt)
        params[f"tm_{comp}"] = None if silent else mean_period(acc, dt)
        params[f"ts_{comp}"] = None if silent else significant_duration(acc, dt)
    for kind, short in (("acc", "a"), ("vel", "v"), ("disp", "d")):
        peak, azimuth, _ = horizontal_peak(getattr(motion, kind))
        params[f"pg{short}_h"] = peak
        params[f"az_max_{kind}_deg"] = azimuth
    params["pgv_pga_h"] = params["pgv_h"] / params["pga_h"] if params["pga_h"] > 0 else None
    params["arias_h"] = params["arias_e"] + params["arias_n"]
    params.update(displacement_directionality(motion.disp))
    meta = motion.meta
    params["back_azimuth_deg"] = meta.get("back_azimuth_deg")
    params["epicentral_distance_km"] = meta.get("epicentral_distance_km")
    for column, key in (("station_latitude", "station_lat"), ("station_longitude", "station_lon"),
                        ("event_latitude", "event_lat"), ("event_longitude", "event_lon")):
        params[column] = meta.get(key)           # degrees, as records/catalog.csv names them
    params["duration_s"] = motion.duration
    params["dt_s"] = dt
    return params


# ---------------------------------------------------------------- ground-motion measures
def arias_intensity(acc, dt):
    """Arias intensity pi / (2 g) * integral a^2 dt (m/s) of acceleration ``acc`` (m/s^2)."""
    return float(np.pi / (2 * STANDARD_GRAVITY) * trapezoid(np.asarray(acc) ** 2, dx=dt))


def mean_period(acc, dt, band=TM_BAND_HZ):
    """Rathje et al. (1998) mean period (s): sum(C^2 / f) / sum(C^2) over Fourier
    amplitudes C at frequencies f inside ``band`` (Hz)."""
    amplitude = np.abs(np.fft.rfft(acc))
    freq = np.fft.rfftfreq(len(acc), dt)
    inside = (freq >= band[0]) & (freq <= band[1])
    power = amplitude[inside] ** 2
    return float(np.sum(power / freq[inside]) / np.sum(power))


def significant_duration(acc, dt, low=0.05, high=0.95):
    """Time (s) between ``low`` and ``high`` fractions of the cumulative Arias intensity."""
    cumulative = cumulative_trapezoid(np.asarray(acc) ** 2, dx=dt, initial=0.0)
    cumulative /= cumulative[-1]
    time = np.arange(len(acc)) * dt
    t_low, t_high = np.interp([low, high], cumulative, time)
    return float(t_high - t_low)


def horizontal_peak(series):
    """(peak length, azimuth in [0, 360) at the peak, sample index) of the
    horizontal vector (columns 0 = East, 1 = North) of an (n, 3) array."""
    length = np.hypot(series[:, 0], series[:, 1])
    index = int(np.argmax(length))
    azimuth = float(np.degrees(np.arctan2(series[index, 0], series[index, 1])) % 360.0)
    return float(length[index]), azimuth, index


def rotd_peak(series, percentile=50.0, step_deg=1.0):
    """RotDnn of the horizontal components (columns 0 = East, 1 = North) of an (n, >=2)
    array (Boore 2010, BSSA 100(4)): the ``percentile`` over rotation angles theta in
    [0, 180) deg, in steps of ``step_deg``, of the peak |x cos theta + y sin theta|.
    RotD100 is the peak of the horizontal vector (to within cos(step / 2)); for a
    motion along one line RotD50 = peak cos 45 deg."""
    theta = np.radians(np.arange(0.0, 180.0, step_deg))
    xy = np.asarray(series, float)[:, :2]
    peaks = np.abs(xy @ np.vstack([np.cos(theta), np.sin(theta)])).max(axis=0)
    return float(np.percentile(peaks, percentile))


def displacement_directionality(disp):
    """Peak displacement along the azimuth of the horizontal peak over the peak
    perpendicular to it (``disp_perp_ratio``), and the number of half cycles
    along that azimuth reaching half the peak (``disp_pulses``)."""
    peak, azimuth, _ = horizontal_peak(disp)
    if peak == 0:
        return {"disp_perp_ratio": None, "disp_pulses": 0}
    unit = np.array([np.sin(np.radians(azimuth)), np.cos(np.radians(azimuth))])
    along = disp[:, :2] @ unit
    across = disp[:, :2] @ np.array([unit[1], -unit[0]])
    big = np.abs(along) >= 0.5 * np.max(np.abs(along))
    # half cycles: runs of one sign; count the runs that contain a big sample
    run_id = np.cumsum(np.r_[0, np.diff(np.sign(along)) != 0])
    pulses = len(np.unique(run_id[big]))
    across_peak = np.max(np.abs(across))
    return {"disp_perp_ratio": float(np.max(np.abs(along)) / across_peak) if across_peak > 0
            else None,
            "disp_pulses": int(pulses)}
