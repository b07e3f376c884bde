"""The records section of REPORT.md against a hand-made runs table and hand-computed numbers.

The table: six records R1-R6 with back azimuths (not catalogue ids: compass
horizontals assumed), a FEMA pair without back azimuth (GM20), a FEMA pair with
an injected back azimuth (NF04, must still never be compared) and a catalogue
record whose horizontals are not compass azimuths (RSN139-TABAS).

Drums fall in R1 (110 vs back azimuth 100: +10, toward), R2 (20 vs 200: 180,
away), R3 (90 vs 0: transverse), R4 (250 vs 300: -50, transverse), R6 (350 vs
10: -20, toward), GM20, NF04 and TABAS; R5 stands.  The monolith falls in R1
(280 vs 100: away) and R3 (0 vs 0: toward) only.
"""
import math

import numpy as np
import pandas as pd
import pytest

from pipeline import paper, report

Z95 = 1.959963984540054    # two-sided 95 % normal quantile


def wilson_by_hand(k, n, z=Z95):
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


# record, back azimuth, drums downfall (None: stands), monolith downfall
CASES = [("R1", 100.0, 110.0, 280.0), ("R2", 200.0, 20.0, None), ("R3", 0.0, 90.0, 0.0),
         ("R4", 300.0, 250.0, None), ("R5", 50.0, None, None), ("R6", 10.0, 350.0, None),
         ("GM20", math.nan, 45.0, None), ("NF04", 30.0, 30.0, None),
         ("RSN139-TABAS", 242.9, 240.0, None)]


def hand_runs():
    rows = []
    for k, (record, baz, drums, mono) in enumerate(CASES):
        for column, azimuth in (("drums", drums), ("monolithic", mono)):
            toppled = azimuth is not None
            rows.append({
                "campaign": "records", "run_id": f"run{k}", "record_id": record, "column": column,
                "toppled": toppled, "downfall_azimuth_deg": azimuth if toppled else math.nan,
                "back_azimuth_deg": baz, "epicentral_distance_km": 5.0 + k,
                "pga_h": 2.0 + 0.5 * k, "pgv_pga_h": 0.1 + 0.01 * k,
                # largest acceleration along the drums' fall, velocity at right angles to it
                "az_max_acc_deg": drums if drums is not None else 17.0 * k,
                "az_max_vel_deg": ((drums if drums is not None else 17.0 * k) + 90.0) % 360.0,
                "az_max_disp_deg": (37.0 * k * k) % 360.0})
    return pd.DataFrame(rows)


def test_wilson_interval_matches_the_hand_formula():
    for k, n in [(8, 9), (2, 9), (13, 29), (7, 29), (0, 5), (5, 5)]:
        low, high = report.wilson_interval(k, n)
        hand = wilson_by_hand(k, n)
        assert low == pytest.approx(hand[0], abs=1e-12) and high == pytest.approx(hand[1], abs=1e-12)
    # 13/29: p = 0.448; centre (0.4483 + 0.0662) / 1.1325 = 0.4543, half 0.1702
    low, high = report.wilson_interval(13, 29)
    assert (round(low, 4), round(high, 4)) == (0.2841, 0.6245)
    assert list(report.wilson_interval(0, 0)) == [0.0, 1.0]    # no trials: anything


def test_toppled_fractions_beside_the_paper():
    table = report.toppled_fractions(hand_runs()).set_index("column")
    assert (table.loc["drums", "toppled"], table.loc["drums", "records"]) == (8, 9)
    assert (table.loc["monolithic", "toppled"], table.loc["monolithic", "records"]) == (2, 9)
    assert table.loc["drums", "ci_low"] == pytest.approx(wilson_by_hand(8, 9)[0])
    assert table.loc["monolithic", "ci_high"] == pytest.approx(wilson_by_hand(2, 9)[1])
    assert (table.loc["drums", "paper_toppled"], table.loc["drums", "paper_records"]) == \
        paper.RECORDS_TOPPLED_DRUMS
    assert table.loc["monolithic", "paper_ci_low"] == pytest.approx(
        wilson_by_hand(*paper.RECORDS_TOPPLED_MONOLITH)[0])


def test_fema_and_non_compass_records_are_never_compared_with_a_back_azimuth():
    kept = report.with_back_azimuth(hand_runs())
    assert set(kept["record_id"]) == {"R1", "R2", "R3", "R4", "R5", "R6"}
    rows = report.per_record_table(hand_runs()).set_index("record")
    for record in ("GM20", "NF04", "RSN139-TABAS"):
        assert rows.loc[record, "drums class"] == "no back azimuth"
        assert rows.loc[record, "monolithic (deg)"] == "stands"


def test_toward_away_transverse_counts_and_circular_statistics():
    table = report.back_azimuth_table(hand_runs()).set_index("column")
    drums, mono = table.loc["drums"], table.loc["monolithic"]
    assert (drums["n_runs"], drums["n_toppled"]) == (6, 5)
    assert (drums["toward"], drums["away"], drums["transverse"]) == (2, 1, 2)
    assert (mono["n_toppled"], mono["toward"], mono["away"], mono["transverse"]) == (2, 1, 1, 0)
    assert drums["uniform_transverse"] == pytest.approx(2.5)
    diffs = np.radians([10.0, 180.0, 90.0, -50.0, -20.0])
    resultant = np.hypot(np.cos(diffs).mean(), np.sin(diffs).mean())
    assert drums["resultant_length"] == pytest.approx(resultant)
    mean = math.degrees(math.atan2(np.sin(diffs).mean(), np.cos(diffs).mean()))
    assert drums["mean_diff_deg"] == pytest.approx(mean)
    axial = np.hypot(np.cos(2 * diffs).mean(), np.sin(2 * diffs).mean())
    assert drums["axial_resultant_length"] == pytest.approx(axial)
    # Rayleigh p (Fisher 1993, eq. 4.17; z = n R^2): exp(-z) (1 + (2z - z^2) / 4n
    # - (24z - 132z^2 + 76z^3 - 9z^4) / 288n^2)
    n = 5
    z = n * resultant ** 2
    p = math.exp(-z) * (1 + (2 * z - z * z) / (4 * n)
                        - (24 * z - 132 * z ** 2 + 76 * z ** 3 - 9 * z ** 4) / (288 * n * n))
    assert drums["rayleigh_p"] == pytest.approx(p, rel=1e-9)


def test_correlations_with_back_azimuth_and_largest_motions():
    table = report.correlation_table(hand_runs())
    drums = table[table["column"] == "drums"].set_index("reference")
    assert set(drums.index) == {"back_azimuth", "max_acc", "max_vel", "max_disp"}
    assert (drums["n"] == 5).all()
    assert drums.loc["max_acc", "circcorr"] == pytest.approx(1.0)     # along the fall
    assert drums.loc["max_vel", "circcorr"] == pytest.approx(1.0)     # rotated copy
    assert drums.loc["max_acc", "mean_difference_deg"] == pytest.approx(0.0, abs=1e-9)
    assert drums.loc["max_vel", "mean_difference_deg"] == pytest.approx(-90.0)
    assert drums.loc["back_azimuth", "resultant_length"] == pytest.approx(
        report.back_azimuth_table(hand_runs()).set_index("column").loc["drums",
                                                                       "resultant_length"])


def test_per_record_table():
    rows = report.per_record_table(hand_runs()).set_index("record")
    assert len(rows) == len(CASES)
    assert rows.loc["R1", "drums (deg)"] == "110" and rows.loc["R1", "drums class"] == "toward"
    assert rows.loc["R2", "drums class"] == "away" and rows.loc["R4", "drums class"] == "transverse"
    assert rows.loc["R5", "drums (deg)"] == "stands" and rows.loc["R5", "drums class"] == ""
    assert rows.loc["R1", "monolithic class"] == "away"
    assert rows.loc["R3", "back azimuth (deg)"] == "0" and rows.loc["GM20", "back azimuth (deg)"] == "-"
    assert rows.loc["R2", "PGA (m/s^2)"] == "2.50" and rows.loc["R2", "distance (km)"] == "6.0"


def test_statements_are_generated_from_the_numbers():
    runs = hand_runs()
    text = "\n".join(report.records_statements(report.toppled_fractions(runs),
                                               report.back_azimuth_table(runs),
                                               report.correlation_table(runs)))
    assert "**Drum column.** 8 of 9 records toppled it in one run each" in text
    assert "2 of 9 records toppled it" in text and "each run is a sample" in text
    assert "the paper: 13 of 29" in text and "the paper: 7 of 29" in text
    assert "Of the 5 falls with a known back azimuth, 2 were toward" in text
    assert "1 away and 2 transverse" in text
    assert "not concentrated relative to the back azimuth" in text
    # drums: |r| = 1 with both the largest acceleration and the largest velocity (a tie)
    assert "no reference stands out" in text and "standard error 1/sqrt(5)" in text
    assert "Answer to the paper's question** (do toppled columns point to the source?): no" in text


def test_concentrated_falls_are_reported_as_such():
    rows = []
    for k in range(12):
        baz = 30.0 * k
        for column in ("drums", "monolithic"):
            rows.append({"campaign": "records", "record_id": f"S{k}", "column": column,
                         "toppled": True, "downfall_azimuth_deg": (baz + 5.0 - k) % 360.0,
                         "back_azimuth_deg": baz, "az_max_acc_deg": 0.0,
                         "az_max_vel_deg": 0.0, "az_max_disp_deg": 0.0})
    runs = pd.DataFrame(rows)
    directions = report.back_azimuth_table(runs)
    assert (directions["toward"] == 12).all() and (directions["rayleigh_p"] < 1e-4).all()
    text = "\n".join(report.records_statements(report.toppled_fractions(runs), directions,
                                               report.correlation_table(runs)))
    assert "the falls are concentrated toward" in text
    assert "the fall directions depend on the back azimuth for the drum column" in text


def test_too_few_falls_give_no_answer():
    runs = hand_runs()
    runs = runs[runs["record_id"].isin(["R1", "R2", "R5"])]
    directions = report.back_azimuth_table(runs)
    text = "\n".join(report.records_statements(report.toppled_fractions(runs), directions,
                                               report.correlation_table(runs)))
    assert "Of the 2 falls with a known back azimuth, 1 was toward" in text
    assert "Of the 1 fall with a known back azimuth, 0 were toward" in text
    assert "Too few falls" in text and "Rayleigh" not in text
    assert "source?): not yet" in text


def test_records_section_from_runs_csv(tmp_path):
    (tmp_path / "records").mkdir()
    hand_runs().to_csv(tmp_path / "records" / "runs.csv", index=False)
    section = report.records_section(tmp_path)
    assert "9 records" in section and "6 of them with a back azimuth" in section
    assert "| drums" in section and "8/9" in section and "13/29" in section
    assert "Answer to the paper's question" in section
    empty = report.records_section(tmp_path / "nothing")
    assert "Not run yet" in empty


def test_processing_section_quotes_the_peer_check(tmp_path):
    rows = [{"id": "A", "pulse_like": True, "pga_ratio_given": 1.0, "pgv_ratio_given": 0.95,
             "pga_ratio_flatfile": None, "pgv_ratio_flatfile": None},
            {"id": "B", "pulse_like": True, "pga_ratio_given": 0.99, "pgv_ratio_given": 0.8,
             "pga_ratio_flatfile": None, "pgv_ratio_flatfile": None},
            {"id": "C", "pulse_like": None, "pga_ratio_given": 0.98, "pgv_ratio_given": 1.0,
             "pga_ratio_flatfile": 0.97, "pgv_ratio_flatfile": 0.9}]
    (tmp_path / "records").mkdir()
    pd.DataFrame(rows).to_csv(tmp_path / "records" / "peer_check.csv", index=False)
    text = report.processing_section(tmp_path)
    assert "| pulse-like | PGV / PEER's record |   2 |    0.875 | 0.800 (B)" in text
    assert "1 of 2 keep their PGV within 10 %" in text
    assert "Not run yet" in report.processing_section(tmp_path / "nothing")
