"""The paper's scenario in the inversion: the nominal twin runs at the paper's sites of its
two sources (rings of PAPER_RINGS_KM km, every node azimuth), inverted site by site and
all sites within half the forward table's last ring together."""
import math

import pandas as pd

from pipeline.files import write_csv
from pipeline.inversion.credible import in_arc
from pipeline.inversion.observations import ColumnObservation
from pipeline.inversion.posterior import invert
from pipeline.inversion.sites import OBS_UNCERTAINTY_DEG, map_azimuth_error, site_frame, \
    site_position
from pipeline.motion.synthetics import SOURCES
from pipeline.stats.circular import azimuth_deg
from pipeline.inversion import write_outputs

PAPER_RINGS_KM = (5.0, 10.0, 20.0)
PAPER_MECHANISMS = {"strike_slip": "strike-slip", "thrust": "thrust"}


def paper_grid(main_grid, source_name, quick=False):
    """The forward grid holding the nominal twin runs at the paper's sites of one source."""
    src = SOURCES[source_name]
    mech = PAPER_MECHANISMS[source_name]
    return main_grid.replace(mechanisms=((mech, src["dip_deg"], src["rake_deg"]),),
                             depths_km=(src["depth_km"],), magnitudes=(src["mw"],),
                             distances_km=PAPER_RINGS_KM[:2] if quick else PAPER_RINGS_KM,
                             members=0, nominal=True)


def paper_nodes(table, source_name):
    """(slice, ring indices, azimuth indices) of the paper's sites in ``table`` or None."""
    src = SOURCES[source_name]
    try:
        s = table.slice_index(PAPER_MECHANISMS[source_name], src["depth_km"], src["mw"])
    except KeyError:
        return None
    if table.nominal_toppled is None:
        return None
    sl = table.slices[s]
    if (sl["dip_deg"], sl["rake_deg"]) != (src["dip_deg"], src["rake_deg"]):
        return None
    rings = [i for i, r in enumerate(table.distances_km) if r in PAPER_RINGS_KM]
    return (s, rings, list(range(len(table.azimuths_deg)))) if rings else None


def paper_scenario(model, obs_table, source_name, candidates):
    """Per site of the paper's rings: what its twin (nominal run) shows and what the
    inversion of that one site gives; plus the joint inversion of the sites within half
    the forward table's last ring of the source (then every candidate within that half of
    the source is within the table's reach of every site; None when no ring is that near)."""
    src = SOURCES[source_name]
    strike = src["strike_deg"]
    s, rings, azimuths = paper_nodes(obs_table, source_name)
    rows, all_sites = [], []
    for i in rings:
        for j in azimuths:
            theta = obs_table.azimuths_deg[j]
            site_az = (theta + strike) % 360.0          # epicentre -> site, geographic
            e, n = site_position(obs_table.distances_km[i], site_az)
            cols = []
            for c, column in enumerate(obs_table.columns):
                if not obs_table.nominal_valid[s, i, j, c]:
                    continue
                if obs_table.nominal_toppled[s, i, j, c]:
                    az = (obs_table.nominal_azimuth_deg[s, i, j, c] + strike) % 360.0
                    cols.append(ColumnObservation(column, "fallen", float(az),
                                                  OBS_UNCERTAINTY_DEG))
                else:
                    cols.append(ColumnObservation(column, "standing"))
            name = f"r{obs_table.distances_km[i]:g}_az{site_az:03.0f}"
            if obs_table.distances_km[i] <= model.table.distances_km[-1] / 2 + 1e-9:
                all_sites.append((name, e, n, tuple(cols)))
            observations, truth = site_frame([(name, e, n, tuple(cols))])
            post = invert(model, observations, candidates)
            summary = post.summary()
            true_baz = (site_az + 180.0) % 360.0
            fell = {c.column: (round(c.downfall_azimuth_deg) if c.fallen else "stands")
                    for c in cols}
            rows.append({"source": source_name, "site": name,
                         "distance_km": float(obs_table.distances_km[i]),
                         "true_back_azimuth_deg": true_baz,
                         "drums": fell.get("drums"), "monolithic": fell.get("monolithic"),
                         "fallen": sum(c.fallen for c in cols),
                         "width95_deg": summary["back_azimuth_ci95_width_deg"],
                         "back_azimuth_in_95": in_arc(true_baz, summary["back_azimuth_ci95_deg"]),
                         "map_back_azimuth_deg": summary["back_azimuth_map_deg"],
                         "map_error_deg": map_azimuth_error(summary, true_baz),
                         "epicentre_in_95": post.contains(*truth, level=0.95),
                         "credible_area_95_km2": summary["credible_area_95_km2"],
                         "reach_warning": summary["reach_warning"] is not None,
                         "p_true_mechanism": summary["mechanism_posterior"].get(
                             PAPER_MECHANISMS[source_name], 0.0)})
    if not all_sites:
        return pd.DataFrame(rows), None, None
    observations, truth = site_frame(all_sites)
    joint = invert(model, observations, candidates)
    js = joint.summary()
    true_baz = azimuth_deg(*truth)
    joint_row = {"source": source_name, "sites": len(all_sites),
                 "sites_within_km": max(math.hypot(e, n) for _, e, n, _ in all_sites),
                 "fallen": observations.n_fallen, "columns": observations.n_columns,
                 "epicentre_error_km": math.hypot(js["map_epicentre_km"][0] - truth[0],
                                                  js["map_epicentre_km"][1] - truth[1]),
                 "epicentre_in_95": joint.contains(*truth, level=0.95),
                 "credible_area_95_km2": js["credible_area_95_km2"],
                 "mechanism_posterior": js["mechanism_posterior"],
                 "strike_map_deg": js["map_candidate"]["strike_deg"],
                 "true_strike_deg": strike, "reach_km": js["reach_km"],
                 "reach_edge_fraction": js["reach_edge_fraction"],
                 "reach_warning": js["reach_warning"]}
    return pd.DataFrame(rows), joint_row, (joint, observations, truth)


def paper_outputs(full_model, paper_tables, candidates, out_dir, forward_info):
    """The paper's sources inverted site by site and all sites together:
    paper_scenario_sites.csv and the maps; returns (per-site rows, joint rows, figures)."""
    paper_rows, paper_joint, figures = [], [], []
    for source_name, obs_table in (paper_tables or {}).items():
        if obs_table is None or paper_nodes(obs_table, source_name) is None:
            continue
        sites, joint_row, detail = paper_scenario(full_model, obs_table, source_name,
                                                  candidates)
        paper_rows.append(sites)
        if joint_row is None:
            continue
        joint, observations, truth = detail
        paper_joint.append(joint_row)
        sub = out_dir / f"paper_{source_name}_all_sites"
        write_outputs(joint, observations, sub, forward_info,
                      truth={"epicentre_km": list(truth),
                             "mechanism": PAPER_MECHANISMS[source_name],
                             "back_azimuth_deg": math.degrees(math.atan2(*truth)) % 360,
                             "distance_km": math.hypot(*truth)},
                      title=f"The paper's {source_name} source: the twins of the "
                            f"{joint_row['sites']} sites within "
                            f"{joint_row['sites_within_km']:g} km")
        figures.append(sub / "posterior_map.png")
    paper_sites = pd.concat(paper_rows, ignore_index=True) if paper_rows else pd.DataFrame()
    if not paper_sites.empty:
        write_csv(out_dir / "paper_scenario_sites.csv", paper_sites)
    return paper_sites, paper_joint, figures
