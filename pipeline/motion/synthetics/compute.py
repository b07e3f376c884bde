"""pyprop8 synthetics at sites on rings around a source, written as processed motions."""
import contextlib
import importlib.metadata
import json
import logging
import math
import os
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np
import pyprop8
from pyprop8.utils import clp_filter, make_moment_tensor, rtf2xyz, stf_trapezoidal
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from pipeline import RECORDS_DIR, files
from pipeline.files import InputError, die_with_parent, display_path
from pipeline.motion import Motion
from pipeline.motion.synthetics.gmm import gmm_check, write_gmm_summary
from pipeline.motion.synthetics.sites import AZIMUTH_STEP_DEG, RINGS_KM, settings, site_table
from pipeline.motion.synthetics.sources import (CRUST_LAYERS, LEAD_TIME_S, source_parameters,
                                                subevents)

log = logging.getLogger(__name__)

GENERATOR_VERSION = 2  # bump when the written motions change
PYPROP8_VERSION = importlib.metadata.version("pyprop8")
# the sources' summed sub-event displacements at the default settings, computed by this
# project and shipped so that a fresh checkout need not recompute them (README there)
SHIPPED_DIR = RECORDS_DIR / "synthetics"
# core s of pyprop8 per site, sub-event, time sample and wavenumber, the long-run gate's
# estimate before any computation (the shipped displacements: 72 sites x 5 sub-events,
# 751 samples x 2104 wavenumbers, took 198.3 s on 2 cores)
PYPROP8_CORE_S_PER_SAMPLE = 7.0e-7


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


def _cache_key(source_name, cfg, num):
    params = {k: v for k, v in cfg.items() if k != "base"}
    return files.content_hash(GENERATOR_VERSION, source_name, source_parameters(source_name),
                              CRUST_LAYERS, LEAD_TIME_S, params, num)


def generate(source_name, rings_km=RINGS_KM, azimuth_step_deg=AZIMUTH_STEP_DEG, duration_s=30.0,
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
    return generate_sources([source_name], rings_km, azimuth_step_deg, duration_s, sampling_hz,
                            fmax_hz, out_dir, quick, jobs)[source_name]


def generate_sources(source_names, rings_km=RINGS_KM, azimuth_step_deg=AZIMUTH_STEP_DEG,
                     duration_s=30.0, sampling_hz=100.0, fmax_hz=10.0, out_dir=None,
                     quick=False, jobs=None, ship=False, allow_long=None):
    """:func:`generate` for several sources at once: {source name: npz paths}.  The
    sub-events of every source to compute share one pool of ``jobs`` processes (two
    sources of five sub-events on 2 cores: five rounds of pyprop8 calls instead of six);
    each source's motions are the same as computed alone.  A source whose displacements
    ``SHIPPED_DIR`` holds for the same cache key and pyprop8 version is not recomputed;
    ``ship``: compute every source (no cache) and write its displacements there.
    ``allow_long``: False refuses a computation estimated at over an hour on ``jobs``
    cores before it starts, True warns (:func:`pipeline.files.check_long`), None: no
    gate."""
    cfg = settings(rings_km, azimuth_step_deg, duration_s, sampling_hz, fmax_hz, out_dir, quick)
    num = numerics(cfg["duration_s"], cfg["sampling_hz"], cfg["fmax_hz"])
    plans, tasks = {}, []
    for name in source_names:
        src = source_parameters(name)
        sites = site_table(name, cfg["rings_km"], cfg["azimuth_step_deg"], cfg["base"])
        paths = [Path(p) for p in sites["npz"]]
        manifest_path = cfg["base"] / name / "manifest.json"
        key = _cache_key(name, cfg, num)
        plans[name] = {"src": src, "sites": sites, "paths": paths, "key": key}
        if (not ship and manifest_path.is_file() and all(p.is_file() for p in paths)
                and json.loads(manifest_path.read_text()).get("cache_key") == key):
            if not (cfg["base"] / name / "gmm_check_sites.csv").is_file():
                _write_gmm_check(name, cfg)
            continue
        shipped = None if ship else load_shipped(name, key, len(sites), num["nt"])
        if shipped is not None:
            plans[name]["shipped"] = shipped
            continue
        mechanism = (src["strike_deg"], src["dip_deg"], src["rake_deg"])
        for _, sub in subevents(name).iterrows():
            sub = dict(sub, rise_s=src["subevent_rise_s"], duration_s=src["subevent_duration_s"])
            tasks.append((name, (sites["x_km"].to_numpy(), sites["y_km"].to_numpy(), mechanism,
                                 sub, num, cfg["fmax_hz"])))
    if tasks:
        jobs = jobs or os.cpu_count() or 1
        totals, elapsed = _run_tasks(tasks, plans, num, jobs, allow_long)
        for name, total in totals.items():
            _write_source(name, plans[name], total, cfg, num, elapsed, jobs)
            if ship:
                save_shipped(name, plans[name]["key"], total, elapsed, jobs)
    for name, plan in plans.items():
        if "shipped" in plan:
            origin = display_path(shipped_path(name))
            log.info(f"{name}: pyprop8 displacements from {origin} (the same parameters and "
                     "pyprop8 version; not recomputed)")
            _write_source(name, plan, plan["shipped"], cfg, num, 0.0, 0, origin=origin)
    write_gmm_summary(cfg["base"])
    return {name: plans[name]["paths"] for name in source_names}


def _run_tasks(tasks, plans, num, jobs, allow_long):
    """The pyprop8 sub-event calls of ``tasks`` [(source name, call)] on ``jobs``
    processes, summed per source in order (reproducible sums): ({name: displacements},
    wall s); the long-run gate first (``allow_long``, as :func:`generate_sources`)."""
    if allow_long is not None:
        computed = list(dict.fromkeys(name for name, _ in tasks))
        sites = sum(len(plans[name]["sites"]) for name in computed)
        core_s = sum(len(call[0]) for _, call in tasks) * num["nt"] * num["nk"] \
            * PYPROP8_CORE_S_PER_SAMPLE          # sites x sub-events x samples
        files.check_long(f"synthetics of {', '.join(computed)}", sites, core_s / sites,
                         jobs, allow_long, "a larger --step or fewer --rings",
                         unit="sites")
    started = time.monotonic()
    totals = dict.fromkeys((name for name, _ in tasks), 0.0)
    progress = tqdm(total=len(tasks), desc="pyprop8 " + ", ".join(totals),
                    unit="sub-event")
    calls = [task for _, task in tasks]
    parallel = jobs > 1 and len(tasks) > 1
    pool_or_none = Pool(min(jobs, len(tasks)), initializer=die_with_parent,
                        initargs=(os.getpid(),)) if parallel \
        else contextlib.nullcontext()
    with pool_or_none as pool:
        results = (pool.imap(_point_source_task, calls) if parallel    # in order:
                   else map(_point_source_task, calls))                # reproducible sums
        for (name, _), disp in zip(tasks, results):
            totals[name] = totals[name] + disp
            progress.update(1)
    progress.close()
    return totals, time.monotonic() - started


def shipped_path(source_name):
    return SHIPPED_DIR / f"{source_name}.npz"


def load_shipped(source_name, key, n_sites, nt):
    """The shipped displacements (m, sites x 3 x nt, the sum of the source's sub-events)
    of ``source_name`` when computed with cache key ``key`` by this pyprop8 version, else
    None; InputError naming the file when it is not such an array."""
    path = shipped_path(source_name)
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["cache_key"]) != key or str(data["pyprop8_version"]) != PYPROP8_VERSION:
                return None
            disp = np.array(data["displacement_m"], dtype=float)
    except (OSError, ValueError, KeyError) as exc:
        raise InputError(f"{path}: not a shipped synthetics file ({exc})") from None
    if disp.shape != (n_sites, 3, nt) or not np.isfinite(disp).all():
        raise InputError(f"{path}: displacement_m must be {n_sites} x 3 x {nt} finite values, "
                         f"got shape {disp.shape}")
    return disp


def save_shipped(source_name, key, total, elapsed_s, jobs):
    """Write ``total`` (m, sites x 3 x nt) to ``SHIPPED_DIR`` with its cache key, the
    pyprop8 version and what computing it cost (atomically)."""
    files.write_npz(shipped_path(source_name), cache_key=np.array(key),
                    pyprop8_version=np.array(PYPROP8_VERSION),
                    displacement_m=np.asarray(total, dtype=float),
                    compute_seconds=np.array(round(elapsed_s, 1)), jobs=np.array(jobs))


def _write_source(name, plan, total, cfg, num, elapsed, jobs, origin="computed"):
    """Write one source's site motions, its GMM check and its manifest (last);
    ``origin``: where the displacements came from ("computed" or the shipped file)."""
    source_dir = cfg["base"] / name
    manifest_path = source_dir / "manifest.json"
    manifest_path.unlink(missing_ok=True)
    for stale in set(source_dir.glob("*.npz")) - set(plan["paths"]):
        stale.unlink()
    for (_, site), path in zip(plan["sites"].iterrows(), plan["paths"]):
        acc, vel, disp = band_limited_motion(total[site.name].T, num["dt_calc"], num["upsample"])
        meta = _site_meta(name, plan["src"], site, cfg, num, plan["key"])
        Motion(1.0 / cfg["sampling_hz"], acc, vel, disp, meta=meta).save(path)
    _write_gmm_check(name, cfg)
    files.write_json(manifest_path, {
        "cache_key": plan["key"], "source": name, "source_parameters": plan["src"],
        "crust_layers_thickness_vp_vs_rho": [  # thickness null: the half-space
            [None if math.isinf(layer[0]) else layer[0], *layer[1:]] for layer in CRUST_LAYERS],
        "settings": {k: v for k, v in cfg.items() if k != "base"}, "numerics": num,
        "displacements": origin, "compute_seconds": round(elapsed, 1), "jobs": jobs,
        "sites": [p.name for p in plan["paths"]]})


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
