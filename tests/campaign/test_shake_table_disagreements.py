"""Where the shake-table members and the laboratory disagree, from hand-made finished
campaigns (no YADE): the kinds of error, the mechanisms of the runs against the damage
states' limits, the Wilson interval of a region against its closed form, the file read
back and a malformed one refused in one line, the times of first slip and uplift of a
trajectory built by hand."""
import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from pipeline.campaign.shake_table_disagreement_file import (FILE, DisagreementTable,
                                                             Mechanism, Verdict)
from pipeline.campaign.shake_table_disagreements import (FIGURE, disagreement_table,
                                                         first_times, write_disagreements)
from pipeline.campaign.shake_table_experiments import EXPERIMENTS, OUTCOME, SPECIMEN
from pipeline.campaign.shake_table_regions import DisagreementSummary, RegionKind
from pipeline.campaign.shake_table_scores import write_scores
from pipeline.files import InputError
from pipeline.outcome import Trajectory
from tests.campaign.tiny_members_campaign import CRITICAL_DEG, member_run, write_campaign

STILL = member_run()
SLID = member_run(tilt_deg=0.1, base_slip_m=0.004, residual_slide_m=0.005,  # no uplift
                  twist_deg=-1.5)
ROCKED = member_run(tilt_deg=2.0, base_slip_m=0.01, residual_slide_m=0.003)
TOPPLED = member_run(toppled=True, tilt_deg=90.0, base_slip_m=0.4, residual_slide_m=0.2,
                     kn=1e9, damping=0.05, mu_s=0.8, footprint_m=0.0015, rotate_deg=357.0)


def _test(name, observed, runs, pga_g=0.15, pgv_pga_s=0.1, day="2021-07-13",
          split="calibration"):
    return {"test": name, "date": day, "split": split, "pga_g": pga_g,
            "pgv_pga_s": pgv_pga_s, "observed": observed, "runs": runs}


TESTS = [
    _test("Test001", True, [SLID, SLID, STILL, SLID]),                 # missed overturn
    _test("Test002", False, [TOPPLED, TOPPLED, TOPPLED, ROCKED], pga_g=0.35),   # false
    _test("Test003", True, [TOPPLED, TOPPLED, ROCKED, ROCKED]),     # P = 0.5: missed
    _test("Test004", False, [STILL, STILL, STILL, STILL], day="2021-08-16",
          split="validation"),
    _test("Test005", True, [TOPPLED, TOPPLED, TOPPLED, TOPPLED], pga_g=0.35,
          day="2021-08-16", split="validation"),
]


@pytest.fixture
def campaign(tmp_path):
    write_campaign(tmp_path, TESTS)
    return tmp_path


def test_each_test_gets_its_kind_of_error(campaign):
    table = disagreement_table(campaign)
    verdicts = {t.test: t.verdict for t in table.tests}
    assert verdicts == {"Test001": Verdict.MISSED_OVERTURN,
                        "Test002": Verdict.FALSE_OVERTURN,
                        "Test003": Verdict.MISSED_OVERTURN,     # P > 0.5 says overturned
                        "Test004": Verdict.RIGHT, "Test005": Verdict.RIGHT}
    assert [t.majority_wrong for t in table.tests] == [True, True, True, False, False]


def test_a_run_that_slid_without_uplift_is_sliding(campaign):
    """theta_max/alpha 0.1/5 = 0.02 under the rotation limit 0.1, residual slide 5 mm
    over the slight limit 0.005 x 90 mm: sliding; 2/5 = 0.4 of alpha: rocking."""
    first, second, *_ = disagreement_table(campaign).tests
    assert first.mechanism is Mechanism.SLIDING
    assert (first.runs_sliding, first.runs_uplift, first.overturned) == (3, 0, 0)
    assert first.median_tilt_over_critical == pytest.approx(0.1 / CRITICAL_DEG)
    assert first.max_residual_slide_m == pytest.approx(0.005)
    assert first.max_residual_twist_deg == pytest.approx(1.5)     # either way round
    assert second.mechanisms == {Mechanism.TOPPLED: 3, Mechanism.ROCKING: 1,
                                 Mechanism.SLIDING: 0, Mechanism.STILL: 0}
    # the contact of the overturned members against the standing one's, as the files say
    assert (second.kn_n_per_m_overturned, second.kn_n_per_m_standing) == (1e9, 1e8)
    assert second.footprint_tolerance_m_overturned == pytest.approx(0.0015)
    # rotate_deg 357: the table motion turned 3 deg clockwise back (a yaw of +3 deg)
    assert (second.motion_turn_deg_overturned, second.motion_turn_deg_standing) == \
        pytest.approx((-3.0, 0.0))
    assert math.isnan(first.kn_n_per_m_overturned)            # none overturned


def test_a_regions_wilson_interval_is_the_closed_form(campaign):
    """PGA 0.1-0.2 g holds Test001 and Test003 (both wrong) and Test004 (right): 2 of 3."""
    summary = DisagreementSummary.of(disagreement_table(campaign))
    region = next(r for r in summary.regions
                  if r.kind is RegionKind.PGA and r.label == "0.1-0.2")
    k, n, z = 2, 3, norm.ppf(0.975)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    assert (region.wrong.count, region.wrong.of, region.missed, region.false) == (2, 3, 2, 0)
    assert region.wrong.ci95 == pytest.approx([centre - half, centre + half], abs=1e-9)
    months = {r.label: r.wrong.count for r in summary.regions if r.kind is RegionKind.MONTH}
    assert months == {"2021-07": 3, "2021-08": 0}
    assert DisagreementSummary.from_json(json.loads(json.dumps(summary.to_json()))) == summary


def test_the_file_reads_back_and_a_malformed_one_is_refused_in_one_line(campaign):
    write_disagreements(campaign, "tiny")
    pd.testing.assert_frame_equal(DisagreementTable.load(campaign).frame(),
                                  disagreement_table(campaign).frame())     # NaN == NaN
    assert (campaign / FIGURE).stat().st_size > 10_000
    text = (campaign / FILE).read_text()
    frame = pd.read_csv(campaign / FILE)
    cases = {"no column P": frame.drop(columns=["P"]),
             "P 0.9 is not that": frame.assign(P=[0.9] + list(frame["P"][1:])),
             "overturned must be a count": frame.assign(
                 overturned=[-1] + list(frame["overturned"][1:])),
             "verdict 'right' is not that": frame.assign(verdict="right")}
    for said, bad in cases.items():
        bad.to_csv(campaign / FILE, index=False)
        with pytest.raises(InputError) as caught:
            DisagreementTable.load(campaign)
        message = str(caught.value)
        assert "\n" not in message and said in message and FILE in message, message
    (campaign / FILE).write_text(text)


def test_runs_that_disagree_with_members_csv_are_refused(campaign):
    runs = pd.read_csv(campaign / "members_runs.csv")
    runs[runs["run_id"] != "test001m3"].to_csv(campaign / "members_runs.csv", index=False)
    with pytest.raises(InputError, match="holds 3 runs of test Test001"):
        disagreement_table(campaign)


def test_first_slip_and_first_uplift_of_a_trajectory():
    """A box slides 2 mm at t = 1 s, then tilts about its centre of mass at 0.01 rad/s
    from t = 2 s: slip first at 1 s (limit 0.005 x 0.2 m), uplift when the tilt reaches
    0.1 x 5 deg, at 2 + radians(0.5)/0.01 s."""
    t = np.arange(0.0, 4.0, 0.01)
    theta = np.where(t >= 2.0, 0.01 * (t - 2.0), 0.0)
    pos = np.zeros((len(t), 1, 3))
    pos[:, 0, 0] = np.where(t >= 1.0, 0.002, 0.0)
    pos[:, 0, 2] = 0.4
    quat = np.stack([np.cos(theta / 2), 0 * theta, np.sin(theta / 2), 0 * theta], axis=1)
    box = {"shape": "box", "height": 0.8, "width": 0.2, "depth": 0.2, "column": "c",
           "index": 0, "initial_pos": [0.0, 0.0, 0.4]}
    trajectory = Trajectory(t=t, pos=pos, quat=quat[:, None, :], bodies=[box])
    uplift, slip = first_times(trajectory, 5.0, 0.2)
    assert slip == pytest.approx(1.0, abs=1e-9)
    assert uplift == pytest.approx(2.0 + math.radians(0.5) / 0.01, abs=0.011)


def test_the_scores_write_the_disagreements(campaign):
    """write_scores (what a campaign re-run with every run finished ends with) writes
    disagreements.csv, its figure and the summary in shake_table_members.json."""
    per_test = pd.read_csv(campaign / "members.csv", dtype={"test": str})
    full = [SimpleNamespace(tags=SimpleNamespace(member=m, point={"m": m})) for m in (-1, 0)]
    options = {"specimen": SPECIMEN, "experiments": EXPERIMENTS, "outcome": OUTCOME,
               "validate_from": "2021-08-01", "members": 4, "axis_deg": 90.0,
               "providers": None}
    (campaign / FILE).unlink(missing_ok=True)
    result = write_scores(per_test, campaign, options, full, True)
    assert (campaign / FILE).is_file() and (campaign / FIGURE).is_file()
    saved = json.loads((campaign / "shake_table_members.json").read_text())
    assert saved["disagreements"]["wrong"]["count"] == 3
    assert saved["disagreements"]["wrong"]["of"] == len(TESTS)
    assert result["lines"][-len(saved["disagreements"]["lines"]):] == \
        saved["disagreements"]["lines"]
