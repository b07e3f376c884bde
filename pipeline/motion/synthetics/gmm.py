"""Synthetics against ground-motion models: RotD50 PGA/PGV against NGA-West2 medians."""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import files
from pipeline.constants import STANDARD_GRAVITY
from pipeline.motion import Motion
from pipeline.motion.synthetics.sites import AZIMUTH_STEP_DEG, RINGS_KM, site_table
from pipeline.motion.synthetics.sources import SOURCES, source_parameters, subevents

GMM_VS30_M_S = 760.0  # reference rock for the ground-motion-model check


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


def gmm_check(source_names=tuple(SOURCES), rings_km=RINGS_KM, azimuth_step_deg=AZIMUTH_STEP_DEG,
              out_dir=None, quick=False):
    """Per-site synthetic PGA/PGV against NGA-West2 medians (pygmm), DataFrame.

    Synthetic horizontal peaks as RotD50 (the models' definition) and as the
    geometric mean of the East and North peaks; model medians of Chiou &
    Youngs (2014) and Boore et al. (2014) for the source's Mw, mechanism, dip,
    top depth and the site's rupture distances, at Vs30 = GMM_VS30_M_S.
    Units: PGA in g, PGV in cm/s.
    """
    import pygmm  # lazy: pygmm, slow to import, only needed here

    models = {"cy14": pygmm.ChiouYoungs2014, "bssa14": pygmm.BooreStewartSeyhanAtkinson2014}
    rows = []
    for name in source_names:
        src = source_parameters(name)
        sites = site_table(name, rings_km, azimuth_step_deg, out_dir, quick)
        rrup, rjb, rx = rupture_distances(name, sites["x_km"], sites["y_km"])
        for i, site in sites.iterrows():
            motion = Motion.load(site.npz)
            acc, vel = motion.acc[:, :2], motion.vel[:, :2]
            row = {"source": name, "site_id": site.site_id, "ring_km": site.ring_km,
                   "rrup_km": rrup[i], "rjb_km": rjb[i], "rx_km": rx[i],
                   "pga_rotd50_g": rotd50(acc) / STANDARD_GRAVITY,
                   "pgv_rotd50_cm_s": rotd50(vel) * 100.0,
                   "pga_geomean_g": np.sqrt(np.prod(np.abs(acc).max(axis=0))) / STANDARD_GRAVITY,
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
