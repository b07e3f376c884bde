"""Sites on rings around a synthetic source's epicentre, and the generator's settings
(rings, azimuth step, duration, sampling, band, where the motions are written)."""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import RESULTS_DIR
from pipeline.files import InputError
from pipeline.motion.synthetics.sources import source_parameters

DEFAULT_OUT_DIR = RESULTS_DIR / "synthetics"
QUICK_OUT_DIR = RESULTS_DIR / "synthetics-quick"
QUICK_FMAX_HZ = 2.5
QUICK_DURATION_S = 20.0
RINGS_KM = (5.0, 10.0, 20.0)     # default site rings around the epicentre
RING_RANGE_KM = (0.05, 100.0)   # epicentral distances the generator takes (as a hidden truth)
AZIMUTH_STEP_DEG = 30.0          # default step between the sites of a ring
MIN_AZIMUTH_STEP_DEG = 0.01      # the finest: 36,000 sites a ring (the long-run gate
#                                  weighs what that costs before any computation)


def settings(rings_km, azimuth_step_deg, duration_s, sampling_hz, fmax_hz, out_dir, quick):
    if quick:
        fmax_hz = min(fmax_hz, QUICK_FMAX_HZ)
        duration_s = min(duration_s, QUICK_DURATION_S)
    rings = tuple(float(r) for r in rings_km)
    low, high = RING_RANGE_KM
    if not rings or not all(math.isfinite(r) and low <= r <= high for r in rings):
        raise InputError(f"site rings {', '.join(f'{r:g}' for r in rings) or 'none'} km: the "
                         f"generator takes rings of {low:g}-{high:g} km")
    if len(set(rings)) < len(rings):
        raise InputError(f"site rings {', '.join(f'{r:g}' for r in rings)} km: a ring given "
                         "twice (its sites would be computed and counted twice)")
    if not MIN_AZIMUTH_STEP_DEG <= azimuth_step_deg <= 360:
        raise InputError(f"azimuth step {azimuth_step_deg:g} deg outside "
                         f"[{MIN_AZIMUTH_STEP_DEG:g}, 360]")
    base = Path(out_dir) if out_dir is not None else (QUICK_OUT_DIR if quick else DEFAULT_OUT_DIR)
    return {"rings_km": rings, "azimuth_step_deg": float(azimuth_step_deg),
            "duration_s": float(duration_s), "sampling_hz": float(sampling_hz),
            "fmax_hz": float(fmax_hz), "base": base}


def site_table(source_name, rings_km=RINGS_KM, azimuth_step_deg=AZIMUTH_STEP_DEG, out_dir=None,
               quick=False):
    """Sites on rings around the epicentre of ``source_name``.

    Columns: site_id, x_km, y_km (East, North of the epicentre), ring_km,
    site_azimuth_deg (epicentre to site), back_azimuth_deg (site to
    epicentre), distance_km (epicentral), npz (path of the motion file).
    """
    source_parameters(source_name)
    cfg = settings(rings_km, azimuth_step_deg, 1.0, 100.0, 1.0, out_dir, quick)
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
