"""Synthetic near-field ground motions around two M 6.5 sources (pyprop8).

Frame: local Cartesian, epicentre at the origin, x East, y North (km), depth
positive down.  Each source is a line of equal point sub-events along strike
at the hypocentre depth, triggered by a rupture front running from the
hypocentre at ``rupture_velocity_km_s`` (directivity).  pyprop8 computes the
full wavefield, near-field terms and static offsets included, in a layered
elastic half-space (no anelastic attenuation); one call per sub-event gives
all sites, since receivers are placed relative to each sub-event.

pyprop8 conventions, pinned in tests/test_synthetics.py against Okada's (1985)
point source in a half-space: lengths km, velocities km/s, density g/cm^3
(moduli in GPa), moment tensor in 1e18 N m, displacement in km; with
``xyz=True`` the components are x East, y North, z Up.  The moment tensor is
built by ``make_moment_tensor`` (r, theta, phi; strike clockwise from North,
fault dipping to the right of the strike direction, rake 0 = left-lateral)
and turned into East/North/Up by ``rtf2xyz``.

Sites are written like processed records (README: npz with dt, acc, vel,
disp in m/s^2, m/s, m, columns East, North, Up, and a JSON meta) under
``results/synthetics/<source>/<site_id>.npz``, cached by a content hash of
every generator parameter.
"""
import importlib.metadata
import json
import math
import os
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np
import pandas as pd
import pyprop8
from pyprop8.utils import clp_filter, make_moment_tensor, rtf2xyz, stf_trapezoidal
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from pipeline import files
from pipeline.files import InputError

GENERATOR_VERSION = 2  # bump when the written motions change
PYPROP8_VERSION = importlib.metadata.version("pyprop8")
DEFAULT_OUT_DIR = Path("results/synthetics")
QUICK_OUT_DIR = Path("results/synthetics-quick")
QUICK_FMAX_HZ = 2.5
QUICK_DURATION_S = 20.0
GMM_VS30_M_S = 760.0  # reference rock for the ground-motion-model check

# Simple layered crust: (thickness km, Vp km/s, Vs km/s, density g/cm^3).
CRUST_LAYERS = (
    (1.0, 3.5, 2.0, 2.3),
    (4.0, 5.5, 3.2, 2.6),
    (15.0, 6.2, 3.6, 2.75),
    (10.0, 6.8, 3.9, 2.9),
    (math.inf, 8.0, 4.5, 3.3),
)

# Sub-events: positions along strike relative to the hypocentre (km, positive
# in the strike direction), equal moments, each with a trapezoidal moment-rate
# function (a boxcar of ``subevent_rise_s`` convolved with one of
# ``subevent_duration_s``).  Rise 0.5 s / duration 1.5 s keeps PGA and PGV
# within a factor ~1.5 of the NGA-West2 medians at 5-20 km (gmm_check.csv).
SOURCES = {
    "strike_slip": {
        "mechanism": "strike-slip",
        "gmm_mechanism": "SS",
        "strike_deg": 0.0,  # N-S fault ...
        "dip_deg": 90.0,
        "rake_deg": 180.0,  # ... right-lateral
        "mw": 6.5,
        "depth_km": 8.0,
        "hypocentre_x_km": 0.0,
        "hypocentre_y_km": 0.0,
        "subevents_along_strike_km": (-4.0, 0.0, 4.0, 8.0, 12.0),
        "rupture_velocity_km_s": 2.8,
        "subevent_rise_s": 0.5,
        "subevent_duration_s": 1.5,
    },
    "thrust": {
        "mechanism": "reverse",
        "gmm_mechanism": "RS",
        "strike_deg": 90.0,  # E-W fault dipping south
        "dip_deg": 40.0,
        "rake_deg": 90.0,
        "mw": 6.5,
        "depth_km": 10.0,
        "hypocentre_x_km": 0.0,
        "hypocentre_y_km": 0.0,
        "subevents_along_strike_km": (-4.0, 0.0, 4.0, 8.0, 12.0),
        "rupture_velocity_km_s": 2.8,
        "subevent_rise_s": 0.5,
        "subevent_duration_s": 1.5,
    },
}

LEAD_TIME_S = 1.0  # record time of the hypocentral origin time


def moment_from_mw(mw):
    """Scalar moment (N m) of moment magnitude ``mw`` (Hanks & Kanamori 1979)."""
    return 10.0 ** (1.5 * mw + 9.1)


def source_parameters(source_name):
    """The parameter dict of a source in :data:`SOURCES`; InputError if unknown."""
    try:
        return SOURCES[source_name]
    except KeyError:
        raise InputError(f"unknown synthetic source {source_name!r} "
                         f"(known: {', '.join(SOURCES)})") from None


def subevents(source_name):
    """Sub-events: DataFrame x_km, y_km, depth_km, delay_s (rupture time), m0_nm."""
    src = source_parameters(source_name)
    strike = math.radians(src["strike_deg"])
    along = np.asarray(src["subevents_along_strike_km"], dtype=float)
    return pd.DataFrame({
        "x_km": src["hypocentre_x_km"] + along * math.sin(strike),
        "y_km": src["hypocentre_y_km"] + along * math.cos(strike),
        "depth_km": float(src["depth_km"]),
        "delay_s": np.abs(along) / src["rupture_velocity_km_s"],
        "m0_nm": moment_from_mw(src["mw"]) / len(along),
    })


def numerics(duration_s, sampling_hz, fmax_hz, layers=CRUST_LAYERS):
    """pyprop8 numerical parameters for content up to ``fmax_hz``.

    The source spectrum is tapered to zero between fmax and 1.2 fmax; the
    computation step puts the Nyquist frequency at >= 1.25 fmax and is an
    integer fraction ``upsample`` of the output step.  Wavenumbers run to
    kmax = 2 pi fmax / Vs_min (every propagating wave below fmax); the step
    dk keeps the source images implied by the discrete wavenumber sum
    (spacing 2 pi / dk) beyond the reach of the fastest wave in the padded
    window plus 60 km.
    """
    if not (fmax_hz > 0 and duration_s > 0 and sampling_hz >= 2.5 * fmax_hz):
        raise InputError(f"impossible synthetics numerics: duration {duration_s} s, sampling "
                         f"{sampling_hz} Hz, fmax {fmax_hz} Hz (need sampling >= 2.5 fmax)")
    upsample = int(sampling_hz // (2.5 * fmax_hz))
    dt_calc = upsample / sampling_hz
    nt = int(math.ceil(duration_s / dt_calc)) + 1
    pad_frac = 0.5
    vs_min = min(layer[2] for layer in layers)
    vp_max = max(layer[1] for layer in layers)
    kmax = 2 * math.pi * fmax_hz / vs_min
    dk = 2 * math.pi / (vp_max * nt * (1 + pad_frac) * dt_calc + 60.0)
    return {"dt_calc": dt_calc, "upsample": upsample, "nt": nt, "pad_frac": pad_frac,
            "kmax": kmax, "nk": int(math.ceil(kmax / dk)) + 1}


def moment_tensor_xyz(strike_deg, dip_deg, rake_deg, m0_nm):
    """Double-couple moment tensor (East, North, Up) in pyprop8 units (1e18 N m)."""
    return rtf2xyz(make_moment_tensor(strike_deg, dip_deg, rake_deg, m0_nm / 1e18))


def point_source_displacement(x_km, y_km, mechanism, sub, num, fmax_hz, layers=CRUST_LAYERS):
    """Surface displacement (m), shape (nsite, 3, nt), East/North/Up, of one sub-event.

    ``mechanism`` = (strike, dip, rake) in degrees; ``sub`` a mapping with
    x_km, y_km, depth_km, delay_s, m0_nm, rise_s, duration_s; ``num`` from
    :func:`numerics`.  Sample 0 is LEAD_TIME_S before the hypocentral origin
    time; the sub-event's moment release starts at its delay_s.
    """
    source = pyprop8.PointSource(
        float(sub["x_km"]), float(sub["y_km"]), float(sub["depth_km"]),
        moment_tensor_xyz(*mechanism, sub["m0_nm"]), np.zeros((3, 1)),
        LEAD_TIME_S + float(sub["delay_s"]) + 0.5 * sub["duration_s"])
    receivers = pyprop8.ListOfReceivers(np.asarray(x_km, float), np.asarray(y_km, float), depth=0)
    w0, w1 = 2 * math.pi * fmax_hz, 2 * math.pi * 1.2 * fmax_hz

    def moment_rate_spectrum(w):
        return stf_trapezoidal(w, sub["rise_s"], sub["duration_s"]) * clp_filter(w, w0, w1)

    with threadpool_limits(1):  # BLAS threads only slow pyprop8's small products
        _, seis = pyprop8.compute_seismograms(
            pyprop8.LayeredStructureModel([tuple(layer) for layer in layers]), source,
            receivers, num["nt"], num["dt_calc"], source_time_function=moment_rate_spectrum,
            pad_frac=num["pad_frac"], xyz=True, show_progress=False, squeeze_outputs=False,
            stencil_kwargs={"kmin": 0.0, "kmax": num["kmax"], "nk": num["nk"]})
    return seis[0] * 1e3  # km -> m


def _point_source_task(call):
    return point_source_displacement(*call)


def band_limited_motion(disp, dt, upsample):
    """(acc, vel, disp) at step dt/upsample from band-limited displacement (n, 3), m.

    A ramp rising by the static offset (last minus first sample) over the FFT
    period n dt is removed, which makes the periodic extension smooth when the
    motion is at rest at both ends; the rest is interpolated and differentiated
    in the frequency domain (exact below the Nyquist frequency) and the ramp
    added back.  Output: n_out = (n - 1) * upsample + 1 samples.
    """
    n = disp.shape[0]
    t = np.arange(n) * dt
    slope = (disp[-1] - disp[0]) / (n * dt)
    rest = disp - disp[0] - np.outer(t, slope)
    spectrum = np.fft.rfft(rest, axis=0)
    n_fine = n * upsample
    dt_out = dt / upsample
    omega = 2 * np.pi * np.fft.rfftfreq(n_fine, dt_out)[:, None]
    padded = np.zeros((omega.shape[0], disp.shape[1]), dtype=complex)
    padded[:spectrum.shape[0]] = spectrum * upsample
    n_out = (n - 1) * upsample + 1
    t_out = np.arange(n_out) * dt_out
    out_disp = np.fft.irfft(padded, n_fine, axis=0)[:n_out] + disp[0] + np.outer(t_out, slope)
    out_vel = np.fft.irfft(1j * omega * padded, n_fine, axis=0)[:n_out] + slope
    out_acc = np.fft.irfft(-omega ** 2 * padded, n_fine, axis=0)[:n_out]
    return out_acc, out_vel, out_disp


def _settings(rings_km, azimuth_step_deg, duration_s, sampling_hz, fmax_hz, out_dir, quick):
    if quick:
        fmax_hz = min(fmax_hz, QUICK_FMAX_HZ)
        duration_s = min(duration_s, QUICK_DURATION_S)
    rings = tuple(float(r) for r in rings_km)
    if not rings or min(rings) <= 0 or not 0 < azimuth_step_deg <= 360:
        raise InputError(f"impossible site rings {rings_km} km / azimuth step {azimuth_step_deg}")
    base = Path(out_dir) if out_dir is not None else (QUICK_OUT_DIR if quick else DEFAULT_OUT_DIR)
    return {"rings_km": rings, "azimuth_step_deg": float(azimuth_step_deg),
            "duration_s": float(duration_s), "sampling_hz": float(sampling_hz),
            "fmax_hz": float(fmax_hz), "base": base}


def site_table(source_name, rings_km=(5, 10, 20), azimuth_step_deg=30, out_dir=None,
               quick=False):
    """Sites on rings around the epicentre of ``source_name``.

    Columns: site_id, x_km, y_km (East, North of the epicentre), ring_km,
    site_azimuth_deg (epicentre to site), back_azimuth_deg (site to
    epicentre), distance_km (epicentral), npz (path of the motion file).
    """
    source_parameters(source_name)
    cfg = _settings(rings_km, azimuth_step_deg, 1.0, 100.0, 1.0, out_dir, quick)
    azimuths = np.arange(0.0, 360.0 - 1e-9, cfg["azimuth_step_deg"])
    rows = []
    for ring in cfg["rings_km"]:
        for az in azimuths:
            x, y = ring * math.sin(math.radians(az)), ring * math.cos(math.radians(az))
            site_id = f"r{ring:02g}_az{az:03g}"
            rows.append({"site_id": site_id, "x_km": x, "y_km": y, "ring_km": ring,
                         "site_azimuth_deg": float(az),
                         "back_azimuth_deg": (float(az) + 180.0) % 360.0,
                         "distance_km": math.hypot(x, y),
                         "npz": cfg["base"] / source_name / f"{site_id}.npz"})
    return pd.DataFrame(rows)


def _cache_key(source_name, cfg, num):
    params = {k: v for k, v in cfg.items() if k != "base"}
    return files.content_hash(GENERATOR_VERSION, source_name, source_parameters(source_name),
                              CRUST_LAYERS, LEAD_TIME_S, params, num)


def generate(source_name, rings_km=(5, 10, 20), azimuth_step_deg=30, duration_s=30.0,
             sampling_hz=100.0, fmax_hz=10.0, out_dir=None, quick=False, jobs=None):
    """Compute (or reuse) the synthetic motions of all sites of one source.

    ``quick`` lowers fmax to QUICK_FMAX_HZ and the duration to
    QUICK_DURATION_S and writes under results/synthetics-quick (unless
    ``out_dir`` is given).  ``jobs`` processes (default: all cores) share the
    sub-events.  Returns the npz paths in site_table order; nothing is
    recomputed when the manifest's cache key (hash of every parameter) matches
    and all files exist.  Also writes the source's ground-motion-model check
    (``<source>/gmm_check_sites.csv``) and refreshes the summary of all
    sources, ``gmm_check.csv``, in the output directory.
    """
    src = source_parameters(source_name)
    cfg = _settings(rings_km, azimuth_step_deg, duration_s, sampling_hz, fmax_hz, out_dir, quick)
    num = numerics(cfg["duration_s"], cfg["sampling_hz"], cfg["fmax_hz"])
    sites = site_table(source_name, cfg["rings_km"], cfg["azimuth_step_deg"], cfg["base"])
    paths = [Path(p) for p in sites["npz"]]
    source_dir = cfg["base"] / source_name
    manifest_path = source_dir / "manifest.json"
    key = _cache_key(source_name, cfg, num)
    if (manifest_path.is_file() and all(p.is_file() for p in paths)
            and json.loads(manifest_path.read_text()).get("cache_key") == key):
        if not (source_dir / "gmm_check_sites.csv").is_file():
            _write_gmm_check(source_name, cfg)
        write_gmm_summary(cfg["base"])
        return paths
    jobs = jobs or os.cpu_count() or 1

    subs = subevents(source_name)
    mechanism = (src["strike_deg"], src["dip_deg"], src["rake_deg"])
    tasks = []
    for _, sub in subs.iterrows():
        sub = dict(sub, rise_s=src["subevent_rise_s"], duration_s=src["subevent_duration_s"])
        tasks.append((sites["x_km"].to_numpy(), sites["y_km"].to_numpy(), mechanism, sub, num,
                      cfg["fmax_hz"]))
    started = time.monotonic()
    total = 0.0
    progress = tqdm(total=len(tasks), desc=f"pyprop8 {source_name}", unit="sub-event")
    if jobs > 1 and len(tasks) > 1:
        with Pool(min(jobs, len(tasks))) as pool:
            for disp in pool.imap(_point_source_task, tasks):  # in order: reproducible sum
                total = total + disp
                progress.update(1)
    else:
        for task in tasks:
            total = total + _point_source_task(task)
            progress.update(1)
    progress.close()
    elapsed = time.monotonic() - started

    manifest_path.unlink(missing_ok=True)
    for stale in set(source_dir.glob("*.npz")) - set(paths):
        stale.unlink()
    for (_, site), path in zip(sites.iterrows(), paths):
        acc, vel, disp = band_limited_motion(total[site.name].T, num["dt_calc"], num["upsample"])
        meta = _site_meta(source_name, src, site, cfg, num, key)
        files.write_npz(path, dt=np.float64(1.0 / cfg["sampling_hz"]), acc=acc, vel=vel,
                        disp=disp, meta=np.array(json.dumps(meta)))
    _write_gmm_check(source_name, cfg)
    files.write_json(manifest_path, {
        "cache_key": key, "source": source_name, "source_parameters": src,
        "crust_layers_thickness_vp_vs_rho": [  # thickness null: the half-space
            [None if math.isinf(layer[0]) else layer[0], *layer[1:]] for layer in CRUST_LAYERS],
        "settings": {k: v for k, v in cfg.items() if k != "base"}, "numerics": num,
        "compute_seconds": round(elapsed, 1), "jobs": jobs,
        "sites": [p.name for p in paths]})
    write_gmm_summary(cfg["base"])
    return paths


def _write_gmm_check(source_name, cfg):
    files.write_csv(cfg["base"] / source_name / "gmm_check_sites.csv",
                    gmm_check([source_name], cfg["rings_km"], cfg["azimuth_step_deg"], cfg["base"]))


def _site_meta(source_name, src, site, cfg, num, key):
    return {
        "record_id": f"syn_{source_name}_{site.site_id}",
        "label": f"synthetic {source_name} r={site.ring_km:g} km az={site.site_azimuth_deg:g}",
        "event": f"synthetic {src['mechanism']} Mw {src['mw']:g}",
        "station": site.site_id, "magnitude": src["mw"], "mechanism": src["mechanism"],
        "back_azimuth_deg": float(site.back_azimuth_deg),
        "epicentral_distance_km": float(site.distance_km),
        "back_azimuth_source": "exact: synthetic site geometry (local frame, epicentre at origin)",
        "has_vertical": True, "horizontals_compass": True, "orientation": "ENU",
        "units": {"dt": "s", "acc": "m/s^2", "vel": "m/s", "disp": "m"},
        "columns": ["East", "North", "Up"],
        "source_file": f"pyprop8 {PYPROP8_VERSION} synthetic, cache key {key}",
        "source": source_name, "ring_km": float(site.ring_km),
        "site_azimuth_deg": float(site.site_azimuth_deg),
        "x_km": float(site.x_km), "y_km": float(site.y_km),
        "processing": {"freqmin_hz": 0.0, "freqmax_hz": cfg["fmax_hz"],
                       "generator": "pyprop8", "lead_time_s": LEAD_TIME_S,
                       "duration_s": cfg["duration_s"], **num, "cache_key": key,
                       "version": GENERATOR_VERSION},
    }


# ---------------------------------------------------------------- ground-motion-model check
def rotd50(series):
    """RotD50 peak of a horizontal pair (n, 2): median over rotations 0-179 deg of the peak."""
    angles = np.radians(np.arange(180.0))
    rotated = np.outer(series[:, 0], np.cos(angles)) + np.outer(series[:, 1], np.sin(angles))
    return float(np.median(np.abs(rotated).max(axis=0)))


def rupture_distances(source_name, x_km, y_km):
    """(Rrup, Rjb, Rx) in km of surface points to the modelled rupture.

    The rupture is the segment through the sub-events (at the hypocentre
    depth); Rjb uses its surface projection; Rx is the horizontal distance
    from the strike line, positive on the side the fault dips to.
    """
    src = source_parameters(source_name)
    subs = subevents(source_name)
    a = subs[["x_km", "y_km", "depth_km"]].to_numpy()[0]
    b = subs[["x_km", "y_km", "depth_km"]].to_numpy()[-1]
    points = np.column_stack([x_km, y_km, np.zeros(len(x_km))])

    def to_segment(p, a, b):
        d = b - a
        t = np.clip((p - a) @ d / max(d @ d, 1e-12), 0.0, 1.0)  # one sub-event: a point
        return np.linalg.norm(p - a - np.outer(t, d), axis=1)

    surface = np.array([1.0, 1.0, 0.0])
    strike = math.radians(src["strike_deg"])
    rx = (np.asarray(x_km) - a[0]) * math.cos(strike) - (np.asarray(y_km) - a[1]) * math.sin(strike)
    return to_segment(points, a, b), to_segment(points, a * surface, b * surface), rx


def gmm_check(source_names=tuple(SOURCES), rings_km=(5, 10, 20), azimuth_step_deg=30,
              out_dir=None, quick=False):
    """Per-site synthetic PGA/PGV against NGA-West2 medians (pygmm), DataFrame.

    Synthetic horizontal peaks as RotD50 (the models' definition) and as the
    geometric mean of the East and North peaks; model medians of Chiou &
    Youngs (2014) and Boore et al. (2014) for the source's Mw, mechanism, dip,
    top depth and the site's rupture distances, at Vs30 = GMM_VS30_M_S.
    Units: PGA in g, PGV in cm/s.
    """
    import pygmm  # noqa: PLC0415  (slow import, only needed here)
    from pipeline.records import load_motion  # noqa: PLC0415

    models = {"cy14": pygmm.ChiouYoungs2014, "bssa14": pygmm.BooreStewartSeyhanAtkinson2014}
    rows = []
    for name in source_names:
        src = source_parameters(name)
        sites = site_table(name, rings_km, azimuth_step_deg, out_dir, quick)
        rrup, rjb, rx = rupture_distances(name, sites["x_km"], sites["y_km"])
        for i, site in sites.iterrows():
            motion = load_motion(site.npz)
            acc, vel = motion["acc"][:, :2], motion["vel"][:, :2]
            row = {"source": name, "site_id": site.site_id, "ring_km": site.ring_km,
                   "rrup_km": rrup[i], "rjb_km": rjb[i], "rx_km": rx[i],
                   "pga_rotd50_g": rotd50(acc) / 9.80665,
                   "pgv_rotd50_cm_s": rotd50(vel) * 100.0,
                   "pga_geomean_g": np.sqrt(np.prod(np.abs(acc).max(axis=0))) / 9.80665,
                   "pgv_geomean_cm_s": np.sqrt(np.prod(np.abs(vel).max(axis=0))) * 100.0}
            scenario = pygmm.Scenario(
                mag=src["mw"], dist_rup=rrup[i], dist_jb=rjb[i], dist_x=rx[i],
                v_s30=GMM_VS30_M_S, mechanism=src["gmm_mechanism"], dip=src["dip_deg"],
                depth_tor=src["depth_km"], on_hanging_wall=bool(rx[i] > 0 and src["dip_deg"] < 90))
            for label, model_class in models.items():
                model = model_class(scenario)
                row[f"{label}_pga_g"] = float(model.pga)
                row[f"{label}_pgv_cm_s"] = float(model.pgv)
            rows.append(row)
    return pd.DataFrame(rows)


def write_gmm_summary(base):
    """Summarise every ``<base>/<source>/gmm_check_sites.csv`` of a current
    source into ``<base>/gmm_check.csv`` (see :func:`gmm_summary`); returns it."""
    per_site = [pd.read_csv(path) for path in sorted(Path(base).glob("*/gmm_check_sites.csv"))
                if (path.parent / "manifest.json").is_file()]
    if not per_site:
        return None
    summary = gmm_summary(pd.concat(per_site, ignore_index=True))
    files.write_csv(Path(base) / "gmm_check.csv", summary)
    return summary


def gmm_summary(per_site):
    """Per source and ring: medians over sites of rupture distance, synthetic
    RotD50 peaks, model medians, and of the synthetic/model ratios (RotD50;
    ``geomean``: geometric mean of the East and North peaks, against CY14)."""
    frame = per_site.copy()
    for peak, unit in (("pga", "g"), ("pgv", "cm_s")):
        for model in ("cy14", "bssa14"):
            frame[f"ratio_{peak}_{model}"] = (frame[f"{peak}_rotd50_{unit}"]
                                              / frame[f"{model}_{peak}_{unit}"])
        frame[f"ratio_{peak}_geomean_cy14"] = (frame[f"{peak}_geomean_{unit}"]
                                               / frame[f"cy14_{peak}_{unit}"])
    columns = ["rrup_km",
               "pga_rotd50_g", "cy14_pga_g", "bssa14_pga_g", "ratio_pga_cy14", "ratio_pga_bssa14",
               "pgv_rotd50_cm_s", "cy14_pgv_cm_s", "bssa14_pgv_cm_s", "ratio_pgv_cy14",
               "ratio_pgv_bssa14", "ratio_pga_geomean_cy14", "ratio_pgv_geomean_cy14"]
    groups = frame.groupby(["source", "ring_km"])
    summary = groups[columns].median().reset_index()
    summary.insert(2, "n_sites", groups.size().to_numpy())
    return summary


# ---------------------------------------------------------------- downfall directions
RUN_COLUMNS = ("site_id", "column", "toppled", "downfall_azimuth_deg", "back_azimuth_deg",
               "x_km", "y_km")


def _checked_runs(runs):
    missing = [c for c in RUN_COLUMNS if c not in runs.columns]
    if missing:
        raise InputError(f"synthetic runs table lacks columns: {', '.join(missing)}")
    return runs


def direction_differences(runs):
    """Per run: ``diff_deg`` = downfall azimuth minus back azimuth in (-180, 180]
    and ``direction_class``: toward (|diff| <= 45, falls toward the epicentre),
    away (|diff| >= 135), transverse, or 'not toppled' (diff NaN)."""
    frame = _checked_runs(runs).copy()
    toppled = frame["toppled"].astype(bool) & frame["downfall_azimuth_deg"].notna()
    diff = -((frame["back_azimuth_deg"] - frame["downfall_azimuth_deg"] + 180.0) % 360.0 - 180.0)
    frame["diff_deg"] = diff.where(toppled)
    size = frame["diff_deg"].abs()
    frame["direction_class"] = np.select(
        [~toppled, size <= 45.0, size >= 135.0], ["not toppled", "toward", "away"], "transverse")
    return frame


def _wrap(angle_deg, period):
    """``angle_deg`` wrapped to (-period/2, period/2]."""
    return float(-((-angle_deg + period / 2) % period - period / 2))


def direction_table(runs):
    """Counts and circular statistics of downfall minus back azimuth.

    One row per source (when ``runs`` has a ``source`` column) and column
    type: n_runs, n_toppled, toward, away, transverse; directional mean of the
    difference (deg) with its mean resultant length and Rayleigh p; axial
    statistics from the doubled angles (astropy.stats): axial mean difference
    in (-90, 90] (0 = along the back-azimuth line, +-90 = transverse), axial
    mean resultant length and Rayleigh p.
    """
    from astropy.stats import circmean, circvar, rayleightest  # noqa: PLC0415

    frame = direction_differences(runs)
    keys = [k for k in ("source", "column") if k in frame.columns]
    rows = []
    for key, group in frame.groupby(keys, sort=True):
        diffs = np.radians(group["diff_deg"].dropna().to_numpy())
        row = dict(zip(keys, key if isinstance(key, tuple) else (key,)))
        row.update({"n_runs": len(group), "n_toppled": diffs.size})
        for cls in ("toward", "away", "transverse"):
            row[cls] = int((group["direction_class"] == cls).sum())
        if diffs.size:
            row["mean_diff_deg"] = _wrap(np.degrees(circmean(diffs)), 360.0)
            row["resultant_length"] = float(1.0 - circvar(diffs))
            row["rayleigh_p"] = float(rayleightest(diffs))
            row["axial_mean_diff_deg"] = _wrap(np.degrees(circmean(2 * diffs)) / 2, 180.0)
            row["axial_resultant_length"] = float(1.0 - circvar(2 * diffs))
            row["axial_rayleigh_p"] = float(rayleightest(2 * diffs))
        rows.append(row)
    return pd.DataFrame(rows)


def axial_misfit(x_km, y_km, downfall_deg, px_km, py_km):
    """Mean of sin^2(downfall - azimuth from site to P) over sites, for points P.

    0 when every fall lies on the line through its site and P (toward or
    away), 1 when all are transverse, 0.5 expected for random directions.
    ``px_km``/``py_km`` are arrays of candidate points (any shape); sites
    coinciding with P count 0.5.
    """
    px, py = np.asarray(px_km, float)[..., None], np.asarray(py_km, float)[..., None]
    dx, dy = px - np.asarray(x_km, float), py - np.asarray(y_km, float)
    term = np.sin(np.radians(np.asarray(downfall_deg, float)) - np.arctan2(dx, dy)) ** 2
    term = np.where(np.hypot(dx, dy) < 1e-9, 0.5, term)
    return term.mean(axis=-1)


def locate_source_from_falls(runs, extent_km=30.0, step_km=0.25):
    """Grid search for the point whose directions best explain the falls (axial).

    For each source (if ``runs`` has a ``source`` column) and column type, and
    for both column types together ('all'), minimises :func:`axial_misfit`
    over a square grid of half-width ``extent_km`` around the epicentre.
    Returns a DataFrame: n_falls, best_x_km, best_y_km, error_km (to the
    epicentre at the origin), at_grid_edge (True: the minimum is not
    constrained inside the grid), misfit_best, misfit_epicentre and, for
    known sources, error_rupture_centre_km (to the middle of the sub-event
    line).
    """
    frame = direction_differences(runs)
    frame = frame[frame["direction_class"] != "not toppled"]
    by_source = frame.groupby("source") if "source" in frame.columns else [(None, frame)]
    grid = np.arange(-extent_km, extent_km + step_km / 2, step_km)
    gx, gy = np.meshgrid(grid, grid)
    rows = []
    for source, source_runs in by_source:
        groups = [(c, g) for c, g in source_runs.groupby("column")] + [("all", source_runs)]
        for column, group in groups:
            row = {"source": source, "column": column, "n_falls": len(group)}
            if len(group):
                args = (group["x_km"], group["y_km"], group["downfall_azimuth_deg"])
                misfit = axial_misfit(*args, gx, gy)
                best = np.unravel_index(np.argmin(misfit), misfit.shape)
                bx, by = float(gx[best]), float(gy[best])
                row.update({"best_x_km": bx, "best_y_km": by, "error_km": math.hypot(bx, by),
                            "at_grid_edge": bool(max(abs(bx), abs(by)) >= grid[-1] - 1e-9),
                            "misfit_best": float(misfit[best]),
                            "misfit_epicentre": float(axial_misfit(*args, 0.0, 0.0))})
                if source in SOURCES:
                    centre = subevents(source)[["x_km", "y_km"]].to_numpy()[[0, -1]].mean(axis=0)
                    row["error_rupture_centre_km"] = math.hypot(bx - centre[0], by - centre[1])
            rows.append(row)
    return pd.DataFrame(rows)


# ---------------------------------------------------------------- map figure
COLUMN_COLOURS = {"monolithic": "tab:blue", "drums": "tab:orange"}


def plot_downfall_map(runs, source_name, path, arrow_km=3.0):
    """Map of one source: rupture and mechanism, each site's downfall arrows.

    Solid line: surface projection of the modelled rupture (sub-event line);
    dashed line for a dipping fault: where its plane would reach the surface.
    Arrows (length ``arrow_km`` on the map) point in the downfall azimuth,
    one colour per column type; an open circle marks a column not toppled.
    ``runs``: columns of RUN_COLUMNS (rows of other sources are ignored when a
    ``source`` column is present).
    """
    import matplotlib  # noqa: PLC0415
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.lines import Line2D  # noqa: PLC0415
    from obspy.imaging.beachball import beach  # noqa: PLC0415

    src = source_parameters(source_name)
    frame = _checked_runs(runs)
    if "source" in frame.columns:
        frame = frame[frame["source"] == source_name]
    subs = subevents(source_name)
    reach = max(float(np.hypot(frame["x_km"], frame["y_km"]).max()) if len(frame) else 0.0,
                float(np.hypot(subs["x_km"], subs["y_km"]).max())) + arrow_km + 4.0

    fig, ax = plt.subplots(figsize=(8, 8))
    for ring in sorted(set(np.round(np.hypot(frame["x_km"], frame["y_km"]), 6))):
        ax.add_patch(plt.Circle((0, 0), ring, fill=False, color="0.85", lw=0.8))
    ax.plot(subs["x_km"], subs["y_km"], "-", color="darkred", lw=3, solid_capstyle="butt")
    ax.plot(subs["x_km"], subs["y_km"], "o", color="darkred", ms=4)
    if src["dip_deg"] < 90:
        up_dip = math.radians(src["strike_deg"] - 90.0)
        shift = src["depth_km"] / math.tan(math.radians(src["dip_deg"]))
        ax.plot(subs["x_km"] + shift * math.sin(up_dip), subs["y_km"] + shift * math.cos(up_dip),
                "--", color="darkred", lw=1.5)
    ax.plot(0, 0, "*", color="k", ms=14, zorder=5)
    ax.add_collection(beach([src["strike_deg"], src["dip_deg"], src["rake_deg"]],
                            xy=(-reach + 4.5, reach - 4.5), width=7.0, facecolor="darkred",
                            linewidth=1, zorder=6))

    columns = sorted(frame["column"].unique(), key=lambda c: (c not in COLUMN_COLOURS, c))
    for k, column in enumerate(columns):
        colour = COLUMN_COLOURS.get(column, f"C{k + 2}")
        group = frame[frame["column"] == column]
        fell = group["toppled"].astype(bool) & group["downfall_azimuth_deg"].notna()
        az = np.radians(group.loc[fell, "downfall_azimuth_deg"].to_numpy(float))
        ax.quiver(group.loc[fell, "x_km"], group.loc[fell, "y_km"], arrow_km * np.sin(az),
                  arrow_km * np.cos(az), color=colour, angles="xy", scale_units="xy", scale=1,
                  width=0.004, zorder=4)
        offset = 0.6 * (k - (len(columns) - 1) / 2)
        ax.plot(group.loc[~fell, "x_km"] + offset, group.loc[~fell, "y_km"], "o", mfc="none",
                mec=colour, ms=7, zorder=4)
    ax.plot(frame["x_km"], frame["y_km"], ".", color="0.4", ms=3, zorder=3)

    handles = [Line2D([], [], color="darkred", lw=3, label="rupture (surface projection)"),
               Line2D([], [], marker="*", color="k", ls="none", ms=12, label="epicentre")]
    if src["dip_deg"] < 90:
        handles.append(Line2D([], [], color="darkred", ls="--", label="fault plane at surface"))
    for k, column in enumerate(columns):
        colour = COLUMN_COLOURS.get(column, f"C{k + 2}")
        handles += [Line2D([], [], color=colour, lw=2, label=f"{column}: downfall direction"),
                    Line2D([], [], marker="o", mfc="none", mec=colour, ls="none",
                           label=f"{column}: not toppled")]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3,
              fontsize=8, frameon=False)
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_aspect("equal")
    ax.set_xlabel("East of epicentre (km)")
    ax.set_ylabel("North of epicentre (km)")
    ax.set_title(f"{source_name}: Mw {src['mw']:g} {src['mechanism']} (strike "
                 f"{src['strike_deg']:g}, dip {src['dip_deg']:g}, rake {src['rake_deg']:g}), "
                 f"depth {src['depth_km']:g} km")
    ax.grid(alpha=0.3)
    files.save_figure(fig, path, dpi=150, bbox_inches="tight")
    plt.close(fig)


# ---------------------------------------------------------------- command line
def _float_list(text):
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise InputError(f"--rings: not a comma-separated list of km: {text!r}") from None
    return values


def add_command(subparsers):
    parser = subparsers.add_parser(
        "synthetics",
        help="generate synthetic near-field motions (pyprop8) around two M6.5 sources",
        description="Compute 3-component synthetic ground motions (pyprop8, layered crust) at "
        "sites on rings around a vertical strike-slip and a thrust source, write them as "
        "processed motions under results/synthetics/<source>/ (cached by parameter hash), and "
        "compare PGA/PGV with NGA-West2 models (results/synthetics/gmm_check.csv).")
    parser.add_argument("--source", default="all", help=f"one of {', '.join(SOURCES)} or 'all'")
    parser.add_argument("--rings", default="5,10,20", help="ring radii in km (default 5,10,20)")
    parser.add_argument("--step", type=float, default=30.0,
                        help="azimuth step between sites in degrees (default 30)")
    parser.add_argument("--quick", action="store_true",
                        help=f"fmax {QUICK_FMAX_HZ:g} Hz, {QUICK_DURATION_S:g} s, "
                        "written to results/synthetics-quick")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                        help="parallel processes (default: all cores)")
    parser.set_defaults(func=run_command)


def run_command(args):
    names = list(SOURCES) if args.source == "all" else [args.source]
    for name in names:
        source_parameters(name)
    rings = _float_list(args.rings)
    for name in names:
        started = time.monotonic()
        paths = generate(name, rings, args.step, quick=args.quick, jobs=max(1, args.jobs))
        print(f"{name}: {len(paths)} sites in {paths[0].parent} "
              f"({time.monotonic() - started:.0f} s, cached when ~0)")
    base = paths[0].parent.parent
    summary = write_gmm_summary(base)
    shown = summary[summary["source"].isin(names)]
    print("synthetic / GMM median (median over sites of each ring; RotD50 unless 'geomean'; "
          f"Vs30 {GMM_VS30_M_S:g} m/s):")
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"written: {base / 'gmm_check.csv'}")
    return 0
