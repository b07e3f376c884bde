"""Tests of the records stage: ground-motion measures against analytic values,
rotation, file round trips, bad inputs, and the shipped catalogue."""
import math

import numpy as np
import pytest
from obspy import Stream, Trace, UTCDateTime
from obspy.io.sac import SACTrace

from pipeline import cli, records
from pipeline.records import sets
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.files import InputError
from pipeline.motion import Motion, measures
from pipeline.records import processing
from pipeline.records.readers import read_record

RATE = 100.0


# ---------------------------------------------------------------- measures
def test_arias_intensity_of_pure_sine():
    dt, amplitude, freq, duration = 0.001, 3.0, 2.0, 5.0   # whole periods
    t = np.arange(0, duration + dt / 2, dt)
    acc = amplitude * np.sin(2 * np.pi * freq * t)
    expected = np.pi / (2 * G) * amplitude ** 2 * duration / 2
    assert measures.arias_intensity(acc, dt) == pytest.approx(expected, rel=1e-6)


def test_mean_period_of_single_tone():
    dt, freq = 0.01, 2.5
    t = np.arange(2000) * dt                   # 20 s: 2.5 Hz is an exact FFT bin
    assert measures.mean_period(np.sin(2 * np.pi * freq * t), dt) == pytest.approx(1 / freq,
                                                                                  rel=1e-9)


def test_significant_duration_of_linear_energy_build_up():
    dt = 0.01
    acc = np.r_[np.ones(1001), np.zeros(500)]  # a^2 constant for 10 s: Arias grows linearly
    assert measures.significant_duration(acc, dt) == pytest.approx(0.9 * 10.0, abs=2 * dt)


def wavelet(t, D, t0, w, f):
    """(acc m/s^2, vel m/s, disp m) at times ``t`` (s) of d(t) = D exp(-((t-t0)/w)^2)
    sin(2 pi f t), differentiated analytically (D m, t0 and w s, f Hz)."""
    g = np.exp(-((t - t0) / w) ** 2)
    gp = -2 * (t - t0) / w ** 2 * g
    gpp = (4 * (t - t0) ** 2 / w ** 4 - 2 / w ** 2) * g
    s, sp, spp = np.sin(2 * np.pi * f * t), 2 * np.pi * f * np.cos(2 * np.pi * f * t), \
        -(2 * np.pi * f) ** 2 * np.sin(2 * np.pi * f * t)
    return D * (gpp * s + 2 * gp * sp + g * spp), D * (gp * s + g * sp), D * g * s


def test_peaks_of_analytically_integrated_pulse_survive_processing():
    """d(t) = D exp(-((t-t0)/w)^2) sin(2 pi f t): its analytic second derivative is
    processed; PGV and PGD must match the analytic velocity and displacement."""
    dt = 0.005
    acc, vel, disp = wavelet(np.arange(0, 40.0, dt), 0.2, 20.0, 2.0, 0.8)
    enz = np.column_stack([acc, 0.5 * acc, np.zeros_like(acc)])
    a, v, d, _ = processing.process(enz, dt)
    assert np.max(np.abs(v[:, 0])) == pytest.approx(np.max(np.abs(vel)), rel=0.02)
    assert np.max(np.abs(d[:, 0])) == pytest.approx(np.max(np.abs(disp)), rel=0.02)
    assert np.max(np.abs(d[:, 1])) == pytest.approx(0.5 * np.max(np.abs(disp)), rel=0.02)
    assert np.allclose(d[:, 2], 0.0)
    # acc, vel, disp mutually consistent: central differences of disp give vel
    assert np.allclose(np.gradient(d[:, 0], dt)[1:-1], v[1:-1, 0], atol=1e-3 * np.max(np.abs(v)))


def _sensor_stream(east, north, up, azimuths, rate=RATE):
    """Project an East/North motion on sensors at ``azimuths`` (deg) + an Up sensor."""
    traces = []
    for i, az in enumerate(azimuths):
        data = east * math.sin(math.radians(az)) + north * math.cos(math.radians(az))
        tr = Trace(data.copy(), header={"sampling_rate": rate, "channel": f"HN{i + 1}"})
        tr.stats.azimuth, tr.stats.dip = az, 0.0
        traces.append(tr)
    tr = Trace(up.copy(), header={"sampling_rate": rate, "channel": "HNZ"})
    tr.stats.azimuth, tr.stats.dip = 0.0, -90.0
    return Stream(traces + [tr])


@pytest.mark.parametrize("azimuth", [30.0, 210.0, 300.0])
def test_rotation_recovers_known_azimuth(azimuth):
    t = np.arange(0, 10, 1 / RATE)
    pulse = np.exp(-((t - 5) / 0.3) ** 2)
    east, north = pulse * math.sin(math.radians(azimuth)), pulse * math.cos(math.radians(azimuth))
    stream = _sensor_stream(east, north, 0.1 * pulse, azimuths=(70.0, 160.0))
    enz, dt = records.to_east_north_up(stream, "synthetic")
    assert dt == pytest.approx(1 / RATE)
    assert np.allclose(enz[:, 0], east, atol=1e-12) and np.allclose(enz[:, 1], north, atol=1e-12)
    assert np.allclose(enz[:, 2], 0.1 * pulse)
    peak, found, _ = measures.horizontal_peak(enz)
    assert peak == pytest.approx(1.0, rel=1e-3)
    assert found == pytest.approx(azimuth, abs=1e-6)


# ---------------------------------------------------------------- file round trips
def _motion(n=3000):
    rng = np.random.default_rng(1)
    t = np.arange(n) / RATE
    envelope = np.exp(-((t - 12) / 4) ** 2)
    return [envelope * rng.standard_normal(n) for _ in range(3)]


def test_miniseed_round_trip(tmp_path):
    east, north, up = _motion()
    start = UTCDateTime(2020, 1, 1)
    stream = Stream([Trace(data.astype(np.float64), header={
        "network": "XX", "station": "TEST", "channel": f"HN{c}", "sampling_rate": RATE,
        "starttime": start}) for data, c in ((east, "E"), (north, "N"), (up, "Z"))])
    path = tmp_path / "rec.mseed"
    stream.write(str(path), format="MSEED")
    read, _ = read_record(path)
    enz, _ = records.to_east_north_up(read, path.name)
    assert np.allclose(enz, np.column_stack([east, north, up]))

    out = tmp_path / "out"
    motion, motion_path = records.processed_motion(path, cache_dir=out)
    assert motion.acc.shape[1] == 3 and motion.dt == pytest.approx(0.01)
    transient = records.processing.filter_transient_s(records.processing.BAND["freqmin_hz"],
                                                      records.processing.BAND["corners"])
    assert motion.duration < 30.0 + 2 * transient   # signal window and the filter's transient
    assert motion.meta["back_azimuth_deg"] is None
    assert motion.meta["has_vertical"] is True
    # cached: a second call does not rewrite; a given back azimuth is a new input
    mtime = motion_path.stat().st_mtime_ns
    assert records.processed_motion(path, cache_dir=out)[1] == motion_path
    assert motion_path.stat().st_mtime_ns == mtime
    assert records.processed_motion(motion_path)[1] == motion_path
    with_baz, _ = records.processed_motion(path, back_azimuth=123.0, cache_dir=out)
    assert with_baz.meta["back_azimuth_deg"] == 123.0
    assert "user" in with_baz.meta["back_azimuth_source"]
    # provenance: every processing step and the software versions
    steps = [s["step"] for s in motion.meta["processing"]["steps"]]
    assert steps == [name for name, _ in processing.DEFAULT_STEPS]
    assert set(motion.meta["processing"]["software"]) >= {"obspy", "numpy", "scipy", "yade"}


@pytest.mark.parametrize("lead_s, mode", [(0.0, "default"), (30.0, "default"),
                                           (0.0, "none")])
def test_a_processed_record_says_where_the_record_starts(tmp_path, lead_s, mode):
    """A Ricker wavelet (2 Hz, symmetric: a zero-phase band-pass keeps its peak in place)
    centred 20 s after the first sample of a 40 s file (50 s with 30 s of zeros before
    it): the processed motion's peak, read on the record's clock (motion time +
    ``start_in_file_s``), is where the file has it.  The processed motion starts the
    filter's transient (a minute) before the wavelet's onset, before the file's first
    sample (``start_in_file_s`` < 0); run as given, the motion is the record and the
    clocks agree."""
    t = np.arange(0.0, 40.0, 1 / RATE)
    arg = (math.pi * 2.0 * (t - 20.0)) ** 2
    ricker = np.r_[np.zeros(int(round(lead_s * RATE))), (1 - 2 * arg) * np.exp(-arg)]
    stream = Stream([Trace(scale * ricker, header={"station": "CLK", "channel": f"HN{c}",
                                                   "sampling_rate": RATE})
                     for scale, c in ((3.0, "E"), (1.5, "N"), (0.5, "Z"))])
    path = tmp_path / "clock.mseed"
    stream.write(str(path), format="MSEED")
    motion, _ = records.processed_motion(path, cache_dir=None, mode=mode)
    peak_s = np.argmax(np.hypot(motion.acc[:, 0], motion.acc[:, 1])) * motion.dt
    assert peak_s + motion.start_in_file_s == pytest.approx(20.0 + lead_s, abs=0.5 / RATE)
    transient = processing.filter_transient_s(processing.BAND["freqmin_hz"],
                                              processing.BAND["corners"])
    if mode == "none":
        assert motion.start_in_file_s == 0.0
    else:      # the filter's margin before the wavelet's first 0.1 % of energy, < 1 s early
        centre = 20.0 + lead_s
        assert centre - transient - 1.0 < motion.start_in_file_s < centre - transient


def test_sac_round_trip_with_coordinates_and_azimuths(tmp_path):
    """Motion purely North recorded by sensors at 45 and 135 deg; the epicentre is
    1 degree due north of the station: back azimuth 0, distance about 111.2 km."""
    _, north, up = _motion()
    for channel, az, inc, data in (("HN1", 45.0, 90.0, north * math.cos(math.radians(45))),
                                   ("HN2", 135.0, 90.0, north * math.cos(math.radians(135))),
                                   ("HNZ", 0.0, 0.0, up)):
        sac = SACTrace(data=data.astype(np.float32), delta=1 / RATE, kstnm="SACST",
                       kcmpnm=channel, cmpaz=az, cmpinc=inc, stla=40.0, stlo=20.0,
                       evla=41.0, evlo=20.0, mag=6.1)
        sac.write(str(tmp_path / f"rec.{channel}.sac"))
    stream, info = read_record(tmp_path / "rec.*.sac")
    enz, _ = records.to_east_north_up(stream, "sac")
    assert np.allclose(enz[:, 0], 0.0, atol=1e-6)
    assert np.allclose(enz[:, 1], north, atol=1e-5)
    assert info["station_lat"] == 40.0 and info["event_lat"] == 41.0 and info["magnitude"] == pytest.approx(6.1)
    meta = records.processed_motion(tmp_path / "rec.*.sac", back_azimuth=200.0,
                                    cache_dir=tmp_path / "out")[0].meta
    assert min(meta["back_azimuth_deg"], 360 - meta["back_azimuth_deg"]) < 1e-6
    assert meta["epicentral_distance_km"] == pytest.approx(111.2, rel=0.01)
    assert "coordinates" in meta["back_azimuth_source"]


def _write_at2(path, component, values_g, dt=0.01):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD",
             f"Test Quake, 1/1/2000, Test Station, {component}",
             "ACCELERATION TIME SERIES IN UNITS OF G",
             f"NPTS=  {len(values_g)}, DT=   {dt:.4f} SEC"]
    rows = [" ".join(f"{v: .7E}" for v in values_g[i:i + 5]) for i in range(0, len(values_g), 5)]
    path.write_text("\n".join(lines + rows) + "\n")


def test_at2_round_trip_finds_sibling_components(tmp_path):
    east, north, up = (x * 0.1 for x in _motion())
    _write_at2(tmp_path / "TEST090.AT2", "90", east)
    _write_at2(tmp_path / "TEST360.AT2", "360", north)
    _write_at2(tmp_path / "TEST-UP.AT2", "UP", up)
    stream, info = read_record(tmp_path / "TEST090.AT2")
    assert info["station"] == "Test Station"
    enz, _ = records.to_east_north_up(stream, "at2")
    assert np.allclose(enz, G * np.column_stack([east, north, up]), atol=1e-6)
    motion, _ = records.processed_motion(tmp_path / "TEST090.AT2", cache_dir=tmp_path / "out")
    assert np.all(np.isfinite(motion.disp))


# ---------------------------------------------------------------- bad inputs
def _write_stream(path, rates=(RATE, RATE, RATE), channels="ENZ", nan=False):
    traces = []
    for rate, channel, data in zip(rates, channels, _motion()):
        data = data.copy()
        if nan:
            data[100] = np.nan
        traces.append(Trace(data, header={"station": "BAD", "channel": f"HN{channel}",
                                          "sampling_rate": rate}))
    Stream(traces).write(str(path), format="MSEED")
    return path


BAD_INPUTS = {
    "missing file": lambda d: d / "nothing_here.mseed",
    "garbage bytes": lambda d: (d / "junk.mseed").write_bytes(
        np.random.default_rng(0).bytes(4096)) and d / "junk.mseed",
    "NaN sample": lambda d: _write_stream(d / "nan.mseed", nan=True),
    "missing component": lambda d: _write_stream(d / "two.mseed", channels="EN"),
    "mismatched sampling rates": lambda d: _write_stream(d / "rates.mseed",
                                                         rates=(100.0, 50.0, 100.0)),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_raises_one_line_error_and_writes_nothing(tmp_path, case, capsys):
    path = BAD_INPUTS[case](tmp_path)
    out = tmp_path / "out"
    with pytest.raises(InputError) as info:
        records.processed_motion(path, cache_dir=out)
    message = str(info.value)
    assert message and "\n" not in message
    assert cli.main(["records", str(path), "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip().startswith("error:")
    assert not out.exists()


def test_cli_rejects_impossible_back_azimuth(tmp_path):
    assert cli.main(["records", "GM20", "--back-azimuth", "400", "--out",
                     str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()


# ---------------------------------------------------------------- shipped catalogue
@pytest.fixture(scope="module")
def catalogue_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("records")
    assert cli.main(["records", "--all", "--no-figures", "--out", str(out)]) == 0
    return out


def test_every_catalogued_record_is_finite_and_plausible(catalogue_run):
    import pandas as pd
    table = pd.read_csv(catalogue_run / "records.csv")
    ids = sets.record_ids("all")
    assert sorted(table["id"]) == sorted(ids)
    for record_id in ids:
        motion = Motion.load(catalogue_run / f"{record_id}.npz")
        params = measures.record_parameters(motion)
        assert 0.5 < params["pga_h"] < 25.0, record_id              # m/s^2
        assert 0.05 < params["pgv_h"] < 3.0, record_id              # m/s
        assert 0.004 < params["pgd_h"] < 1.5, record_id             # m (RSN134: 5 mm)
        assert 0.05 < params["tm_e"] < 2.0 and 1.0 < params["ts_e"] < 100.0, record_id
        end = np.hypot(*motion.disp[-1, :2])
        assert end < 0.05 * params["pgd_h"], record_id           # ends at rest, no drift
        assert (params["pga_z"] > 0) == motion.meta["has_vertical"], record_id
    gm20 = table.set_index("id").loc["GM20"]
    assert 1.0 < gm20["pga_h"] < 3.0


def test_catalogue_distances_and_back_azimuths_agree_with_independent_values():
    """Ridgecrest epicentral distances as listed by gmprocess (data/lme table, ComCat
    ci38457511); back azimuths against a spherical-earth initial bearing."""
    cat = records.catalog().set_index("id")
    gmprocess_km = {"RC-CCC": 34.47, "RC-CLC": 5.13, "RC-TOW2": 15.58}
    for record_id, km in gmprocess_km.items():
        assert cat.loc[record_id, "epicentral_distance_km"] == pytest.approx(km, abs=0.05)
    located = cat.dropna(subset=["station_lat", "event_lat"])
    assert len(located) == 55        # the 4 first located records and 51 near-source ones
    for record_id, row in located.iterrows():
        lat1, lon1, lat2, lon2 = map(math.radians, (row.station_lat, row.station_lon,
                                                    row.event_lat, row.event_lon))
        bearing = math.degrees(math.atan2(
            math.sin(lon2 - lon1) * math.cos(lat2),
            math.cos(lat1) * math.sin(lat2) - math.sin(lat1) * math.cos(lat2) * math.cos(lon2 - lon1)))
        diff = (row.back_azimuth_deg - bearing + 180) % 360 - 180
        assert abs(diff) < 0.5, record_id
    unlocated = cat[cat["station_lat"].isna()]
    assert unlocated["back_azimuth_deg"].isna().all()   # never invented
