"""The verification campaign's types: a Check validated and identified on creation, a
CheckResult read by one loader, and the campaign's summary of made-up results."""
import dataclasses
import json

import pytest

from pipeline import verification
from pipeline.files import InputError
from pipeline.verification import Check, CheckResult, campaign_checks, run_check


@pytest.mark.parametrize("kind, setting, words", [
    ("rolling", {"mu_s": 0.5}, "unknown kind 'rolling'"),
    ("housner", {"theta0_ratio": 0.5}, "exactly theta0_ratio, damping"),
    ("sliding", {"mu_s": 0.5, "damping": 0.3}, "exactly mu_s"),
    ("housner", {"theta0_ratio": 1.5, "damping": 1.0}, "theta0 ratio must be between 0 and 1"),
    ("housner", {"theta0_ratio": 0.5, "damping": 1.5}, "--damping"),
    ("housner", {"theta0_ratio": 0.5, "damping": float("nan")}, "finite number"),
    ("sine-pulse", {"amplitude_ratio": True, "omega_ratio": 5.0}, "finite number"),
    ("sine-pulse", {"amplitude_ratio": 6.5, "omega_ratio": 0.0}, "--omega-ratio"),
    ("sliding", {"mu_s": 0.0}, "--mu-s"),
    ("sliding", {"mu_s": 10 ** 400}, "mu_s 1000000.*0000 is beyond a float's range"),
])
def test_a_bad_check_is_refused_on_creation_in_one_line(kind, setting, words):
    with pytest.raises(InputError, match=words) as err:
        Check.create(kind, "code", **setting)
    assert "\n" not in str(err.value)


def test_the_run_id_follows_the_code_and_the_setting_and_nothing_else():
    a = Check.create("housner", "code", theta0_ratio=0.5, damping=1.0)
    assert a == Check.create("housner", "code", damping=1.0, theta0_ratio=0.5)
    assert a.run_id != Check.create("housner", "code", theta0_ratio=0.4, damping=1.0).run_id
    assert a.run_id != Check.create("housner", "other", theta0_ratio=0.5, damping=1.0).run_id
    assert Check.from_dict(dict(a)) == a                 # what a Dask worker receives
    assert a["record"] == "housner" and a["damping"] == 1.0 and a.get("motion_file") is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.kind = "sliding"


def test_the_campaign_checks_span_its_grids_with_one_run_id_each():
    checks = campaign_checks("code")
    by_kind = {k: [c for c in checks if c.kind == k] for k in verification.KINDS}
    assert len(by_kind["housner"]) == (len(verification.CAMPAIGN_THETA0)
                                       * len(verification.CAMPAIGN_DAMPING))
    assert len(by_kind["sine-pulse"]) == (len(verification.CAMPAIGN_PULSE_AMPLITUDES)
                                          * len(verification.CAMPAIGN_PULSE_OMEGAS))
    assert sorted(c["mu_s"] for c in by_kind["sliding"]) == sorted(verification.SLIDING_MU)
    assert len({c.run_id for c in checks}) == len(checks)


def _housner(theta0_ratio, error, passed=True):
    return {"test": "housner", "passed": passed, "theta0_ratio": theta0_ratio,
            "max_rel_error_impact_times": error, "max_rel_error_peaks": error / 2,
            "effective_restitution": 0.9 + error, "housner_restitution": 0.9,
            "yade": {"peaks_over_alpha": [0.4, 0.3]}}


def _sliding(mu, rocking):
    return {"test": "sliding", "passed": True, "augusti_sinopoli_mu_min": 0.149,
            "runs": [{"mu_s": mu, "pure_rocking": rocking, "t": [0.0], "base_x_m": [0.0]}]}


def test_the_summary_takes_the_worst_of_each_kind():
    pairs = [(Check.create("housner", "c", theta0_ratio=r, damping=1.0),
              CheckResult(_housner(r, e, passed=p)))
             for r, e, p in ((0.2, 0.01, True), (0.4, 0.03, False))]
    pairs += [(Check.create("sliding", "c", mu_s=mu), CheckResult(_sliding(mu, mu > 0.15)))
              for mu in (0.1, 0.14, 0.2, 0.4)]
    pairs += [(Check.create("sine-pulse", "c", amplitude_ratio=a, omega_ratio=5.0),
               CheckResult({"test": "sine-pulse", "passed": a < 7, "yade": {"mode": mode}}))
              for a, mode in ((5.5, "overturn_after_impact"), (7.0, "no_overturn"))]
    out = verification.summarise_campaign(pairs)
    housner = out["housner"]["1.0"]
    assert housner["max_rel_error_impact_times"] == 0.03
    assert housner["max_rel_error_peaks"] == 0.015
    assert housner["effective_restitution"] == pytest.approx(0.92)
    assert housner["all_passed"] is False
    assert out["sine_pulse"] == {"runs": 2, "agree": 1,
                                 "modes_seen": ["no_overturn", "overturn_after_impact"]}
    assert out["sliding"] == {"lowest_mu_pure_rocking": 0.2, "highest_mu_sliding": 0.14,
                              "augusti_sinopoli_mu_min": 0.149}
    assert len(out["lines"]) == 3


@pytest.mark.parametrize("content, words", [
    (None, "verification result not found"),
    ("{", "not a verification result"),
    (json.dumps({"test": "rolling", "passed": True}), "unknown test 'rolling'"),
    (json.dumps({"test": "sliding", "passed": "yes"}), "passed must be true or false"),
    (json.dumps({"test": "sine-pulse", "passed": True, "yade": {"mode": "wobble"}}),
     "lacks yade.mode"),
    (json.dumps({**_sliding(0.3, True), "runs": [{"mu_s": 0.3}]}), "lacks runs with"),
])
def test_a_bad_result_file_is_named_in_one_line(tmp_path, content, words):
    path = tmp_path / "summary.json"
    if content is not None:
        path.write_text(content)
    with pytest.raises(InputError, match=words) as err:
        CheckResult.load(tmp_path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


@pytest.mark.yade
def test_the_campaign_worker_writes_a_result_its_loader_reads(tmp_path):
    """Housner's free rocking through the worker, from the flat dict a Dask worker gets:
    the result read back is the physics check (within 2 % of Housner's equation)."""
    check = Check.create("housner", "code", theta0_ratio=0.5, damping=1.0)
    run_check(dict(check), tmp_path)
    result = CheckResult.load(tmp_path)
    assert result.kind == "housner" and result.passed
    assert result["max_rel_error_impact_times"] < 0.02
