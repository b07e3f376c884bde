"""Synthetic near-field motions: conventions, symmetry, decay, geometry, cache, statistics.

pyprop8 calls are kept tiny (fmax <= 1 Hz, a few receivers, short windows).
"""
import hashlib
import json
import math

import numpy as np
import pandas as pd
import pytest

from pipeline.figures.synthetic_map import plot_downfall_map
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion import synthetics as syn
from pipeline.motion.synthetics import compute as generate_module
from pipeline.stats.circular import direction_differences, direction_table
from pipeline.stats.location import locate_source_from_falls

RIGHT_LATERAL_NS = (0.0, 90.0, 180.0)  # strike N, vertical, rake 180


def _displacement(x_km, y_km, mechanism=RIGHT_LATERAL_NS, depth_km=8.0, fmax_hz=1.0,
                  duration_s=20.0, layers=syn.CRUST_LAYERS, m0_nm=1e18):
    """Displacement (m) of one point source at the origin, (nsite, 3, nt), and dt."""
    num = syn.numerics(duration_s, 2.5 * fmax_hz, fmax_hz, layers)
    sub = {"x_km": 0.0, "y_km": 0.0, "depth_km": depth_km, "delay_s": 0.0, "m0_nm": m0_nm,
           "rise_s": 0.5, "duration_s": 1.0}
    disp = syn.point_source_displacement(np.asarray(x_km, float), np.asarray(y_km, float),
                                         mechanism, sub, num, fmax_hz, layers)
    return disp, num["dt_calc"]


def _okada_point_strike_slip(x_okada, y_okada, depth, potency, alpha):
    """Okada (1985, eq. 25) surface displacement of a vertical strike-slip point source.

    Okada's frame: x along strike, y to its left, z up, all in m; ``potency`` =
    slip x area (m^3), positive = left-lateral; alpha = mu / (lambda + mu).
    Returns (u_x, u_y, u_z) in m.
    """
    x, y, d = x_okada, y_okada, depth
    q = y  # q = y sin(dip) - d cos(dip) with dip = 90
    r = np.sqrt(x * x + y * y + d * d)
    i1 = alpha * y * (1 / (r * (r + d) ** 2) - x * x * (3 * r + d) / (r ** 3 * (r + d) ** 3))
    i2 = alpha * x * (1 / (r * (r + d) ** 2) - y * y * (3 * r + d) / (r ** 3 * (r + d) ** 3))
    i4 = -alpha * x * y * (2 * r + d) / (r ** 3 * (r + d) ** 2)
    scale = -potency / (2 * np.pi)
    return (scale * (3 * x * x * q / r ** 5 + i1), scale * (3 * x * y * q / r ** 5 + i2),
            scale * (3 * x * d * q / r ** 5 + i4))


def test_final_displacement_matches_okada_point_source_in_half_space():
    """Pins pyprop8's units (moment 1e18 N m, output km -> m) and axes (East, North, Up)."""
    vp, vs, rho = 6.0, 6.0 / math.sqrt(3.0), 2.7  # Poisson solid: lambda = mu
    layers = ((math.inf, vp, vs, rho),)
    x = np.array([5.0, 0.0, 3.0, -4.0, 6.0])
    y = np.array([0.0, 5.0, 4.0, 2.0, -7.0])
    m0 = 1e18  # N m
    disp, _ = _displacement(x, y, depth_km=5.0, layers=layers, m0_nm=m0, duration_s=30.0)
    final = disp[:, :, -1]
    mu = rho * 1e3 * (vs * 1e3) ** 2  # Pa
    # Okada frame for strike N: x_okada = North, y_okada = West; right-lateral = negative potency.
    ux, uy, uz = _okada_point_strike_slip(y * 1e3, -x * 1e3, 5e3, -m0 / mu, alpha=0.5)
    expected = np.column_stack([-uy, ux, uz])  # East, North, Up
    scale = np.abs(expected).max()
    assert scale > 1e-4  # about 1 mm: a meaningful comparison
    np.testing.assert_allclose(final, expected, atol=0.03 * scale)


def test_static_offset_sign_by_quadrant():
    """Right-lateral slip on a N-S vertical fault (layered crust).

    Sites across the fault move with their block: east of it south, west of
    it north.  The double couple is symmetric in fault and auxiliary (E-W)
    plane, on which the same tensor is slip of the north side to the west:
    sites north move west, south move east.  The P axis (NE-SW) shortens and
    the T axis (NW-SE) lengthens, so sites NE and SW move toward the source,
    NW and SE away (the Okada comparison above checks this field in a half-space).
    """
    az = np.radians(np.arange(0, 360, 45))
    x, y = 6.0 * np.sin(az), 6.0 * np.cos(az)
    disp, _ = _displacement(x, y, m0_nm=1e18, duration_s=30.0)
    east, north = disp[:, 0, -1], disp[:, 1, -1]
    inward, outward = -1, 1
    expected = {0: (-1, 0), 90: (0, -1), 180: (1, 0), 270: (0, 1),  # (sign E, sign N)
                45: (inward, inward), 225: (-inward, -inward),
                135: (outward, -outward), 315: (-outward, outward)}
    for k, angle in enumerate(range(0, 360, 45)):
        sign_e, sign_n = expected[angle]
        size = math.hypot(east[k], north[k])
        assert size > 1e-4
        for sign, value in ((sign_e, east[k]), (sign_n, north[k])):
            if sign == 0:
                assert abs(value) < 1e-6 * size
            else:
                assert np.sign(value) == sign, (angle, east[k], north[k])


def test_mirror_symmetry_of_vertical_strike_slip():
    """Mirroring x -> -x maps the right-lateral N-S fault to a left-lateral one,
    i.e. the source to minus itself, so u(-x, y) = -R u(x, y) with R = diag(-1, 1, 1):
    fault-normal (East) component equal, fault-parallel (North) and Up opposite.
    Likewise across the auxiliary plane: u(x, -y) = (-u_E, u_N, -u_Z)(x, y)."""
    disp, _ = _displacement([3.0, -3.0, 3.0], [4.0, 4.0, -4.0], duration_s=12.0)
    peak = np.abs(disp).max()
    base, mirror_x, mirror_y = disp
    np.testing.assert_allclose(mirror_x, base * np.array([1, -1, -1])[:, None], atol=1e-9 * peak)
    np.testing.assert_allclose(mirror_y, base * np.array([-1, 1, -1])[:, None], atol=1e-9 * peak)
    assert np.abs(base).max(axis=1).min() > 1e-3 * peak  # all components non-trivial


def test_mirror_symmetry_of_thrust_across_plane_normal_to_strike():
    """An E-W thrust (strike 90, rake 90) is its own mirror image across x = 0:
    u(-x, y) = (-u_E, u_N, u_Z)(x, y)."""
    disp, _ = _displacement([4.0, -4.0], [-3.0, -3.0], mechanism=(90.0, 40.0, 90.0),
                            depth_km=10.0, duration_s=12.0)
    peak = np.abs(disp).max()
    np.testing.assert_allclose(disp[1], disp[0] * np.array([-1, 1, 1])[:, None], atol=1e-9 * peak)


def test_amplitude_decays_with_distance():
    az = math.radians(30.0)
    rings = np.array([5.0, 10.0, 20.0])
    disp, dt = _displacement(rings * math.sin(az), rings * math.cos(az), duration_s=25.0)
    speed = np.linalg.norm(np.gradient(disp, dt, axis=2), axis=1).max(axis=1)
    static = np.linalg.norm(disp[:, :, -1], axis=1)
    assert speed[0] > 1.3 * speed[1] > 1.3 ** 2 * speed[2]
    # the static offset vanishes at the epicentre (symmetry) and peaks near r ~ depth;
    # beyond it, it falls like a double couple's 1 / R^2
    assert static[1] > 2.0 * static[2]


def test_band_limited_motion_differentiates_a_smooth_step():
    dt, upsample, tau, t0 = 0.2, 4, 1.0, 10.0
    t = np.arange(151) * dt
    step = 0.5 * (1 + np.tanh((t - t0) / tau))
    disp = np.column_stack([0.3 * step, -0.1 * step, 0.0 * step])
    acc, vel, out = syn.band_limited_motion(disp, dt, upsample)
    t_out = np.arange(len(out)) * dt / upsample
    assert len(out) == (len(t) - 1) * upsample + 1
    sech2 = 1 / np.cosh((t_out - t0) / tau) ** 2
    exact_vel = 0.5 / tau * sech2
    exact_acc = -exact_vel * 2 * np.tanh((t_out - t0) / tau) / tau
    np.testing.assert_allclose(out[:, 0], 0.3 * 0.5 * (1 + np.tanh((t_out - t0) / tau)), atol=1e-4)
    np.testing.assert_allclose(vel[:, 0], 0.3 * exact_vel, atol=1e-3 * 0.15)
    np.testing.assert_allclose(acc[:, 1], -0.1 * exact_acc, atol=2e-3 * 0.04)


@pytest.fixture
def tiny_source(monkeypatch):
    params = dict(syn.SOURCES["strike_slip"], subevents_along_strike_km=(0.0,), depth_km=6.0)
    monkeypatch.setitem(syn.SOURCES, "tiny", params)
    return "tiny"


def test_generate_writes_motions_with_exact_geometry_and_caches(tiny_source, tmp_path,
                                                                 monkeypatch):
    kwargs = dict(rings_km=(4, 8), azimuth_step_deg=90, duration_s=10.0, sampling_hz=100.0,
                  fmax_hz=1.0, out_dir=tmp_path)
    paths = syn.generate(tiny_source, **kwargs)
    assert [p.name for p in paths] == [f"r{r:02d}_az{a:03d}.npz" for r in (4, 8)
                                       for a in (0, 90, 180, 270)]
    hand = {0: 180.0, 90: 270.0, 180: 0.0, 270: 90.0}  # back azimuth of sites N, E, S, W
    for path in paths:
        motion = Motion.load(path)
        meta = motion.meta
        ring, azimuth = meta["ring_km"], meta["site_azimuth_deg"]
        x, y = ring * math.sin(math.radians(azimuth)), ring * math.cos(math.radians(azimuth))
        assert meta["back_azimuth_deg"] == pytest.approx(hand[int(azimuth)], abs=1e-9)
        assert 0.0 <= meta["back_azimuth_deg"] < 360.0
        to_epicentre = math.degrees(math.atan2(-x, -y))
        assert math.sin(math.radians(meta["back_azimuth_deg"] - to_epicentre)) == pytest.approx(
            0.0, abs=1e-12)
        assert math.cos(math.radians(meta["back_azimuth_deg"] - to_epicentre)) > 0
        assert meta["epicentral_distance_km"] == pytest.approx(ring)
        # walking the distance along the back azimuth from the site reaches the epicentre
        baz = math.radians(meta["back_azimuth_deg"])
        reach = meta["epicentral_distance_km"]
        assert (x + reach * math.sin(baz), y + reach * math.cos(baz)) == pytest.approx((0, 0),
                                                                                         abs=1e-9)
        assert motion.dt == pytest.approx(0.01)
        assert motion.acc.shape == motion.disp.shape == (1001, 3)
        np.testing.assert_allclose(np.gradient(motion.disp, 0.01, axis=0), motion.vel,
                                   atol=0.01 * np.abs(motion.vel).max())

    stamps = [p.stat().st_mtime_ns for p in paths]

    def no_pyprop8(*args, **kwargs):
        raise AssertionError("pyprop8 called although the cache is current")

    monkeypatch.setattr(generate_module, "point_source_displacement", no_pyprop8)
    assert syn.generate(tiny_source, **kwargs) == paths
    assert [p.stat().st_mtime_ns for p in paths] == stamps
    with pytest.raises(AssertionError, match="cache is current"):
        syn.generate(tiny_source, **dict(kwargs, fmax_hz=0.8))
    manifest = json.loads((tmp_path / tiny_source / "manifest.json").read_text())
    assert len(manifest["sites"]) == 8
    summary = pd.read_csv(tmp_path / "gmm_check.csv")
    assert list(summary["ring_km"]) == [4.0, 8.0] and list(summary["n_sites"]) == [4, 4]
    ratios = summary.filter(like="ratio_").to_numpy()
    assert np.isfinite(ratios).all() and (ratios > 0).all()


def test_shipped_displacements_are_used_instead_of_pyprop8_and_written_as_computed(
        tiny_source, tmp_path, monkeypatch):
    """A shipped file with the settings' cache key replaces the pyprop8 calls and gives
    the motions computing gives; another key or ``ship`` computes (and ``ship`` writes
    the file); a damaged file is named in one line."""
    kwargs = dict(rings_km=(4,), azimuth_step_deg=180, duration_s=8.0, sampling_hz=100.0,
                  fmax_hz=1.0)
    monkeypatch.setattr(generate_module, "SHIPPED_DIR", tmp_path / "shipped")
    computed = syn.generate_sources([tiny_source], out_dir=tmp_path / "a", ship=True,
                                    **kwargs)[tiny_source]
    shipped = generate_module.shipped_path(tiny_source)
    with np.load(shipped) as data:
        assert data["displacement_m"].shape[:2] == (2, 3)
        assert str(data["pyprop8_version"]) == generate_module.PYPROP8_VERSION

    def no_pyprop8(*args, **kwargs):
        raise AssertionError("pyprop8 called")

    monkeypatch.setattr(generate_module, "point_source_displacement", no_pyprop8)
    from_file = syn.generate_sources([tiny_source], out_dir=tmp_path / "b", **kwargs)[tiny_source]
    for a, b in zip(computed, from_file):
        np.testing.assert_array_equal(Motion.load(a).acc, Motion.load(b).acc)
    manifest = json.loads((tmp_path / "b" / tiny_source / "manifest.json").read_text())
    assert manifest["displacements"].endswith(f"shipped/{tiny_source}.npz")
    with pytest.raises(AssertionError, match="pyprop8 called"):     # another key: computed
        syn.generate_sources([tiny_source], out_dir=tmp_path / "c", **dict(kwargs, fmax_hz=0.8))
    installed = generate_module.PYPROP8_VERSION
    monkeypatch.setattr(generate_module, "PYPROP8_VERSION", "0.0-another")
    with pytest.raises(AssertionError, match="pyprop8 called"):     # another pyprop8: computed
        syn.generate_sources([tiny_source], out_dir=tmp_path / "e", **kwargs)
    monkeypatch.setattr(generate_module, "PYPROP8_VERSION", installed)
    shipped.write_bytes(b"not an npz")
    with pytest.raises(InputError, match=r"shipped/tiny.npz: not a shipped synthetics file"):
        syn.generate_sources([tiny_source], out_dir=tmp_path / "d", **kwargs)


def test_the_shipped_displacements_are_the_default_sources_and_near_the_gmm_medians(
        tmp_path, monkeypatch):
    """records/synthetics holds each source at the default settings (else run-all computes
    them: `python -m pipeline synthetics --ship`), with the SHA-256 its README states; the
    motions made from them (no pyprop8 call) have ring-median RotD50 PGA and PGV within a
    factor 2 of the NGA-West2 medians (CY14, BSSA14), an independent reference.  Taken
    as of the pyprop8 they name: a newer pyprop8 recomputes them (test above)."""
    readme = (generate_module.SHIPPED_DIR / "README.md").read_text()
    for name in syn.SOURCES:
        path = generate_module.shipped_path(name)
        assert f"{hashlib.sha256(path.read_bytes()).hexdigest()}  {path.name}" in readme
        with np.load(path) as data:
            monkeypatch.setattr(generate_module, "PYPROP8_VERSION", str(data["pyprop8_version"]))

    def no_pyprop8(*args, **kwargs):
        raise AssertionError("pyprop8 called: records/synthetics is not of the default "
                             "settings (run `python -m pipeline synthetics --ship`)")

    monkeypatch.setattr(generate_module, "point_source_displacement", no_pyprop8)
    syn.generate_sources(list(syn.SOURCES), out_dir=tmp_path)
    summary = pd.read_csv(tmp_path / "gmm_check.csv")
    assert sorted(summary["source"].unique()) == sorted(syn.SOURCES)
    assert list(summary["ring_km"].unique()) == list(syn.RINGS_KM)
    ratios = summary[[f"ratio_{m}_{g}" for m in ("pga", "pgv") for g in ("cy14", "bssa14")]]
    assert ((ratios > 0.5) & (ratios < 2.0)).all().all(), summary.to_string()


def test_site_table_geometry():
    sites = syn.site_table("thrust")
    assert len(sites) == 36
    assert set(sites["ring_km"]) == {5.0, 10.0, 20.0}
    diff = (sites["back_azimuth_deg"] - sites["site_azimuth_deg"]) % 360
    np.testing.assert_allclose(diff, 180.0, atol=1e-9)
    np.testing.assert_allclose(np.hypot(sites["x_km"], sites["y_km"]), sites["distance_km"])
    with pytest.raises(InputError):
        syn.site_table("nonexistent")


def test_rupture_distances_by_hand():
    # strike-slip: rupture segment x = 0, y from -4 to 12 km at 8 km depth
    rrup, rjb, rx = syn.rupture_distances("strike_slip", np.array([5.0, 0.0]),
                                          np.array([0.0, 20.0]))
    np.testing.assert_allclose(rjb, [5.0, 8.0])
    np.testing.assert_allclose(rrup, [math.hypot(5, 8), math.hypot(8, 8)])
    np.testing.assert_allclose(rx, [5.0, 0.0])
    # thrust: strike 90 (fault dips south): a site south is on the hanging-wall side
    _, _, rx = syn.rupture_distances("thrust", np.array([0.0]), np.array([-6.0]))
    np.testing.assert_allclose(rx, [6.0])


def test_rotd50_of_linear_and_circular_motion():
    t = np.linspace(0, 1, 2001)
    linear = np.column_stack([2 * np.sin(2 * np.pi * 3 * t), 0 * t])
    circular = np.column_stack([np.cos(2 * np.pi * 3 * t), np.sin(2 * np.pi * 3 * t)])
    assert syn.rotd50(linear) == pytest.approx(2 * math.cos(math.radians(45)), rel=1e-2)
    assert syn.rotd50(circular) == pytest.approx(1.0, rel=1e-3)


def _runs(rows):
    frame = pd.DataFrame(rows, columns=["column", "toppled", "downfall_azimuth_deg",
                                        "back_azimuth_deg", "x_km", "y_km"])
    frame.insert(0, "site_id", [f"s{i}" for i in range(len(frame))])
    return frame


def test_direction_table_classifies_hand_made_angles():
    runs = _runs([
        ("monolithic", True, 170.0, 180.0, 0, 5),  # diff -10: toward
        ("monolithic", True, 0.0, 180.0, 0, 5),  # diff 180: away
        ("monolithic", True, 315.0, 0.0, 0, -5),  # diff -45: toward (boundary)
        ("monolithic", True, 135.0, 0.0, 0, -5),  # diff 135: away (boundary)
        ("monolithic", True, 100.0, 10.0, 0, -5),  # diff 90: transverse
        ("monolithic", False, np.nan, 10.0, 0, -5),
        ("drums", True, 200.0, 190.0, 0, 5),  # diff 10
        ("drums", True, 20.0, 190.0, 0, 5),  # diff -170: away
    ])
    diffs = direction_differences(runs)
    np.testing.assert_allclose(diffs["diff_deg"].to_numpy()[[0, 1, 2, 3, 4, 6, 7]],
                               [-10, 180, -45, 135, 90, 10, -170])
    assert list(diffs["direction_class"]) == ["toward", "away", "toward", "away", "transverse",
                                              "not toppled", "toward", "away"]
    table = direction_table(runs).set_index("column")
    mono, drums = table.loc["monolithic"], table.loc["drums"]
    # monolithic diffs -10, 180, -45, 135, 90: doubled -20, 0, -90, -90, 180 (by hand)
    doubled = np.radians([-20, 0, -90, -90, 180])
    resultant = np.hypot(np.cos(doubled).sum(), np.sin(doubled).sum()) / 5
    assert mono.axial_resultant_length == pytest.approx(resultant)
    assert (mono.n_runs, mono.n_toppled, mono.toward, mono.away, mono.transverse) == (6, 5, 2, 2, 1)
    # drums: +10 and -170 lie on one axis 10 deg from the back azimuth, in opposite senses
    assert drums.axial_mean_diff_deg == pytest.approx(10.0)
    assert drums.axial_resultant_length == pytest.approx(1.0)
    assert drums.resultant_length == pytest.approx(0.0, abs=1e-12)


def test_locate_source_from_falls_finds_the_point_the_falls_align_with():
    target = (3.0, -2.0)
    az = np.radians(np.arange(0, 360, 30))
    x, y = 10 * np.sin(az), 10 * np.cos(az)
    toward = np.degrees(np.arctan2(target[0] - x, target[1] - y)) % 360
    falls = np.where(np.arange(len(az)) % 2, toward, (toward + 180) % 360)  # toward or away
    runs = _runs([("monolithic", True, f, 0.0, xi, yi) for f, xi, yi in zip(falls, x, y)])
    result = locate_source_from_falls(runs, extent_km=15, step_km=0.5).set_index("column")
    best = result.loc["monolithic"]
    assert (best.best_x_km, best.best_y_km) == pytest.approx(target, abs=1e-9)
    assert best.misfit_best == pytest.approx(0.0, abs=1e-12)
    assert best.error_km == pytest.approx(math.hypot(*target))
    assert best.misfit_epicentre > 0.01
    assert not best.at_grid_edge


def test_downfall_map_is_written(tmp_path):
    sites = syn.site_table("strike_slip", rings_km=(5,), azimuth_step_deg=90)
    rows = []
    for _, site in sites.iterrows():
        rows.append((site.site_id, "monolithic", True, site.back_azimuth_deg))
        rows.append((site.site_id, "drums", False, np.nan))
    runs = pd.DataFrame(rows, columns=["site_id", "column", "toppled", "downfall_azimuth_deg"])
    runs = runs.merge(sites[["site_id", "back_azimuth_deg", "x_km", "y_km"]], on="site_id")
    path = tmp_path / "map.png"
    plot_downfall_map(runs, "strike_slip", path)
    assert path.stat().st_size > 10_000
    with pytest.raises(InputError, match="lacks columns"):
        plot_downfall_map(runs.drop(columns="x_km"), "strike_slip", path)
