"""Near-source readers (``pipeline/records/readers``: geonet, dmg_v2, mseed_stationxml,
at2_triplet) checked against what each shipped file states independently, and
against small malformed files.

Independent statements used: GeoNet V2A/V1A and DMG V2 headers print each
component's peak acceleration and its time; StationXML gives the sensitivity,
azimuth, dip and coordinates; AT2 headers give NPTS and DT; the NGA-West2
flatfile rows give coordinates and filter corners.  The test parses those with
its own regular expressions / ElementTree, never through the reader.
"""
import csv
import gzip
import json
import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import obspy
import pytest
from obspy import UTCDateTime

from pipeline.files import InputError
from pipeline.records import readers
from pipeline.records.readers import at2_triplet as at2
from pipeline.records.readers import dmg_v2, geonet
from pipeline.records.readers import mseed_stationxml as mseed

REPO = Path(__file__).resolve().parents[2]
RECORDS = REPO / "records"
G = 9.80665

KAIKOURA = sorted((RECORDS / "kaikoura2016").glob("*.V?A.gz"))
COALINGA = RECORDS / "coalinga1983" / "ce36456p_CE36456.V2.gz"
RIDGECREST = RECORDS / "ridgecrest2019_mseed"
NGA = RECORDS / "ngawest2"
RSNS = sorted(int(p.name[3:].split("_")[0]) for p in NGA.glob("RSN*_1.AT2.gz"))


def text_of(path):
    raw = Path(path).read_bytes()
    return (gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw).decode("latin-1")


def one_line_error(call, *args, **kwargs):
    """Run ``call``; it must raise InputError with a non-empty one-line message."""
    with pytest.raises(InputError) as info:
        call(*args, **kwargs)
    message = str(info.value)
    assert message.strip() and "\n" not in message
    return message


def flatfile():
    with open(NGA / "flatfile_rows.csv", newline="") as handle:
        return {int(row["rsn"]): row for row in csv.DictReader(handle)}


def test_shipped_files_are_present():
    assert len(KAIKOURA) == 4 and COALINGA.is_file()
    assert len(sorted(RIDGECREST.glob("*.mseed"))) == 30
    assert len(RSNS) == 38 and len(flatfile()) == 38


# ---------------------------------------------------------------- GeoNet V1A / V2A
def _geonet_buffer_start(text):
    """Buffer start time of the first channel from the integer header (GeoNet format:
    fields 9-10 year/month, 19-20 day/hour, 39-40 minute/milliseconds)."""
    lines = text.splitlines()
    ints = [int(line[k:k + 8]) for line in lines[16:20] for k in range(0, 80, 8)]
    return UTCDateTime(ints[8], ints[9], ints[18], ints[19], ints[38]) + ints[39] / 1000.0


@pytest.mark.parametrize("path", KAIKOURA, ids=lambda p: p.name)
def test_geonet_peaks_and_times_match_the_header(path):
    text = text_of(path)
    stated = re.findall(r"^Component\s+(\S+).*\n\s*Acceleration:\s+peak\s+(-?[\d.]+)\s+mm/s/s"
                        r"\s+at\s+([\d.]+)", text, re.M | re.I)
    assert len(stated) == 3
    stream, info = geonet.read(path)
    assert [tr.stats.channel for tr in stream] == [c for c, _, _ in stated]
    start = _geonet_buffer_start(text)
    for trace, (_, peak, at) in zip(stream, stated):
        i = int(np.argmax(np.abs(trace.data)))
        # Header peak and samples print the same series; samples have 0.1 mm/s^2
        # resolution, but V1 samples of 5 digits lose the decimal in their 8-character
        # field (-11026 vs header -11026.2): 0.5 mm/s^2 covers both (< 0.05 % here).
        assert trace.data[i] * 1000.0 == pytest.approx(float(peak), abs=0.5)
        # the header's peak time (printed to 0.01 s) counts from the buffer start; V2
        # series begin 5 s earlier (prepended padding), which the trace start carries
        t = trace.stats.starttime + i * trace.stats.delta - start
        assert abs(t - float(at)) <= 0.005 + 1e-6


@pytest.mark.parametrize("path", KAIKOURA, ids=lambda p: p.name)
def test_geonet_coordinates_orientation_and_sampling_from_the_header(path):
    text = text_of(path)
    lines = text.splitlines()
    site = re.match(r"Site\s+(\w+)\s+(\d+) (\d+) (\d+)S\s+(\d+) (\d+) (\d+)E", lines[1])
    lat = -(int(site.group(2)) + int(site.group(3)) / 60 + int(site.group(4)) / 3600)
    lon = int(site.group(5)) + int(site.group(6)) / 60 + int(site.group(7)) / 3600
    epi = re.match(r"Epicentre\s+(\d+) (\d+) (\d+)S\s+(\d+) (\d+) (\d+)E", lines[8])
    npts = int(re.search(r"Number of points\s+(\d+)", lines[9]).group(1))
    dt = float(re.search(r"(?:intervals of|data at)\s+([\d.]+)\s*s", lines[10]).group(1))
    stream, info = geonet.read(path)
    assert info["station"] == f"NZ.{site.group(1)}"
    assert info["station_lat"] == pytest.approx(lat, abs=1e-9)
    assert info["station_lon"] == pytest.approx(lon, abs=1e-9)
    assert info["event_lat"] == pytest.approx(
        -(int(epi.group(1)) + int(epi.group(2)) / 60 + int(epi.group(3)) / 3600), abs=1e-9)
    assert info["horizontals_compass"] is True
    expected = {"N28W": 332.0, "S62W": 242.0, "N10E": 10.0, "N80W": 280.0}
    for trace in stream:
        assert trace.stats.npts == npts and trace.stats.delta == pytest.approx(dt)
        if trace.stats.channel == "Up":
            assert trace.stats.dip == -90.0
        else:
            assert (trace.stats.azimuth, trace.stats.dip) == (expected[trace.stats.channel], 0.0)
    if path.name.endswith(".V2A.gz"):  # "transition bands are .10-.25 Hz and 24.50-25.50 Hz"
        assert (info["lowest_usable_hz"], info["highest_usable_hz"]) == (0.25, 24.5)
    else:
        assert "lowest_usable_hz" not in info


def _geonet_lines():
    lines = text_of(RECORDS / "kaikoura2016" / "20161113_110259_WTMC_20.V2A.gz").splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("Corrected accelerogram")]
    return lines, starts


def _write(path, lines):
    path.write_text("\n".join(lines) + "\n", encoding="latin-1")
    return path


def test_geonet_malformed_files_raise_one_line_errors(tmp_path):
    lines, (c1, c2, c3) = _geonet_lines()
    block = c2 - c1

    bad = list(lines)
    bad[c1 + 1] = bad[c1 + 1].replace("37 10S", "37 XXS")
    assert "site line" in one_line_error(geonet.read, _write(tmp_path / "site.V2A", bad))

    bad = list(lines)
    bad[c1 + 9] = bad[c1 + 9].replace("8192", "8193")
    assert "points" in one_line_error(geonet.read, _write(tmp_path / "npts.V2A", bad))

    message = one_line_error(geonet.read, _write(tmp_path / "two.V2A", lines[:c3]))
    assert "missing component" in message and "two.V2A" in message

    bad = lines[:c2] + lines[c1:c2] + lines[c3:]
    assert "duplicated component" in one_line_error(geonet.read,
                                                    _write(tmp_path / "dup.V2A", bad))

    bad = lines[:c1 + 40] + lines[c1 + 41:]  # one acceleration data line less
    assert "sample" in one_line_error(geonet.read, _write(tmp_path / "count.V2A", bad))

    for label, field in (("zero", "  0.0000"), ("negative", " -0.0200"), ("dot", "       .")):
        bad = list(lines)
        row = bad[c1 + 22]
        assert row[40:48] == "  0.0200"
        bad[c1 + 22] = row[:40] + field + row[48:]
        one_line_error(geonet.read, _write(tmp_path / f"dt_{label}.V2A", bad))

    assert block == 2486


def test_broken_gzip_raises_one_line_error(tmp_path):
    good = (RECORDS / "kaikoura2016" / "20161113_110259_WTMC_20.V2A.gz").read_bytes()
    path = tmp_path / "broken.V2A.gz"
    path.write_bytes(good[:5000])
    assert "gzip" in one_line_error(geonet.read, path)


# ---------------------------------------------------------------- CSMIP/DMG V2
def test_dmg_v2_peaks_coordinates_and_orientation_match_the_header():
    text = text_of(COALINGA)
    peaks = re.findall(r"PEAK ACCELERATION =\s*(-?[\d.]+)\s+CM/SEC/SEC\s+AT\s+([\d.]+)", text)
    points = re.findall(r"^\s*(\d+) POINTS OF ACCEL DATA EQUALLY SPACED AT\s+([\d.]+) SEC", text,
                        re.M)
    chans = re.findall(r"^CORRECTED ACCELEROGRAM.*CHAN\s+\d+:\s*(\d+ DEG|UP)", text, re.M)
    stream, info = dmg_v2.read(COALINGA)
    assert len(stream) == len(peaks) == len(points) == len(chans) == 3
    for trace, (peak, at), (npts, dt), chan in zip(stream, peaks, points, chans):
        assert trace.stats.npts == int(npts) and trace.stats.delta == pytest.approx(float(dt))
        i = int(np.argmax(np.abs(trace.data)))
        # header and samples print the same series to 0.001 cm/s^2
        assert trace.data[i] * 100.0 == pytest.approx(float(peak), abs=1e-3)
        assert i * trace.stats.delta == pytest.approx(float(at), abs=trace.stats.delta / 2)
        if chan == "UP":
            assert trace.stats.dip == -90.0
        else:
            assert trace.stats.azimuth == float(chan.split()[0]) % 360 and trace.stats.dip == 0
    station = re.search(r"STATION NO\. 36456\s+([\d.]+)N, ([\d.]+)W", text)
    assert (info["station_lat"], info["station_lon"]) == (float(station.group(1)),
                                                          -float(station.group(2)))
    hypo = re.search(r"HYPOCENTER\(BRK\): ([\d.]+)N,([\d.]+)W", text)
    assert (info["event_lat"], info["event_lon"]) == (float(hypo.group(1)), -float(hypo.group(2)))
    # "BANDPASS FILTERED WITH RAMPS AT .050- .100 AND 23.00-25.00 CYC/SEC"
    assert (info["lowest_usable_hz"], info["highest_usable_hz"]) == (0.1, 23.0)
    assert info["horizontals_compass"] is True


def test_dmg_v2_malformed_files_raise_one_line_errors(tmp_path):
    lines = text_of(COALINGA).splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("CORRECTED ACCELEROGRAM")]
    accel = [i for i, line in enumerate(lines) if "POINTS OF ACCEL DATA" in line]

    bad = [line.replace("35.908N, 120.458W", "35.908X, 120.458W") for line in lines]
    assert "STATION NO." in one_line_error(dmg_v2.read, _write(tmp_path / "station.V2", bad))

    message = one_line_error(dmg_v2.read, _write(tmp_path / "two.V2", lines[:starts[2]]))
    assert "missing component" in message and "two.V2" in message

    bad = list(lines)
    bad[starts[2]] = bad[starts[2]].replace("CHAN  3:   0 DEG", "CHAN  3:  90 DEG")
    assert "duplicated component" in one_line_error(dmg_v2.read, _write(tmp_path / "dup.V2", bad))

    bad = lines[:accel[0] + 5] + lines[accel[0] + 6:]
    message = one_line_error(dmg_v2.read, _write(tmp_path / "count.V2", bad))
    assert "3243 samples, header says 3251" in message

    for label, value in (("zero", " .000"), ("negative", "-.020"), ("dot", "   .")):
        bad = list(lines)
        bad[accel[0]] = bad[accel[0]].replace("AT  .020 SEC", f"AT {value} SEC")
        assert bad[accel[0]] != lines[accel[0]]
        one_line_error(dmg_v2.read, _write(tmp_path / f"dt_{label}.V2", bad))


# ---------------------------------------------------------------- MiniSEED + StationXML
def _stationxml(path):
    """{channel: (sensitivity, input units, azimuth, dip)} and station (lat, lon), read with
    ElementTree (not obspy)."""
    root = ET.fromstring(gzip.decompress(path.read_bytes()))
    ns = {"s": "http://www.fdsn.org/xml/station/1"}
    station = root.find(".//s:Station", ns)
    channels = {}
    for cha in station.findall("s:Channel", ns):
        if cha.get("locationCode"):
            continue
        sens = cha.find("s:Response/s:InstrumentSensitivity", ns)
        channels[cha.get("code")] = (float(sens.find("s:Value", ns).text),
                                     sens.find("s:InputUnits/s:Name", ns).text,
                                     float(cha.find("s:Azimuth", ns).text),
                                     float(cha.find("s:Dip", ns).text))
    return channels, (float(station.find("s:Latitude", ns).text),
                      float(station.find("s:Longitude", ns).text))


@pytest.mark.parametrize("xml", sorted(RIDGECREST.glob("*.xml.gz")), ids=lambda p: p.name[:-7])
def test_mseed_is_counts_over_the_stationxml_sensitivity(xml):
    network, station = xml.name.split(".")[:2]
    channels, (lat, lon) = _stationxml(xml)
    stream, info = mseed.read(RIDGECREST / f"{network}.{station}..HN?.mseed")
    assert sorted(tr.stats.channel for tr in stream) == ["HNE", "HNN", "HNZ"]
    for trace in stream:
        raw = obspy.read(str(RIDGECREST / f"{trace.id}.mseed"))[0]
        value, units, azimuth, dip = channels[trace.stats.channel]
        assert units == "M/S**2"
        np.testing.assert_allclose(trace.data, raw.data / value, rtol=1e-12, atol=0)
        assert (trace.stats.azimuth, trace.stats.dip) == ((azimuth if dip == 0 else 0.0), dip)
    event = json.loads((RIDGECREST / "event.json").read_text())
    assert (info["station_lat"], info["station_lon"]) == (lat, lon)
    assert (info["event_lat"], info["event_lon"]) == (event["lat"], event["lon"])
    assert info["magnitude"] == event["magnitude"]
    assert UTCDateTime(info["origin_time"]) == UTCDateTime(event["time"])


@pytest.fixture
def ccc(tmp_path):
    """A copy of CI.CCC (three MiniSEED files, plain StationXML text, event.json)."""
    for path in RIDGECREST.glob("CI.CCC..HN?.mseed"):
        shutil.copy(path, tmp_path / path.name)
    shutil.copy(RIDGECREST / "event.json", tmp_path / "event.json")
    xml = gzip.decompress((RIDGECREST / "CI.CCC.xml.gz").read_bytes()).decode()
    (tmp_path / "CI.CCC.xml").write_text(xml)
    return tmp_path, xml


def test_mseed_reads_from_a_plain_stationxml(ccc):
    directory, _ = ccc
    stream, _ = mseed.read(directory / "CI.CCC..HN?.mseed")
    assert len(stream) == 3


def test_mseed_malformed_inputs_raise_one_line_errors(ccc):
    directory, xml = ccc
    pattern = directory / "CI.CCC..HN?.mseed"
    xml_path = directory / "CI.CCC.xml"

    xml_path.write_text(re.sub(r'<Channel code="HNN".*?</Channel>', "", xml, flags=re.S))
    assert "lacks the channel" in one_line_error(mseed.read, pattern)

    xml_path.write_text(re.sub(r"<Response>.*?</Response>", "", xml, flags=re.S))
    assert "no response" in one_line_error(mseed.read, pattern)

    xml_path.write_text(xml.replace("M/S**2", "M/S"))
    assert "not acceleration" in one_line_error(mseed.read, pattern)

    xml_path.write_text(xml)
    shutil.copy(directory / "CI.CCC..HNE.mseed", directory / "CI.CCC..HNE_copy.mseed")
    assert "duplicated channel" in one_line_error(mseed.read, directory / "CI.CCC..HN*.mseed")
    (directory / "CI.CCC..HNE_copy.mseed").unlink()

    assert "missing component" in one_line_error(mseed.read, directory / "CI.CCC..HN[EN].mseed")
    assert "glob" in one_line_error(mseed.read, directory / "CI.CCC..HNZ.mseed")

    event = json.loads((directory / "event.json").read_text())
    (directory / "event.json").write_text(json.dumps(dict(event, time="2000-01-01T00:00:00")))
    assert "wrong event" in one_line_error(mseed.read, pattern)
    (directory / "event.json").write_text(json.dumps(event))

    good = (RIDGECREST / "CI.CCC..HNE.mseed").read_bytes()
    for cut in (700, 40000):  # truncated inside the first record / after some records
        (directory / "CI.CCC..HNE.mseed").write_bytes(good[:cut])
        assert "MiniSEED" in one_line_error(mseed.read, pattern)
    (directory / "CI.CCC..HNE.mseed").write_bytes(good)

    xml_path.unlink()
    assert "no StationXML" in one_line_error(mseed.read, pattern)


# ---------------------------------------------------------------- NGA-West2 AT2 triplets
@pytest.mark.parametrize("rsn", [r for r in RSNS if r != 171])
def test_at2_triplets_match_their_npts_dt_and_samples(rsn):
    stream, info = at2.read(NGA / f"RSN{rsn}_2.AT2.gz")
    assert len(stream) == 3
    for k, trace in zip((1, 2, 3), stream):
        lines = text_of(NGA / f"RSN{rsn}_{k}.AT2.gz").splitlines()
        assert "UNITS OF G" in lines[2]
        npts, dt = re.search(r"NPTS=\s*(\d+), DT=\s*([\d.]+) SEC", lines[3]).groups()
        assert trace.stats.npts == int(npts)
        assert trace.stats.delta == pytest.approx(float(dt), rel=1e-12)
        first, last = lines[4].split()[0], lines[-1].split()[-1]
        assert trace.data[0] == pytest.approx(float(first) * G, rel=1e-12)
        assert trace.data[-1] == pytest.approx(float(last) * G, rel=1e-12)
        component = lines[1].rsplit(",", 1)[1].strip()
        if component.isdigit():
            assert (trace.stats.azimuth, trace.stats.dip) == (float(component) % 360, 0.0)
        elif component in ("UP", "V"):
            assert trace.stats.dip == -90.0
        elif component == "DWN":
            assert trace.stats.dip == 90.0
    row = flatfile()[rsn]
    assert info["station_lat"] == float(row["station_lat"])
    assert info["event_lon"] == float(row["hypo_lon"])
    assert info["lowest_usable_hz"] == float(row["lowest_usable_hz"])
    corners = [float(row[c]) for c in ("lp_h1_hz", "lp_h2_hz") if row[c]]
    assert info.get("highest_usable_hz") == (min(corners) if corners else None)


def test_at2_flatfile_values_of_the_papers_records():
    stream, info = at2.read(NGA / "RSN126_1.AT2.gz")  # GM1 Gazli, Karakyr
    assert (info["station"], info["event"], info["magnitude"]) == ("Karakyr", "Gazli, USSR", 6.8)
    assert (info["station_lat"], info["station_lon"]) == (40.35, 63.47)
    assert (info["event_lat"], info["event_lon"], info["event_depth_km"]) == (40.465, 63.462, 18.2)
    assert info["mechanism"] == "Reverse" and info["lowest_usable_hz"] == 0.25
    assert [tr.stats.azimuth for tr in stream[:2]] == [0.0, 90.0]
    _, info = at2.read(NGA / "RSN30_1.AT2.gz")  # HP 0.13/0.10, LP 17.4/20.0 Hz
    assert (info["lowest_usable_hz"], info["highest_usable_hz"]) == (0.1625, 17.4)


def test_at2_component_na_takes_the_flatfile_azimuth():
    stream, info = at2.read(NGA / "RSN230_1.AT2.gz")
    assert [tr.stats.azimuth for tr in stream if tr.stats.dip == 0] == [90.0, 180.0]
    assert "'NA'" in info["notes"] and info["horizontals_compass"] is True


@pytest.mark.parametrize("rsn", [134, 139, 144])
def test_at2_longitudinal_transverse_components_are_not_compass(rsn):
    stream, info = at2.read(NGA / f"RSN{rsn}_3.AT2.gz")
    assert info["horizontals_compass"] is False and "L/T" in info["notes"]
    assert [tr.stats.azimuth for tr in stream if tr.stats.dip == 0] == [0.0, 90.0]


def test_at2_rsn171_duplicate_is_refused():
    message = one_line_error(at2.read, NGA / "RSN171_1.AT2.gz")
    assert "RSN171_2" in message and "duplicated component" in message


def _at2(path, component, npts="10", dt=".0100", values=None, station="Test Site",
         units="ACCELERATION TIME SERIES IN UNITS OF G",
         first="PEER NGA STRONG MOTION DATABASE RECORD"):
    values = np.arange(1, 11) * 1e-3 if values is None else values
    body = "\n".join("  ".join(f"{v: .7E}" for v in values[i:i + 5])
                     for i in range(0, len(values), 5))
    path.write_text(f"{first}\nTest Event, 1/2/2003, {station}, {component}\n{units}\n"
                    f"NPTS= {npts:>6}, DT= {dt:>8} SEC,\n{body}\n")
    return path


@pytest.fixture
def triplet(tmp_path):
    rng = np.random.default_rng(3)
    for k, comp in ((1, "0"), (2, "90"), (3, "UP")):
        _at2(tmp_path / f"RSN9001_{k}.AT2", comp, values=rng.normal(0, 0.1, 10))
    return tmp_path


def test_at2_synthetic_triplet_round_trip(triplet):
    path = triplet / "RSN9001_1.AT2"
    assert at2.detect(path, path.read_bytes()[:4096])
    assert not at2.detect(triplet / "Kocaeli.AT2", path.read_bytes()[:4096])
    stream, info = at2.read(path)
    assert [(tr.stats.azimuth, tr.stats.dip) for tr in stream] == [(0, 0), (90, 0), (0, -90)]
    expected = np.array(io_lines(path)) * G
    np.testing.assert_allclose(stream[0].data, expected, rtol=1e-12)
    assert info["station"] == "Test Site" and "no NGA-West2 flatfile row" in info["notes"]


def io_lines(path):
    return [float(v) for line in path.read_text().splitlines()[4:] for v in line.split()]


def test_at2_malformed_files_raise_one_line_errors(triplet):
    first = triplet / "RSN9001_1.AT2"
    good = first.read_text()
    for dt in ("0", "-.0100", "."):
        _at2(first, "0", dt=dt)
        assert "DT" in one_line_error(at2.read, first)
    _at2(first, "0", npts="9")
    assert "10 samples, header NPTS=9" in one_line_error(at2.read, first)
    _at2(first, "0", first="XEER NGA STRONG MOTION DATABASE RECORD")
    assert "not a PEER AT2" in one_line_error(at2.read, first)
    _at2(first, "0", units="ACCELERATION TIME SERIES IN UNITS OF CM/S/S")
    assert "units" in one_line_error(at2.read, first)
    first.write_text(good.replace("NPTS=", "N=", 1))
    assert "NPTS" in one_line_error(at2.read, first)
    _at2(first, "0", station="Another Site")
    assert "recording" in one_line_error(at2.read, first)
    first.write_text(good)
    assert "key" in one_line_error(at2.read, first, key="RSN1")

    second = triplet / "RSN9001_2.AT2"
    second_text = second.read_text()
    second.write_text(good)  # same samples as _1
    assert "duplicated component" in one_line_error(at2.read, first)
    _at2(second, "180")  # other samples, same axis as _1
    assert "duplicated component" in one_line_error(at2.read, first)
    second.write_text(second_text)
    second.unlink()
    assert "missing component" in one_line_error(at2.read, first)


# ---------------------------------------------------------------- detection and registry
SAMPLES = {
    "geonet": KAIKOURA,
    "dmg-v2": [COALINGA],
    "at2-triplet": [NGA / "RSN126_1.AT2.gz", NGA / "RSN30_3.AT2.gz"],
    "mseed-stationxml": [RIDGECREST / "CI.CCC..HNE.mseed"],
}


def _head(path):
    return text_of(path).encode("latin-1")[:4096] if not path.name.endswith(".mseed") \
        else path.read_bytes()[:4096]


@pytest.mark.parametrize("fmt", sorted(SAMPLES))
def test_each_reader_detects_its_own_files_only(fmt):
    modules = {m.FORMAT: m for m in (geonet, dmg_v2, mseed, at2)}
    for path in SAMPLES[fmt]:
        head = _head(path)
        assert [f for f, m in modules.items() if m.detect(path, head)] == [fmt]


def test_registry_routes_the_shipped_files_to_these_readers():
    for fmt, paths in SAMPLES.items():
        for path in paths:
            head = _head(path)
            chosen = next(m for m in readers.formats() if m.detect(path, head))
            assert chosen.FORMAT == fmt, path.name


def test_nearsource_catalogue_rows_name_readable_files():
    with open(RECORDS / "nearsource_catalog.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 51 and len({r["id"] for r in rows}) == 51
    for row in rows:
        matches = sorted(RECORDS.glob(row["source_file"]))
        assert matches, row["source_file"]
        assert (row["usable"] == "False") == (row["id"] == "RSN171-IMPVALL")
    gm = {r["paper_gm"]: r["id"] for r in rows if r["paper_gm"]}
    assert gm == {"GM1": "RSN126-GAZLI", "GM2": "RSN132-FRIULI", "GM5": "RSN139-TABAS"}
