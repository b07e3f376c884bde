"""The hazard-curve loader on the engine's own output (values the files state about
themselves) and one-line errors for bad files."""
import json
import math

import numpy as np
import pandas as pd
import pytest

from pipeline import RECORDS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard import load_hazard

CASE_14 = RECORDS_DIR / "hazard" / "oq_classical_case_14_hazard_curve-rlz-000_PGA.csv"
CASE_1 = RECORDS_DIR / "hazard" / "oq_classical_case_1_hazard_curve-PGA.csv"
USGS = RECORDS_DIR / "hazard" / "usgs_nshm2014r1_curves_-118_34_vs760.json"


def _engine_table(path):
    """(header line, table) read with pandas, apart from the loader."""
    header = path.read_text().splitlines()[0]
    return header, pd.read_csv(path, skiprows=1)


def test_openquake_multi_site_file_as_it_states_itself():
    header, table = _engine_table(CASE_14)
    assert "investigation_time=50.0" in header and "imt='PGA'" in header
    levels_g = np.array([float(c.split("-", 1)[1]) for c in table.columns[3:]])
    for site in (0, 4):
        curve = load_hazard(CASE_14, site)
        assert curve.source["investigation_time_yr"] == 50.0
        assert curve.source["imt"] == "PGA" and curve.source["sites_in_file"] == len(table)
        assert (curve.source["lon"], curve.source["lat"]) == (table["lon"][site],
                                                              table["lat"][site])
        poe = table.iloc[site, 3:].to_numpy(float)
        positive = poe > 0
        np.testing.assert_allclose(curve.levels_m_s2, levels_g[positive] * 9.80665, rtol=1e-12)
        np.testing.assert_allclose(curve.rates_per_yr, -np.log(1 - poe[positive]) / 50.0,
                                   rtol=1e-12)
    # site 0 gives poe 0 at its last level: said, and kept as where the rate is 0
    curve = load_hazard(CASE_14, 0)
    assert curve.zero_rate_from_m_s2 == pytest.approx(levels_g[-1] * STANDARD_GRAVITY)
    assert any("rates are 0" in note for note in curve.notes)


def test_openquake_single_site_old_header():
    header, table = _engine_table(CASE_1)
    assert "investigation_time=1.0" in header and 'imt="PGA"' in header
    curve = load_hazard(CASE_1)
    assert curve.source["investigation_time_yr"] == 1.0
    np.testing.assert_allclose(curve.levels_m_s2 / STANDARD_GRAVITY, [0.1, 0.4, 0.6])
    np.testing.assert_allclose(curve.rates_per_yr, -np.log1p(-table.iloc[0, 3:].to_numpy(float)))
    assert curve.notes == () and curve.zero_rate_from_m_s2 is None


def test_usgs_web_service_curve_as_it_states_itself():
    response = json.loads(USGS.read_text())["response"]
    pga = next(c for c in response if c["metadata"]["imt"]["value"] == "PGA")
    assert pga["metadata"]["xlabel"] == "Ground Motion (g)"
    curve = load_hazard(USGS)
    np.testing.assert_allclose(curve.levels_m_s2, np.array(pga["metadata"]["xvals"]) * 9.80665,
                               rtol=1e-12)
    np.testing.assert_allclose(curve.rates_per_yr, pga["data"][0]["yvals"], rtol=1e-12)
    assert (curve.source["lat"], curve.source["lon"]) == (34, -118)
    assert curve.source["edition"] == "USGS NSHM 2014 Rev. 1" and curve.notes == ()


def _usgs_variant(tmp_path, change):
    data = json.loads(USGS.read_text())
    change(data)
    path = tmp_path / "usgs.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("change, message", [
    (lambda d: d["response"].pop(0), "no PGA curve"),
    (lambda d: d["response"][0]["metadata"].pop("imt"), "missing IMT"),
    (lambda d: d["response"][0]["metadata"].update(xlabel="Ground Motion (gal)"),
     "unknown unit"),
    (lambda d: d["response"][0]["data"][0]["yvals"].__setitem__(3, 0.9), "non-monotonic"),
    (lambda d: d["response"][0]["data"][0]["yvals"].__setitem__(19, -1e-6),
     "negative annual rate"),
    (lambda d: d.pop("response"), "no 'response' list"),
])
def test_bad_usgs_files_one_line(tmp_path, change, message):
    with pytest.raises(InputError, match=message) as caught:
        load_hazard(_usgs_variant(tmp_path, change))
    assert "\n" not in str(caught.value)


def test_several_sites_need_a_choice():
    with pytest.raises(InputError, match=r"10 sites: choose one with --site \(0 to 9\)"):
        load_hazard(CASE_14)
    with pytest.raises(InputError, match="--site must be 0 to 9"):
        load_hazard(CASE_14, 10)


def test_older_level_columns_and_unbounded_rates(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("# gsim_tree_path=('Sad1997',), investigation_time=50.0,imt=PGA\n"
                    "lon,lat,depth,PGA-0.01:float32,PGA-0.1:float32,PGA-0.3:float32\n"
                    "1.0,2.0,0.0,1.0,0.5,0.1\n")
    curve = load_hazard(path)
    np.testing.assert_allclose(curve.levels_m_s2, [0.1 * STANDARD_GRAVITY, 0.3 * STANDARD_GRAVITY])
    np.testing.assert_allclose(curve.rates_per_yr, [math.log(2) / 50, -math.log(0.9) / 50])
    assert "probability of exceedance 1" in curve.notes[0]


@pytest.mark.parametrize("unit, factor", [("g", STANDARD_GRAVITY), ("m_s2", 1.0),
                                          ("cm_s2", 0.01)])
def test_plain_table(tmp_path, unit, factor):
    path = tmp_path / "curve.csv"
    path.write_text(f"# a site\npga_{unit},annual_rate_per_yr\n0.1,1e-2\n# comment\n"
                    "0.2,3e-3\n0.4,1e-4\n\n")
    curve = load_hazard(path)
    np.testing.assert_allclose(curve.levels_m_s2, np.array([0.1, 0.2, 0.4]) * factor)
    np.testing.assert_allclose(curve.rates_per_yr, [1e-2, 3e-3, 1e-4])
    assert curve.source["format"] == "plain table"


OQ_HEAD = "#,,,\"kind='mean', investigation_time=50.0, imt='PGA'\"\nlon,lat,depth,poe-0.1,poe-0.2\n"


@pytest.mark.parametrize("text, message", [
    ("", "is empty"),
    ("# only a comment\n", "is empty"),
    ("pga_g,annual_rate_per_yr\n0.1,1e-3\n0.2,2e-3\n", "non-monotonic"),
    ("pga_g,annual_rate_per_yr\n0.1,1e-3\n0.2,-2e-4\n", "negative annual rate"),
    ("pga_g,annual_rate_per_yr\n-0.1,1e-3\n0.2,1e-4\n", "levels must be positive"),
    ("pga_g,annual_rate_per_yr\n0.2,1e-3\n0.1,1e-4\n", "levels not increasing"),
    ("level,annual_rate_per_yr\n0.1,1e-3\n0.2,1e-4\n", "missing IMT"),
    ("pga_furlong,annual_rate_per_yr\n0.1,1e-3\n0.2,1e-4\n", "unknown unit"),
    ("pga_g,rate\n0.1,1e-3\n0.2,1e-4\n", "annual_rate_per_yr"),
    ("pga_g,annual_rate_per_yr\n0.1,abc\n0.2,1e-4\n", "not a number"),
    ("pga_g,annual_rate_per_yr\n0.1,1e-3\n", "at least 2"),
    ("pga_g,annual_rate_per_yr\n0.1,1e-3\n0.2,0\n", "fewer than 2 levels"),
    ("sa(0.1)_g,annual_rate_per_yr\n0.1,1e-3\n0.2,1e-4\n", "IMT SA"),
    (OQ_HEAD + "0,0,0,0.1,0.2\n", "non-monotonic"),
    (OQ_HEAD + "0,0,0,0.1,-0.01\n", "negative probability of exceedance"),
    (OQ_HEAD + "0,0,0,1.2,0.1\n", "above 1"),
    (OQ_HEAD + "0,0,0,0.2\n", "4 values for 5 columns"),
    (OQ_HEAD, "no site rows"),
    ("# investigation_time=50.0\nlon,lat,poe-0.1,poe-0.2\n0,0,0.2,0.1\n", "missing IMT"),
    ("# imt='PGA'\nlon,lat,poe-0.1,poe-0.2\n0,0,0.2,0.1\n", "no investigation_time"),
    ("# investigation_time=50.0, imt='SA(0.1)'\nlon,lat,poe-0.1,poe-0.2\n0,0,0.2,0.1\n",
     "IMT SA"),
])
def test_bad_files_one_line(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=message.replace("(", r"\(")) as caught:
        load_hazard(path)
    assert "\n" not in str(caught.value) and str(path) in str(caught.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="hazard file not found"):
        load_hazard(tmp_path / "nowhere.csv")
