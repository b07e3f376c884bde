"""Observation files: the schema, geographic positions, and one-line errors."""
import json
import math

import pytest

from pipeline import cli
from pipeline.files import InputError
from pipeline.inversion import EXAMPLES_DIR
from pipeline.inversion.observations import load_observations, parse_observations

GOOD_SITE = {"name": "A", "east_km": 0, "north_km": 0,
             "columns": [{"column": "drums", "state": "fallen", "downfall_azimuth_deg": 240,
                          "uncertainty_deg": 10}, {"column": "monolithic", "state": "standing"}]}


def test_examples_parse():
    obs = load_observations(EXAMPLES_DIR / "two_sites.json")
    assert [s.name for s in obs.sites] == ["A", "B"]
    assert obs.n_fallen == 3 and obs.n_columns == 5
    geo = load_observations(EXAMPLES_DIR / "geographic.json")
    assert (geo.sites[0].east_km, geo.sites[0].north_km) == (0.0, 0.0)


def test_positions_are_relative_to_the_first_site():
    obs = parse_observations({"sites": [dict(GOOD_SITE, east_km=3, north_km=4),
                                        dict(GOOD_SITE, name="B", east_km=5, north_km=1)]})
    assert (obs.sites[1].east_km, obs.sites[1].north_km) == (2.0, -3.0)
    assert obs.sites[0].columns[1].downfall_azimuth_deg is None


def test_latitude_longitude_on_the_local_tangent_plane():
    a = {"name": "A", "latitude": 38.0, "longitude": 23.0, "columns": GOOD_SITE["columns"]}
    b = dict(a, name="B", latitude=38.1)                 # 0.1 deg north: 11.1 km
    c = dict(a, name="C", longitude=23.1)                # 0.1 deg east at 38 N: 8.8 km
    obs = parse_observations({"sites": [a, b, c]})
    assert obs.sites[1].north_km == pytest.approx(11.10, abs=0.02)
    assert obs.sites[1].east_km == pytest.approx(0.0, abs=1e-6)
    assert obs.sites[2].east_km == pytest.approx(111.0 * 0.1 * math.cos(math.radians(38)),
                                                 rel=0.01)


def test_column_file_names_pass_through():
    obs = parse_observations({"sites": [dict(GOOD_SITE, columns=[
        {"column": "columns/ionic.json", "state": "standing"}])]})
    assert obs.column_types() == ["columns/ionic.json"]


def test_a_standing_column_says_its_damage_states():
    # residual slide over D against the limits 0.005, 0.025, 0.1 (docs/damage.md): at
    # least that state, and up to severe (the peak measures leave no trace)
    cases = [({}, ("none", "severe")),
             ({"damage_state": "slight"}, ("slight", "slight")),
             ({"residual_slide_m": 0.004, "base_width_m": 1.0}, ("none", "severe")),
             ({"residual_slide_m": 0.01, "base_width_m": 1.0}, ("slight", "severe")),
             ({"residual_slide_m": 0.06, "base_width_m": 2.0}, ("moderate", "severe")),
             ({"residual_slide_m": 0.25, "base_width_m": 2.0}, ("severe", "severe"))]
    columns = [{"column": "drums", "state": "standing", **extra} for extra, _ in cases]
    obs = parse_observations({"sites": [dict(GOOD_SITE, columns=GOOD_SITE["columns"]
                                             + columns)]})
    ranges = [tuple(s.label for s in c.state_range) for c in obs.sites[0].columns]
    assert ranges == [("collapse", "collapse"), ("none", "severe")] + [r for _, r in cases]
    again = parse_observations(obs.as_dict())           # the file's schema, read back
    assert again.sites[0].columns == obs.sites[0].columns
    assert obs.turned(90.0).sites[0].columns[2:] == obs.sites[0].columns[2:]


BAD = [
    ("[1, 2", "not valid JSON"),
    ({"site": []}, "expected an object with a 'sites' list"),
    ({"sites": []}, "'sites' must be a non-empty list"),
    ({"sites": [{"name": "A", "columns": GOOD_SITE["columns"]}]}, "give either east_km"),
    ({"sites": [dict(GOOD_SITE, latitude=1.0, longitude=2.0)]}, "give either east_km"),
    ({"sites": [GOOD_SITE, {"name": "B", "latitude": 1, "longitude": 2,
                            "columns": GOOD_SITE["columns"]}]}, "mixes east_km"),
    ({"sites": [dict(GOOD_SITE, east_km="3")]}, "east_km must be a finite number"),
    ({"sites": [dict(GOOD_SITE, columns=[])]}, "'columns' must be a non-empty list"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "fallen"}])]},
     "needs downfall_azimuth_deg"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "fallen",
                                          "downfall_azimuth_deg": 400}])]},
     r"400 outside the allowed range \[0, 360\]"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "toppled"}])]},
     "'state' must be 'fallen' or 'standing'"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "downfall_azimuth_deg": 10}])]},
     "a standing column has no downfall_azimuth_deg"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "fallen",
                                          "downfall_azimuth_deg": 10,
                                          "uncertainty_deg": -1}])]}, "uncertainty_deg"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "azimuth": 3}])]}, "unknown key"),
    ({"sites": [GOOD_SITE, GOOD_SITE]}, "two sites have this name"),
    ({"sites": [GOOD_SITE, dict(GOOD_SITE, name="B")]}, "at the same place"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "ionic.json", "state": "standing"}])]},
     "column 'ionic.json': no such file or shipped example"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "damage_state": "collapse"}])]},
     "a column in collapse fell: state 'fallen'"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "damage_state": "cracked"}])]},
     "'damage_state' must be one of none, slight, moderate, severe"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "fallen",
                                          "downfall_azimuth_deg": 10,
                                          "damage_state": "severe"}])]},
     "a fallen column is in collapse; damage_state describes a standing one"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "residual_slide_m": 0.02}])]},
     "residual_slide_m and base_width_m go together"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "residual_slide_m": -0.02, "base_width_m": 1}])]},
     "residual_slide_m -0.02 outside the allowed range"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "residual_slide_m": 0.02, "base_width_m": 0}])]},
     "base_width_m 0 outside the allowed range"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "drums", "state": "standing",
                                          "residual_slide_m": 0.02, "base_width_m": 1,
                                          "damage_state": "slight"}])]},
     "give damage_state or residual_slide_m with base_width_m, not both"),
    ({"sites": [dict(GOOD_SITE, columns=[{"column": "corinthian", "state": "standing"}])]},
     "column 'corinthian': no such file or shipped example"),
]


@pytest.mark.parametrize("content, message", BAD)
def test_bad_files_give_one_line_errors(tmp_path, capsys, content, message):
    path = tmp_path / "obs.json"
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    out = tmp_path / "out"
    code = cli.main(["invert", str(path), "--out", str(out), "--table",
                     str(tmp_path / "never-read.npz")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("error: ")
    assert __import__("re").search(message, err), err
    assert not out.exists()


def test_missing_file_and_option_errors(tmp_path, capsys):
    assert cli.main(["invert", str(tmp_path / "none.json")]) == 2
    assert "observations file not found" in capsys.readouterr().err
    good = tmp_path / "good.json"
    good.write_text(json.dumps({"sites": [GOOD_SITE]}))
    for argv, message in (([], "give one of an OBSERVATIONS.json file, --demo"),
                          (["--radius", "-3"], "--radius -3 outside the allowed range (0, 100] km"),
                          (["--quick", "--grid", "full"], "--quick is --grid quick"),
                          (["--azimuth-step", "7"], "--azimuth-step must divide 360"),
                          (["--mechanisms", "oblique"], "unknown mechanism"),
                          (["--depths", "5,x"], "--depths: not a comma-separated list"),
                          (["--jobs", "0"], "--jobs must be at least 1")):
        args = ["invert"] + ([str(good)] if argv else []) + argv
        assert cli.main(args) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and message in err, (argv, err)
    with pytest.raises(InputError):
        parse_observations({"sites": [dict(GOOD_SITE, name="")]})


def test_sites_in_km_far_apart_are_refused_like_sites_in_degrees(tmp_path):
    """1,000 km between two sites given in km: refused by the same rule as latitudes and
    longitudes over 300 km apart (it used to be accepted and tried to allocate GiB)."""
    from pipeline.inversion.observations import MAX_REGION_KM, parse_observations
    column = {"column": "drums", "state": "standing"}
    data = {"sites": [{"name": "A", "east_km": 0.0, "north_km": 0.0, "columns": [column]},
                      {"name": "B", "east_km": 1000.0, "north_km": 0.0, "columns": [column]}]}
    with pytest.raises(InputError, match=f"more than {MAX_REGION_KM:g} km"):
        parse_observations(data, "far.json")
