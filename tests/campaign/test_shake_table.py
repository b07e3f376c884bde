"""The shake-table campaign's pieces: scores against a confusion table counted by hand,
the experiment table's loader, the grid, and the shipped SP1 data against what its
sources state about it (mass, critical angle, PGA)."""
import json
import math

import numpy as np
import pytest

from pipeline.campaign.shake_table_experiments import (EXPERIMENTS, SPECIMEN, load_experiments,
                                                       grid_contact, parse_grid)
from pipeline.files import InputError
from pipeline.records import build_motion, resolve
from pipeline.scenario import ColumnGeometry
from pipeline.stats.classification import binned_rates, scores


def test_scores_of_a_confusion_table_counted_by_hand():
    observed = [1, 1, 1, 1, 0, 0, 0, 0, 0, 0]
    predicted = [1, 1, 1, 0, 1, 0, 0, 0, 0, 0]      # tp 3, fn 1, fp 1, tn 5
    s = scores(observed, predicted)
    assert s["accuracy"] == pytest.approx(0.8)
    assert s["precision"] == pytest.approx(0.75)
    assert s["recall"] == pytest.approx(0.75)
    assert s["f1"] == pytest.approx(0.75)
    assert s["confusion"] == {"overturned_predicted_overturned": 3,
                              "overturned_predicted_standing": 1,
                              "standing_predicted_overturned": 1,
                              "standing_predicted_standing": 5}
    assert s["accuracy_95"][0] < 0.8 < s["accuracy_95"][1]
    never = scores(observed, [0] * 10)
    assert never["precision"] is None and never["recall"] == 0.0 and never["f1"] is None


def test_binned_rates_count_each_test_once():
    rate, count = binned_rates([0.05, 0.15, 0.15, 0.15], [0.01, 0.01, 0.01, 0.2],
                               [1, 0, 1, np.nan], [0, 0.1, 0.2], [0, 0.1, 1.0])
    assert count.tolist() == [[1, 0], [2, 0]]
    assert rate[0, 0] == 1.0 and rate[1, 0] == 0.5 and math.isnan(rate[0, 1])


def test_grid_is_the_cartesian_product_and_checks_its_ranges():
    points = parse_grid("damping=0.1,0.36;footprint_tolerance_m=0.003")
    assert points == [{"damping": 0.1, "footprint_tolerance_m": 0.003},
                      {"damping": 0.36, "footprint_tolerance_m": 0.003}]
    assert parse_grid("") == [{}]
    for bad, words in (("damping=2", r"\[0, 1\]"), ("colour=1", "unknown"),
                       ("damping=a", "numbers"), ("damping=0.1;damping=0.2", "twice")):
        with pytest.raises(InputError, match=words):
            parse_grid(bad)


def test_grid_friction_alone_takes_the_kinetic_friction_a_run_takes():
    """A point giving mu_s alone runs with the mu_k that Contact gives that mu_s (the
    paper's ratio 0.6 / 0.7), not the paper's 0.6, which exceeds a low mu_s."""
    low, paper_value = parse_grid("mu_s=0.3,0.7")
    assert grid_contact(low)["mu_k"] == pytest.approx(0.6 / 0.7 * 0.3, abs=5e-5)
    assert grid_contact(paper_value)["mu_k"] == pytest.approx(0.6)
    assert grid_contact({"mu_s": 0.5, "mu_k": 0.5})["mu_k"] == 0.5


def test_experiment_table_errors_are_one_line(tmp_path):
    good = "test,date,pga_g,pgv_pga_s,sp1_overturned,motion_file\nT1,2021-06-01,0.1,0.05,1,\n"
    path = tmp_path / "e.csv"
    path.write_text(good)
    assert load_experiments(path)["observed"].tolist() == [True]
    for text, words in ((good.replace(",sp1_overturned", ",x"), "missing column"),
                        (good.replace("2021-06-01", "June"), "bad date"),
                        (good.replace(",1,\n", ",2,\n"), "0 or 1"),
                        (good + "T1,2021-06-02,0.1,0.05,0,\n", "twice"),
                        (good.replace(",1,\n", ",1,nowhere.txt\n"), "not found"),
                        (good.replace("0.1,0.05", "-1,0.05"), ">= 0"),
                        (good.replace("\nT1,", "\n,"), "test name '' must be"),
                        (good.replace("\nT1,", "\n  ,"), "not blank")):
        path.write_text(text)
        with pytest.raises(InputError, match=words) as info:
            load_experiments(path)
        assert "\n" not in str(info.value)


def test_tables_with_a_byte_order_mark_are_read(tmp_path):
    """A spreadsheet's UTF-8 export starts with a byte-order mark: the experiment table
    and the providers' table are read as without it."""
    from pipeline.campaign.shake_table_scores import load_providers
    path = tmp_path / "e.csv"
    path.write_bytes(b"\xef\xbb\xbftest,date,pga_g,pgv_pga_s,sp1_overturned,motion_file\n"
                     b"T1,2021-06-01,0.1,0.05,1,\n")
    assert load_experiments(path)["test"].tolist() == ["T1"]
    path.write_bytes(b"\xef\xbb\xbftest,model_a\nT1,1\n")
    assert load_providers(path) == {"model_a": {"T1": 1}}


def test_shipped_experiments_are_sp1_only_and_complete():
    frame = load_experiments(EXPERIMENTS)
    assert len(frame) == 582                               # every test of the source
    assert sum(p is not None for p in frame["motion_path"]) == 490
    assert not any("sp2" in c.lower() for c in frame.columns)   # SP2 stays held out
    months = frame.groupby(frame["date"].str[:7])["observed"].agg(["size", "sum"])
    assert months.loc["2021-06"].tolist() == [124, 79]      # README's per-month counts
    assert months.loc["2021-08"].tolist() == [268, 57]
    nominal = frame[frame["pga_nominal"] == 1]
    assert len(nominal) == 42 and set(nominal["pga_g"]) == {0.7, 1.1, 1.5}


def test_sp1_specimen_has_the_mass_and_critical_angle_its_sources_state():
    rock = ColumnGeometry.load(SPECIMEN)
    assert rock.mass == pytest.approx(353.802)             # config/sp1.yaml
    assert rock.density == pytest.approx(2856, abs=5)      # 353.8 kg / 0.1239 m^3
    # the rock's weak-side critical angle along the table's axis: 14.7 deg (the
    # specimen's equivalent box; pivot distance 0.302 m)
    assert rock.critical_angle_along_deg(90.0) == pytest.approx(14.7, abs=0.1)
    lever = rock.com[2] / math.cos(math.radians(14.7))
    assert lever == pytest.approx(0.302, abs=0.005)
    assert rock.settled_by_deg < 1.0                        # the scan stands as scanned


@pytest.mark.parametrize("k", [0, 115, 230, 345, 459])
def test_shipped_motions_give_the_pga_their_summary_states(k):
    """The providers' PGA is the peak after a 3rd-order 0.1-25 Hz band-pass; ours after
    the toolkit's processing (0.1-25 Hz) agrees within 5 %."""
    frame = load_experiments(EXPERIMENTS)
    # the k-th test with a motion and a measured PGA (42 rows of 2021-07-06/08 carry
    # nominal values only)
    row = frame[np.array([p is not None for p in frame["motion_path"]])
                & (frame["pga_nominal"] == 0)].iloc[k]
    motion = build_motion(resolve(str(row["motion_path"])))
    pga_g = np.abs(motion.acc[:, :2]).max() / 9.80665
    assert pga_g == pytest.approx(row["pga_g"], rel=0.05)


def test_summary_and_report_state_the_scores_of_the_table(tmp_path):
    """summarise() scores each split from the experiment table; the report prints them."""
    import json
    from datetime import date

    import pandas as pd

    from pipeline.campaign.shake_table import summarise
    from pipeline.report import shake_table_section
    box = ColumnGeometry.from_dict({"name": "box", "density": 2700.0, "blocks": [
        {"shape": "box", "height": 1.0, "width": 0.25, "depth": 0.5}]})
    table = pd.DataFrame({
        "test": [f"T{k}" for k in range(6)],
        "day": [date(2021, 6, 1)] * 3 + [date(2021, 8, 2)] * 3,
        "split": ["calibration"] * 3 + ["validation"] * 3,
        "pga_g": [0.1, 0.3, 0.5, 0.1, 0.3, 0.5],
        "observed": [False, True, True, False, False, True],
        "predicted": [False, True, False, True, False, True]})
    result = summarise(table, box, {"scores": {}}, "defaults", {},
                       {"validate_from": "2021-08-01", "grid": "", "axis_deg": 90.0})
    assert result["pga_threshold_g"] == pytest.approx(0.25)        # tan alpha = b / h
    assert result["splits"]["calibration"]["model"]["accuracy"] == pytest.approx(2 / 3)
    assert result["splits"]["validation"]["model"]["precision"] == pytest.approx(0.5)
    assert result["splits"]["all"]["pga_threshold"]["accuracy"] == pytest.approx(5 / 6)
    (tmp_path / "shake-table").mkdir()
    (tmp_path / "shake-table" / "shake_table.json").write_text(json.dumps(result))
    text = shake_table_section(tmp_path)
    row = [c.strip() for c in next(line for line in text.splitlines()
                                    if "| validation" in line and "YADE" in line).split("|")]
    assert row[1:8] == ["validation", "YADE model", "3", "0.667", "0.500", "1.000", "0.667"]
    assert "Not run yet" in shake_table_section(tmp_path / "nothing")


@pytest.mark.yade
def test_run_a_lab_table_on_the_sp1_specimen(tmp_path, capsys):
    """The user's path: a lab table and the shipped mesh specimen through `run`. A gentle
    2 Hz shaking at half SP1's weakest uplift threshold leaves it standing; two cycles
    at 0.5 g along East-West, between the thresholds toward its weak side (East, tan
    14.7 deg = 0.26 g) and its strong side (West, tan 38 deg = 0.78 g), overturn it
    toward East."""
    from pipeline import cli
    rock = ColumnGeometry.load(SPECIMEN)
    t = np.arange(0.0, 6.0, 0.005)
    on = (t > 1.0) & (t < 3.0)
    for name, accel_g, standing in (
            ("gentle", 0.5 * rock.uplift_ratio() * np.sin(2 * np.pi * 2.0 * t), True),
            ("cycles", np.where(on, 0.5 * np.sin(2 * np.pi * (t - 1.0)), 0.0), False)):
        table = tmp_path / f"{name}.txt"
        table.write_text("# lab-table: test\n# units: g\n# axes: 90\n" + "\n".join(
            f"{a:.4f} {b:.6f}" for a, b in zip(t, accel_g)) + "\n")
        code = cli.main(["run", "--record", str(table), "--column", "monolithic",
                         "--column-file", str(SPECIMEN), "--out", str(tmp_path / name)])
        assert code == 0
        out = capsys.readouterr().out
        assert "specimen 'SP1' from SP1.obj: 353.8 kg" in out
        summary = json.loads((tmp_path / name / "summary.json").read_text())
        (column,) = summary["columns"]
        assert column["toppled"] is (not standing)
        if not standing:                 # toward its weak side
            assert column["toppled_by"] == "rests past its critical angle"
            assert abs((column["downfall_azimuth_deg"] - 90.0 + 180.0) % 360.0 - 180.0) < 45.0


@pytest.mark.yade
def test_campaign_calibrates_on_early_tests_and_validates_the_chosen_set_only(tmp_path):
    """Two parameter sets on two June tests, the chosen one alone on two August tests;
    the outputs say so and score what ran."""
    import pandas as pd

    from pipeline import cli
    tests = "Test011,Test048,Test412,Test595"
    code = cli.main(["campaign", "shake-table", "--tests", tests, "--grid",
                     "footprint_tolerance_m=0.001;damping=0.05,0.1", "--out",
                     str(tmp_path / "st"), "--jobs", "2"])
    assert code == 0
    calibration = pd.read_csv(tmp_path / "st" / "calibration.csv")
    validation = pd.read_csv(tmp_path / "st" / "validation.csv")
    assert sorted(set(calibration["test"])) == ["Test011", "Test048"]
    observed = dict(zip(calibration["test"], calibration["observed"]))
    assert observed == {"Test011": False, "Test048": True}          # tests.csv says so
    assert calibration["grid_point"].nunique() == 2
    assert sorted(validation["test"]) == sorted(["Test412", "Test595"])
    summary = json.loads((tmp_path / "st" / "shake_table.json").read_text())
    assert validation["grid_point"].unique().tolist() == [summary["chosen"]["label"]]
    assert summary["splits"]["validation"]["model"]["n"] == 2
    assert summary["splits"]["all"]["tests"] == 4
    assert (tmp_path / "st" / "shake_table_rates.png").stat().st_size > 10_000


@pytest.mark.yade
def test_sp1_starts_at_rest_at_any_contact_stiffness(tmp_path):
    """SP1 on its lowest asperities (footprint 1 mm) starts at rest on the table: no
    contact sphere starts inside the table, so no spring is loaded at the start, whatever
    its stiffness (a sphere 0.6 mm inside at kn 1.2e9 launched the rock at 0.5 m/s and
    overturned it).  Shaken gently (a fifth of its weakest uplift threshold: it cannot
    move as a rigid body) until a pulse past the threshold at 1.5 s, its bodies stay
    slower than 1 cm/s before the pulse, at kn x1 and x10."""
    from pipeline import cli
    rock = ColumnGeometry.load(SPECIMEN).to_dict()
    rock["footprint_tolerance_m"] = 0.001
    rock["mesh"] = str(SPECIMEN.parent / rock["mesh"])
    specimen = tmp_path / "sp1.json"
    specimen.write_text(json.dumps(rock))
    t = np.arange(0.0, 2.0, 0.005)
    uplift = ColumnGeometry.load(specimen).uplift_ratio()
    accel_g = np.where((t >= 1.5) & (t < 1.6), 1.2 * uplift,
                       0.2 * uplift * np.sin(2 * np.pi * 2.0 * t))
    table = tmp_path / "gentle.txt"
    table.write_text("# lab-table: test\n# units: g\n# axes: 90\n" + "\n".join(
        f"{a:.4f} {b:.6f}" for a, b in zip(t, accel_g)) + "\n")
    for kn in ("1.2e8", "1.2e9"):
        out = tmp_path / kn
        assert cli.main(["run", "--record", str(table), "--column", "monolithic",
                         "--column-file", str(specimen), "--kn", kn, "--damping", "0.05",
                         "--quiet-motion", "simulate", "--out", str(out)]) == 0
        trajectory = np.load(out / "trajectory.npz")
        quiet = trajectory["t"] < 1.45
        assert quiet.sum() > 20                     # the quiet lead was simulated
        speed = np.linalg.norm(trajectory["vel"][quiet, 0], axis=1)
        spin = np.linalg.norm(trajectory["angvel"][quiet, 0], axis=1)
        assert speed.max() < 0.01 and spin.max() < 0.05, (kn, speed.max(), spin.max())
