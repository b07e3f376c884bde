"""The ``records`` stage: real strong-motion records in, processed ground motion
and the paper's Table 1 parameters out (Hinzen 2009, "Measured Ground Motions").

A record is a catalogue id (``records/catalog.csv``), a record file (anything
:mod:`pipeline.readers` reads) or an already processed ``.npz``.  Processing
(obspy): rotate the horizontals to East/North, demean and detrend, 5 % Hann
taper, zero-phase 4-pole Butterworth band-pass from max(0.1 Hz, lowest usable
frequency) to min(25 Hz, 0.8 x Nyquist), integrate twice, then remove a
displacement baseline ``p(t) = sum_{k=2..6} c_k t^k`` (fitted to the
displacement, pinned to end at rest) by subtracting ``p''`` from the
acceleration and integrating again, so acceleration, velocity and displacement
stay mutually consistent (trapezoidal integrals of each other).

Outputs in ``results/records/``: ``<id>.npz`` (format in README.md),
``records.csv`` (Table 1) and ``<id>.png`` (like the paper's Fig. 8).
"""
import glob
import json
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from obspy import Stream, Trace, UTCDateTime
from obspy.geodetics import gps2dist_azimuth
from obspy.signal.rotate import rotate2zne
from scipy.integrate import cumulative_trapezoid, trapezoid

from pipeline import files
from pipeline.files import InputError
from pipeline.readers import G, is_pattern, read_record

REPO = Path(__file__).resolve().parents[1]
RECORDS_DIR = REPO / "records"
CATALOG_PATH = RECORDS_DIR / "catalog.csv"
DEFAULT_OUT = REPO / "results" / "records"

PROCESSING = {
    "freqmin_hz": 0.1,          # raised to the record's lowest usable frequency
    "freqmax_hz": 25.0,         # lowered to 0.8 x Nyquist
    "nyquist_fraction": 0.8,
    "filter_corners": 4,        # Butterworth, applied forward and backward
    "taper_fraction": 0.05,     # Hann taper on each end
    "baseline_max_power": 6,    # displacement baseline t^2 ... t^6
    "version": 1,
}
TM_BAND_HZ = (0.25, 20.0)       # Rathje et al. (1998) mean-period band
COMPONENTS = ("e", "n", "z")


# ---------------------------------------------------------------- catalogue
def catalog():
    """The record catalogue ``records/catalog.csv`` as a DataFrame (one row per record)."""
    frame = pd.read_csv(CATALOG_PATH, dtype={"id": str, "source_key": str, "start_utc": str,
                                             "end_utc": str, "azimuths_deg": str})
    return frame


def _catalog_row(record_id):
    frame = catalog()
    match = frame[frame["id"].str.upper() == str(record_id).upper()]
    return None if match.empty else _clean(match.iloc[0].to_dict())


def _clean(row):
    """NaN -> None, numpy scalars -> Python scalars."""
    return {k: (None if isinstance(v, float) and np.isnan(v) else
                v.item() if isinstance(v, np.generic) else v) for k, v in row.items()}


# ---------------------------------------------------------------- public API
def processed_motion_path(record, back_azimuth=None, out_dir=None):
    """Path of the processed motion ``.npz`` of ``record``, processing it if needed.

    ``record``: catalogue id, record file path (or glob pattern of single-channel
    files such as ``rec.*.sac``), or processed ``.npz`` (returned as is).  ``back_azimuth`` (degrees) is used only when neither the file nor the
    catalogue gives coordinates or a back azimuth.  Results are cached by a hash
    of the input file(s), catalogue row, back azimuth and processing parameters.
    """
    source = _resolve(record)
    if source["processed"]:
        return source["path"]
    out_path, input_hash = _output_path_and_hash(source, back_azimuth, out_dir)
    if not _is_current(out_path, input_hash):
        motion = build_motion(source, back_azimuth, input_hash)
        _write_motion(out_path, motion)
    return out_path


def load_motion(path):
    """Read a processed motion ``.npz``: dict with ``dt`` (s), ``acc`` (m/s^2), ``vel`` (m/s),
    ``disp`` (m) as (n, 3) arrays (East, North, Up) and ``meta`` (dict)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"processed motion not found: {path}")
    try:
        with np.load(path, allow_pickle=False) as archive:
            motion = {key: archive[key] for key in ("dt", "acc", "vel", "disp", "meta")}
    except (KeyError, ValueError, OSError) as exc:
        raise InputError(f"{path.name}: not a processed motion file ({exc})") from None
    motion["dt"] = float(motion["dt"])
    motion["meta"] = json.loads(str(motion["meta"]))
    return motion


def record_parameters(motion):
    """Table 1 numbers of one motion (dict from :func:`load_motion`), SI units.

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
    ``back_azimuth_deg``, ``epicentral_distance_km`` (None when unknown),
    ``duration_s`` and ``dt_s``.
    """
    dt = motion["dt"]
    params = {}
    for i, comp in enumerate(COMPONENTS):
        acc, vel, disp = (motion[k][:, i] for k in ("acc", "vel", "disp"))
        silent = not np.any(acc)
        params[f"pga_{comp}"] = float(np.max(np.abs(acc)))
        params[f"pgv_{comp}"] = float(np.max(np.abs(vel)))
        params[f"pgd_{comp}"] = float(np.max(np.abs(disp)))
        params[f"pgv_pga_{comp}"] = None if silent else params[f"pgv_{comp}"] / params[f"pga_{comp}"]
        params[f"arias_{comp}"] = arias_intensity(acc, dt)
        params[f"tm_{comp}"] = None if silent else mean_period(acc, dt)
        params[f"ts_{comp}"] = None if silent else significant_duration(acc, dt)
    for kind, short in (("acc", "a"), ("vel", "v"), ("disp", "d")):
        peak, azimuth, _ = horizontal_peak(motion[kind])
        params[f"pg{short}_h"] = peak
        params[f"az_max_{kind}_deg"] = azimuth
    params["pgv_pga_h"] = params["pgv_h"] / params["pga_h"] if params["pga_h"] > 0 else None
    params["arias_h"] = params["arias_e"] + params["arias_n"]
    params.update(displacement_directionality(motion["disp"]))
    meta = motion["meta"]
    params["back_azimuth_deg"] = meta.get("back_azimuth_deg")
    params["epicentral_distance_km"] = meta.get("epicentral_distance_km")
    params["duration_s"] = dt * (len(motion["acc"]) - 1)
    params["dt_s"] = dt
    return params


# ---------------------------------------------------------------- ground-motion measures
def arias_intensity(acc, dt):
    """Arias intensity pi / (2 g) * integral a^2 dt (m/s) of acceleration ``acc`` (m/s^2)."""
    return float(np.pi / (2 * G) * trapezoid(np.asarray(acc) ** 2, dx=dt))


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
    return {"disp_perp_ratio": float(np.max(np.abs(along)) / np.max(np.abs(across))),
            "disp_pulses": int(pulses)}


# ---------------------------------------------------------------- processing
def build_motion(source, back_azimuth=None, input_hash=None):
    """Read and process one record; returns dict dt, acc, vel, disp, meta (not written)."""
    row = source["row"] or {}
    stream, info = read_record(source["path"], row.get("source_key"))
    _apply_catalog_orientation(stream, row, source["path"])
    if row.get("start_utc") or row.get("end_utc"):
        stream.trim(starttime=UTCDateTime(row["start_utc"]) if row.get("start_utc") else None,
                    endtime=UTCDateTime(row["end_utc"]) if row.get("end_utc") else None)
    needs_vertical = row.get("has_vertical", True) not in (False, "false", "False", 0)
    enz, dt = to_east_north_up(stream, source["path"].name, needs_vertical)
    lowest = info.get("lowest_usable_hz")
    freqmin = max(PROCESSING["freqmin_hz"], lowest or 0.0)
    freqmax = min(PROCESSING["freqmax_hz"], PROCESSING["nyquist_fraction"] * 0.5 / dt)
    if freqmin >= freqmax:
        raise InputError(f"{source['path'].name}: sampling too coarse for the "
                         f"{freqmin:g}-{freqmax:g} Hz band")
    acc, vel, disp = process_acceleration(enz, dt, freqmin, freqmax)
    meta = _motion_meta(source, row, info, back_azimuth, needs_vertical)
    meta["processing"] = dict(PROCESSING, freqmin_hz=freqmin, freqmax_hz=freqmax,
                              input_hash=input_hash)
    return {"dt": dt, "acc": acc, "vel": vel, "disp": disp, "meta": meta}


def to_east_north_up(stream, name, needs_vertical=True):
    """Check a raw acceleration stream and rotate it to an (n, 3) East, North, Up array.

    Raises InputError for NaN or gaps, mixed sampling rates, missing or extra
    components.  Returns (array in m/s^2, dt in s).
    """
    if len(stream) == 0:
        raise InputError(f"{name}: no traces")
    for trace in stream:
        data = trace.data
        if np.ma.isMaskedArray(data) and np.ma.is_masked(data):
            raise InputError(f"{name}: trace {trace.id} has gaps")
        if not np.all(np.isfinite(np.asarray(data, dtype=float))):
            raise InputError(f"{name}: trace {trace.id} has NaN or infinite samples")
    rates = {round(trace.stats.sampling_rate, 9) for trace in stream}
    if len(rates) > 1:
        raise InputError(f"{name}: components have different sampling rates "
                         f"({', '.join(f'{r:g}' for r in sorted(rates))} Hz)")
    horizontals = [tr for tr in stream if abs(tr.stats.dip) < 1e-6]
    verticals = [tr for tr in stream if abs(abs(tr.stats.dip) - 90.0) < 1e-6]
    if len(horizontals) != 2 or len(verticals) > 1 or len(horizontals) + len(verticals) != len(stream):
        raise InputError(f"{name}: need 2 horizontal and 1 vertical component, found "
                         f"{len(horizontals)} horizontal, {len(verticals)} vertical, "
                         f"{len(stream) - len(horizontals) - len(verticals)} inclined")
    if not verticals and needs_vertical:
        raise InputError(f"{name}: missing vertical component")
    start = max(tr.stats.starttime for tr in stream)
    end = min(tr.stats.endtime for tr in stream)
    if end - start <= 0:
        raise InputError(f"{name}: components do not overlap in time")
    stream = stream.copy().trim(start, end, nearest_sample=True)
    n = min(tr.stats.npts for tr in stream)
    if n < 100:
        raise InputError(f"{name}: fewer than 100 common samples")
    h1, h2 = (np.asarray(tr.data[:n], dtype=float) for tr in horizontals)
    vertical = verticals[0] if verticals else None
    z = np.asarray(vertical.data[:n], dtype=float) if vertical else np.zeros(n)
    z_dip = vertical.stats.dip if vertical else -90.0
    try:
        up, north, east = rotate2zne(z, 0.0, z_dip,
                                     h1, horizontals[0].stats.azimuth, 0.0,
                                     h2, horizontals[1].stats.azimuth, 0.0)
    except ValueError:
        raise InputError(f"{name}: horizontal azimuths {horizontals[0].stats.azimuth:g} and "
                         f"{horizontals[1].stats.azimuth:g} are not independent") from None
    if vertical is None:
        up = np.zeros(n)  # rotate2zne leaves round-off (1e-17) of the horizontals here
    return np.column_stack([east, north, up]), stream[0].stats.delta


def process_acceleration(enz, dt, freqmin, freqmax):
    """Band-pass and integrate an (n, 3) acceleration; returns consistent acc, vel, disp.

    obspy: demean, linear detrend, Hann taper, zero-phase Butterworth band-pass.
    Then a displacement baseline t^2..t^6 (ending at rest) is removed through
    its second derivative in the acceleration, and velocity and displacement are
    re-integrated (trapezoid) so the three agree.
    """
    stream = Stream([Trace(np.array(enz[:, i]), header={"delta": dt}) for i in range(3)])
    stream.detrend("demean")
    stream.detrend("linear")
    stream.taper(max_percentage=PROCESSING["taper_fraction"], type="hann")
    stream.filter("bandpass", freqmin=freqmin, freqmax=freqmax,
                  corners=PROCESSING["filter_corners"], zerophase=True)
    acc = np.column_stack([tr.data for tr in stream])
    vel = cumulative_trapezoid(acc, dx=dt, axis=0, initial=0.0)
    disp = cumulative_trapezoid(vel, dx=dt, axis=0, initial=0.0)
    acc = acc - _baseline_acceleration(disp, vel, dt)
    vel = cumulative_trapezoid(acc, dx=dt, axis=0, initial=0.0)
    disp = cumulative_trapezoid(vel, dx=dt, axis=0, initial=0.0)
    return acc, vel, disp


def _baseline_acceleration(disp, vel, dt):
    """Second derivative of the least-squares baseline p(t) = sum_{k=2..K} c_k (t/T)^k of
    each displacement column, with p(T) = disp(T) and p'(T) = vel(T) enforced by
    heavily weighted rows; p(0) = p'(0) = 0 by construction."""
    n = disp.shape[0]
    duration = dt * (n - 1)
    tau = np.arange(n) * dt / duration
    powers = np.arange(2, PROCESSING["baseline_max_power"] + 1)
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


def _apply_catalog_orientation(stream, row, path):
    """Catalogue ``azimuths_deg`` ("a;b") sets the horizontal azimuths where the file has none."""
    if not row.get("azimuths_deg"):
        if any(tr.stats.azimuth is None for tr in stream):
            raise InputError(f"{path.name}: horizontal azimuths unknown (catalogue azimuths_deg)")
        return
    azimuths = [float(v) for v in str(row["azimuths_deg"]).split(";")]
    horizontals = [tr for tr in stream if tr.stats.dip == 0.0]
    if len(azimuths) != len(horizontals):
        raise InputError(f"catalogue {row['id']}: {len(azimuths)} azimuths for "
                         f"{len(horizontals)} horizontal components")
    for trace, azimuth in zip(horizontals, azimuths):
        trace.stats.azimuth = azimuth % 360.0


def _motion_meta(source, row, info, back_azimuth, has_vertical):
    def pick(key):
        return row.get(key) if row.get(key) is not None else info.get(key)

    meta = {"record_id": source["id"], "label": row.get("label") or source["id"],
            "event": pick("event"), "station": pick("station"), "magnitude": pick("magnitude"),
            "mechanism": row.get("mechanism"), "has_vertical": bool(has_vertical),
            "horizontals_compass": row.get("horizontals_compass", True),
            "orientation": row.get("orientation", "as-recorded"),
            "source_file": _display_path(source["path"]), "source_key": row.get("source_key"),
            "units": {"dt": "s", "acc": "m/s^2", "vel": "m/s", "disp": "m"},
            "columns": ["East", "North", "Up"]}
    coords = {k: pick(k) for k in ("station_lat", "station_lon", "event_lat", "event_lon")}
    meta.update(coords)
    if None not in coords.values():
        dist_m, _, baz = gps2dist_azimuth(coords["event_lat"], coords["event_lon"],
                                          coords["station_lat"], coords["station_lon"])
        meta["back_azimuth_deg"] = float(baz % 360.0)
        meta["epicentral_distance_km"] = float(dist_m / 1000.0)
        meta["back_azimuth_source"] = ("gps2dist_azimuth of station and epicentre coordinates from "
                                       + (row.get("citation") or "the record file header"))
        if back_azimuth is not None:
            print(f"note: {source['id']}: coordinates give the back azimuth; "
                  f"--back-azimuth {back_azimuth:g} ignored", file=sys.stderr)
    elif row.get("back_azimuth_deg") is not None:
        meta["back_azimuth_deg"] = float(row["back_azimuth_deg"])
        meta["epicentral_distance_km"] = row.get("epicentral_distance_km")
        meta["back_azimuth_source"] = f"catalogue: {row.get('citation')}"
    else:
        meta["back_azimuth_deg"] = None if back_azimuth is None else float(back_azimuth) % 360.0
        meta["epicentral_distance_km"] = row.get("epicentral_distance_km")
        meta["back_azimuth_source"] = ("unknown" if back_azimuth is None
                                       else "given by the user (--back-azimuth)")
    if meta["epicentral_distance_km"] is not None:
        meta["epicentral_distance_km"] = float(meta["epicentral_distance_km"])
    if not has_vertical:
        meta["notes"] = "no vertical component in the source: Up column is zero"
    if row.get("notes"):
        meta["notes"] = (meta.get("notes", "") + "; " + row["notes"]).lstrip("; ")
    return meta


def _display_path(path):
    try:
        return str(Path(path).resolve().relative_to(REPO))
    except ValueError:
        return str(path)


# ---------------------------------------------------------------- resolving and caching
def _resolve(record):
    """dict(id, path, row, processed) for a catalogue id, record file or processed npz."""
    path = Path(record)
    if is_pattern(path) and glob.glob(str(path)):
        record_id = re.sub(r"[^A-Za-z0-9_.-]", "_", path.name.split("*")[0].strip("._") or "record")
        return {"id": record_id, "path": path, "row": None, "processed": False}
    row = None if path.is_file() else _catalog_row(str(record))
    if row is not None:
        path = RECORDS_DIR / row["source_file"]
        if not path.is_file():
            raise InputError(f"catalogue {row['id']}: source file missing: {path}")
        return {"id": row["id"], "path": path, "row": row, "processed": False}
    if not path.is_file():
        raise InputError(f"not a catalogue id and no such file: {record}")
    if path.suffix.lower() == ".npz":
        try:
            with np.load(path, allow_pickle=False) as archive:
                names = set(archive.files)
        except (ValueError, OSError) as exc:
            raise InputError(f"{path.name}: unreadable npz ({exc})") from None
        if {"dt", "acc", "vel", "disp", "meta"} <= names:
            return {"id": path.stem, "path": path, "row": None, "processed": True}
    record_id = re.sub(r"[^A-Za-z0-9_.-]", "_", path.stem)
    return {"id": record_id, "path": path, "row": None, "processed": False}


def _input_files(path):
    """Files a record depends on (AT2: all sibling AT2 files; a glob: its matches)."""
    if is_pattern(path):
        return [Path(p) for p in sorted(glob.glob(str(path)))]
    if path.suffix.lower() == ".at2":
        return sorted(p for p in path.parent.iterdir() if p.suffix.lower() == ".at2")
    return [path]


def _output_path_and_hash(source, back_azimuth, out_dir):
    out_dir = Path(out_dir) if out_dir is not None else DEFAULT_OUT
    parts = [PROCESSING, source["row"], back_azimuth] + _input_files(source["path"])
    return out_dir / f"{source['id']}.npz", files.content_hash(*parts)


def _is_current(out_path, input_hash):
    if not out_path.is_file():
        return False
    try:
        return load_motion(out_path)["meta"]["processing"]["input_hash"] == input_hash
    except (InputError, KeyError):
        return False


def _write_motion(out_path, motion):
    files.write_npz(out_path, dt=np.float64(motion["dt"]), acc=motion["acc"], vel=motion["vel"],
                    disp=motion["disp"], meta=np.array(json.dumps(motion["meta"])))


# ---------------------------------------------------------------- table and figure
def parameters_table(motions):
    """Table 1 rows (DataFrame) for a list of (record id, motion dict)."""
    rows = []
    for record_id, motion in motions:
        meta = motion["meta"]
        row = {"id": record_id, "label": meta.get("label"), "event": meta.get("event"),
               "station": meta.get("station"), "magnitude": meta.get("magnitude"),
               "mechanism": meta.get("mechanism"), "has_vertical": meta.get("has_vertical"),
               "horizontals_compass": meta.get("horizontals_compass")}
        row.update(record_parameters(motion))
        rows.append(row)
    return pd.DataFrame(rows)


def plot_motion(motion, path):
    """Figure like the paper's Fig. 8: E, N, Up acceleration traces and the 3D
    displacement hodogram with its projections on the three coordinate planes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meta, dt = motion["meta"], motion["dt"]
    acc, disp = motion["acc"], motion["disp"] * 100.0  # cm
    time = np.arange(len(acc)) * dt
    fig = plt.figure(figsize=(12, 6.5))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.1, 1.0])
    limit = max(np.max(np.abs(acc)), 1e-9) * 1.05
    for i, name in enumerate(("East", "North", "Up")):
        ax = fig.add_subplot(grid[i, 0])
        ax.plot(time, acc[:, i], lw=0.6, color="k")
        ax.set_ylim(-limit, limit)
        ax.set_ylabel(f"{name}\n(m/s$^2$)")
        ax.grid(alpha=0.3)
        if i < 2:
            ax.tick_params(labelbottom=False)
    ax.set_xlabel("time (s)")
    ax3 = fig.add_subplot(grid[:, 1], projection="3d")
    e, n, u = disp[:, 0], disp[:, 1], disp[:, 2]
    span = max(np.max(np.abs(disp)), 1e-9) * 1.1
    ax3.plot(e, n, u, color="C3", lw=1.0, label="displacement")
    shadow = {"color": "0.55", "lw": 0.6}
    ax3.plot(e, n, np.full_like(u, -span), **shadow)
    ax3.plot(e, np.full_like(n, span), u, **shadow)
    ax3.plot(np.full_like(e, -span), n, u, **shadow)
    ax3.set_xlim(-span, span)
    ax3.set_ylim(-span, span)
    ax3.set_zlim(-span, span)
    ax3.set_xlabel("East (cm)")
    ax3.set_ylabel("North (cm)")
    ax3.set_zlabel("Up (cm)")
    ax3.set_box_aspect((1, 1, 1), zoom=0.85)
    baz = meta.get("back_azimuth_deg")
    note = f"back azimuth {baz:.0f}°" if baz is not None else "back azimuth unknown"
    ax3.set_title(f"displacement hodogram ({note})", fontsize=10)
    title = f"{meta['record_id']}: {meta.get('event') or ''}, {meta.get('station') or ''}"
    if not meta.get("has_vertical"):
        title += " (no vertical in source)"
    fig.suptitle(title)
    fig.tight_layout()
    files.save_figure(fig, path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- command line
def add_command(subparsers):
    parser = subparsers.add_parser(
        "records", help="process strong-motion records: npz, Table 1 (records.csv), figures",
        description="Process strong-motion records (catalogue ids from records/catalog.csv or "
                    "record files: PEER AT2, DMG V1, ASDF, MiniSEED, SAC, ...) into "
                    "results/records/<id>.npz, records.csv (Table 1) and <id>.png.")
    parser.add_argument("records", nargs="*", metavar="ID_OR_PATH",
                        help="catalogue id (e.g. GM20) or record file")
    parser.add_argument("--all", action="store_true", help="process every catalogued record")
    parser.add_argument("--back-azimuth", type=float, metavar="DEG",
                        help="back azimuth (deg) for files without coordinates")
    parser.add_argument("--out", type=Path, default=None,
                        help=f"output directory (default {_display_path(DEFAULT_OUT)})")
    parser.add_argument("--no-figures", action="store_true", help="skip the per-record figures")
    parser.set_defaults(func=run_command)


def run_command(args):
    specs = list(catalog()["id"]) if args.all else []
    specs += [spec for spec in args.records if spec not in specs]
    if not specs:
        raise InputError("name records (ids or files) or use --all")
    if args.back_azimuth is not None and not 0.0 <= args.back_azimuth < 360.0:
        raise InputError(f"--back-azimuth {args.back_azimuth:g} not in [0, 360)")
    out_dir = args.out if args.out is not None else DEFAULT_OUT

    # read and process everything in memory first: a bad input writes nothing
    motions = []
    for spec in specs:
        source = _resolve(spec)
        if source["processed"]:
            motions.append((source["id"], load_motion(source["path"]), source["path"], False))
            continue
        out_path, input_hash = _output_path_and_hash(source, args.back_azimuth, out_dir)
        if _is_current(out_path, input_hash):
            motions.append((source["id"], load_motion(out_path), out_path, False))
            print(f"{source['id']}: up to date", flush=True)
        else:
            motion = build_motion(source, args.back_azimuth, input_hash)
            motions.append((source["id"], motion, out_path, True))
            print(f"{source['id']}: processed", flush=True)

    for record_id, motion, out_path, fresh in motions:
        if fresh:
            _write_motion(out_path, motion)
        figure = out_path.with_suffix(".png")
        if not args.no_figures and (fresh or not figure.is_file()):
            plot_motion(motion, figure)
    table = parameters_table([(rid, motion) for rid, motion, _, _ in motions])
    _update_table(Path(out_dir) / "records.csv", table)
    print(f"wrote {len(motions)} records to {_display_path(Path(out_dir))}", flush=True)
    return 0


def _update_table(path, table):
    """Write records.csv: these rows replace same-id rows of an existing table."""
    if path.is_file():
        old = pd.read_csv(path, dtype={"id": str})
        table = pd.concat([old[~old["id"].isin(table["id"])], table], ignore_index=True)
    files.write_csv(path, table)
