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

Sites are written like processed records (docs/records.md: npz with dt, acc, vel,
disp in m/s^2, m/s, m, columns East, North, Up, and a JSON meta) under
``results/synthetics/<source>/<site_id>.npz``, cached by a content hash of
every generator parameter.
"""
from pipeline.motion.synthetics.compute import (band_limited_motion, generate, generate_sources,
                                                 moment_tensor_xyz, numerics,
                                                 point_source_displacement)
from pipeline.motion.synthetics.gmm import (GMM_VS30_M_S, gmm_check, gmm_summary, rotd50,
                                            rupture_distances, write_gmm_summary)
from pipeline.motion.synthetics.sites import (AZIMUTH_STEP_DEG, DEFAULT_OUT_DIR, QUICK_DURATION_S,
                                               QUICK_FMAX_HZ, QUICK_OUT_DIR, RINGS_KM,
                                               site_table)
from pipeline.motion.synthetics.sources import (CRUST_LAYERS, LEAD_TIME_S, SOURCES,
                                                moment_from_mw, rupture_centre,
                                                source_parameters, subevents)
