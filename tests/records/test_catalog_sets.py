"""The merged catalogue ``records/catalog.csv`` and the record sets of
``pipeline.records.sets`` (rules, lazy cached PGA, command-line plumbing)."""
import csv
import importlib.util
import json
import math

import pandas as pd
import pytest
from obspy.geodetics import gps2dist_azimuth

from pipeline import RECORDS_DIR, cli, paper
from pipeline.files import InputError
from pipeline.records import catalog, catalog_row, sets
from pipeline.records.readers import read_record

ISSUE_COLUMNS = ["id", "event", "date", "magnitude", "mechanism", "station", "station_latitude",
                 "station_longitude", "event_latitude", "event_longitude",
                 "epicentral_distance_km", "back_azimuth_deg", "has_vertical",
                 "horizontals_compass", "source", "licence"]
CODE_COLUMNS = ["source_file", "source_key", "azimuths_deg", "orientation", "start_utc",
                "end_utc", "pulse_like", "replaces_gm23", "notes", "citation", "usable", "format",
                "lowest_usable_hz", "highest_usable_hz", "paper_gm"]
NOT_COMPASS = {"RSN134-IZMIR", "RSN139-TABAS", "RSN144-DURSUN"}


def _rows():
    with open(RECORDS_DIR / "catalog.csv", newline="") as handle:
        return list(csv.DictReader(handle))


# ---------------------------------------------------------------- catalogue
def test_one_catalogue_with_the_issue_columns():
    rows = _rows()
    header = list(rows[0])
    assert set(ISSUE_COLUMNS + CODE_COLUMNS) <= set(header)
    assert not {"station_lat", "station_lon", "event_lat", "event_lon", "year"} & set(header)
    ids = [r["id"] for r in rows]
    assert len(ids) == 105 and len(set(ids)) == 105
    with open(RECORDS_DIR / "nearsource_catalog.csv", newline="") as handle:
        nearsource = {r["id"] for r in csv.DictReader(handle)}
    assert nearsource <= set(ids)                       # every near-source record merged
    assert sum(r["source_file"] == "fema_p695.npz" for r in rows) == 50


def test_unusable_rows_stay_with_their_reason():
    row = catalog_row("RSN171-IMPVALL")
    assert row["usable"] is False and "duplicated component" in row["notes"]
    assert [r["id"] for r in _rows() if r["usable"] != "True"] == ["RSN171-IMPVALL"]
    assert "RSN171-IMPVALL" not in sets.record_ids("all")


def test_catalog_row_has_full_names_and_short_aliases():
    row = catalog_row("rsn126-gazli")
    assert row["station_latitude"] == row["station_lat"] == pytest.approx(40.35)
    assert row["event_longitude"] == row["event_lon"] == pytest.approx(63.462)
    assert row["paper_gm"] == "GM1" and row["source_key"] == "RSN126"
    assert row["has_vertical"] is True and row["horizontals_compass"] is True
    fema = catalog_row("GM20")
    assert fema["station_lat"] is None and fema["back_azimuth_deg"] is None
    frame = catalog()
    assert (frame["station_lat"].fillna(-999) == frame["station_latitude"].fillna(-999)).all()


def test_distances_and_back_azimuths_come_from_the_coordinates():
    located = 0
    for row in _rows():
        coords = [row[k] for k in ("event_latitude", "event_longitude", "station_latitude",
                                   "station_longitude")]
        if "" in coords:
            assert row["back_azimuth_deg"] == "", row["id"]          # never invented
            continue
        located += 1
        dist_m, _, baz = gps2dist_azimuth(*(float(c) for c in coords))
        assert float(row["epicentral_distance_km"]) == pytest.approx(dist_m / 1000, abs=0.006)
        diff = (float(row["back_azimuth_deg"]) - baz + 180) % 360 - 180
        assert abs(diff) <= 0.051, row["id"]
    assert located == 55


def test_fema_rows_have_no_back_azimuth_and_no_compass_claim_for_fn_fp():
    for row in _rows():
        if row["source_file"] == "fema_p695.npz":
            assert row["back_azimuth_deg"] == "" and row["has_vertical"] == "False"
            if row["id"].startswith("NF") or row["source_key"].startswith("NF"):
                assert row["orientation"] == "fn-fp" and row["horizontals_compass"] == "False"


def test_every_row_names_a_file_its_format_reads():
    for row in _rows():
        if row["usable"] != "True":
            continue
        stream, info = read_record(RECORDS_DIR / row["source_file"], row["source_key"] or None)
        assert info["format"] == row["format"], row["id"]
        assert any(tr.stats.dip != 0 for tr in stream) == (row["has_vertical"] == "True")


def test_make_catalog_reproduces_the_shipped_catalogue(tmp_path):
    spec = importlib.util.spec_from_file_location(
        "make_catalog", RECORDS_DIR / "tools" / "make_catalog.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    tool.write(tool.build_rows(), tmp_path / "catalog.csv")
    assert (tmp_path / "catalog.csv").read_bytes() == (RECORDS_DIR / "catalog.csv").read_bytes()


# ---------------------------------------------------------------- sets
def fake_pga(values=None, default=3.0):
    values = values or {}
    return lambda record_id: values.get(record_id, default)


def test_fema_and_all_sets():
    fema = sets.record_ids("fema")
    assert len(fema) == 50 and {"GM20", "NF04", "FF01"} <= set(fema)
    everything = sets.record_ids("all")
    assert len(everything) == 104 and everything == [r["id"] for r in _rows()
                                                     if r["usable"] == "True"]
    with pytest.raises(InputError):
        sets.record_ids("nope")


def test_nearsource_rule_without_processing():
    table = sets.selection(pga=fake_pga()).set_index("id")
    chosen = set(table.index[table["selected"]])
    assert not chosen & set(sets.record_ids("fema"))                 # no vertical
    assert not chosen & NOT_COMPASS and "RSN171-IMPVALL" not in chosen
    assert "RC19-CCC" not in chosen and "RC-CCC" in chosen           # one record per recording
    assert table.loc["RC19-CCC", "reason"].startswith("same station and event as RC-CCC")
    assert table.loc["RSN139-TABAS", "reason"].startswith("horizontals not compass")
    assert table.loc["GM1", "reason"] == "no vertical component"
    # 4 Ridgecrest V1/Napa + 50 usable near-source - 3 L/T - the second CI.CCC recording
    assert len(chosen) == 50
    for record_id in chosen:
        row = catalog_row(record_id)
        assert row["epicentral_distance_km"] < paper.SELECTION_MAX_DISTANCE_KM
        assert row["back_azimuth_deg"] is not None and row["has_vertical"]


def test_nearsource_thresholds_come_from_paper(monkeypatch):
    at_threshold = fake_pga({"RSN126-GAZLI": paper.SELECTION_MIN_PGA_M_S2,
                             "RSN132-FRIULI": paper.SELECTION_MIN_PGA_M_S2 + 1e-6})
    chosen = sets.record_ids("nearsource", pga=at_threshold)
    assert "RSN126-GAZLI" not in chosen and "RSN132-FRIULI" in chosen    # PGA strictly above
    assert "RSN68-SFERN" in chosen                                        # 39.37 km < 40 km
    monkeypatch.setattr(paper, "SELECTION_MAX_DISTANCE_KM", 39.0)
    assert "RSN68-SFERN" not in sets.record_ids("nearsource", pga=fake_pga())


def test_pga_is_computed_lazily_only_for_candidates():
    asked = []
    sets.selection(pga=lambda record_id: asked.append(record_id) or 3.0)
    assert len(asked) == 51 and not set(asked) & (set(sets.record_ids("fema")) | NOT_COMPASS)


def test_horizontal_pga_is_cached_by_content(tmp_path, monkeypatch):
    from pipeline import records
    value = sets.horizontal_pga("RC-CLC", cache_dir=tmp_path)
    key = records.resolve("RC-CLC").key()
    cached = json.loads((tmp_path / f"{key}{sets.PGA_SUFFIX}").read_text())
    assert cached["input_hash"] == key and cached["pga_h"] == value
    assert (tmp_path / f"{key}.npz").is_file()                    # the motion cache itself
    assert 4.0 < value < 6.0                                      # m/s^2, peak 0.5 g

    def no_processing(*args, **kwargs):
        raise AssertionError("processed again")
    monkeypatch.setattr(records, "processed_motion", no_processing)
    assert sets.horizontal_pga("RC-CLC", cache_dir=tmp_path) == value


def test_nearsource_set_of_the_shipped_catalogue(tmp_path):
    """The processed set (45): the paper's GM1 and GM2 in it; GM5 (Tabas, L/T horizontals)
    not; five Ridgecrest MiniSEED stations below 2 m/s^2."""
    table = sets.selection(cache_dir=tmp_path).set_index("id")
    chosen = list(table.index[table["selected"]])
    assert len(chosen) == 45
    assert {"RSN126-GAZLI", "RSN132-FRIULI"} <= set(chosen) and "RSN139-TABAS" not in chosen
    low = set(table.index[table["reason"].str.startswith("horizontal PGA")])
    assert low == {"RC19-JRC2", "RC19-MPM", "RC19-SLA", "RC19-WRV2", "RC19-WVP2"}
    assert (table.loc[chosen, "pga_h"] > paper.SELECTION_MIN_PGA_M_S2).all()
    assert sets.record_ids("nearsource", cache_dir=tmp_path) == chosen


# ---------------------------------------------------------------- command line
def test_campaign_set_option_passes_the_set(monkeypatch):
    from pipeline import campaign
    seen = {}
    monkeypatch.setattr(campaign, "run_campaign",
                        lambda name, records=None, **kw: seen.update(name=name, records=records))
    monkeypatch.setattr(sets, "record_ids", lambda name, **kw: [f"{name}-1", f"{name}-2"])
    assert cli.main(["campaign", "records", "--set", "fema"]) == 0
    assert seen == {"name": "records", "records": ["fema-1", "fema-2"]}
    assert cli.main(["campaign", "records"]) == 0 and seen["records"] is None
    assert cli.main(["campaign", "records", "--set", "all", "--records", "GM20"]) == 2


def test_records_campaign_defaults_to_nearsource(monkeypatch):
    from pipeline import campaign
    from pipeline.campaign import definitions
    monkeypatch.setattr(sets, "record_ids", lambda name, **kw: [name])
    monkeypatch.setattr(definitions, "column_specs", lambda runs, d: [r for r, _ in runs])
    assert campaign.get("records").specs(None, "unused") == ["nearsource"]
    assert campaign.get("records").specs(["GM20"], "unused") == ["GM20"]


def test_records_command_set_option(tmp_path, monkeypatch):
    monkeypatch.setattr(sets, "record_ids", lambda name, **kw: ["RC-CLC"] if name == "fema"
                        else ["RC-CLC", "NAPA-68150"])
    out = tmp_path / "out"
    assert cli.main(["records", "--set", "fema", "--no-figures", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.glob("*.npz")) == ["RC-CLC.npz"]
    assert cli.main(["records", "--all", "--set", "fema", "--no-figures", "--out",
                     str(out)]) == 0
    assert sorted(p.name for p in out.glob("*.npz")) == ["NAPA-68150.npz", "RC-CLC.npz"]
    table = pd.read_csv(out / "records.csv")
    assert sorted(table["id"]) == ["NAPA-68150", "RC-CLC"]
    assert table["pga_h"].map(math.isfinite).all()
