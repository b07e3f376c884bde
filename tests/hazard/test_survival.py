"""Survival against independent references: the closed form of a lognormal fragility
under a power-law hazard, numeric quadrature over the age, the PGV/PGA average by
quadrature, and the command's outputs and one-line refusals."""
import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, stats

from pipeline import RECORDS_DIR
from pipeline.campaign.fragility_tables import _column_fits
from pipeline.cli import main
from pipeline.files import InputError
from pipeline.hazard import load_hazard
from pipeline.hazard.fragility.file import FragilityFile, write_fragility_file
from pipeline.hazard.ages import LowerBound, TruncatedNormal, UniformInterval
from pipeline.hazard.fragility import (Logistic, Lognormal, RatioFromGmm, RatioLognormal,
                                       load_campaign_fragility)
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.survival import (contribution_by_intensity, intensity_scale_bound,
                                      overturning_rate, rate_scale_bound, survival_probability)
from pipeline.stats.fragility import logistic_surface

CASE_14 = RECORDS_DIR / "hazard" / "oq_classical_case_14_hazard_curve-rlz-000_PGA.csv"


def _power_law(k0, k, lo, hi, n=40):
    """lambda(x) = k0 x^-k (x in m/s^2) at n levels from lo to hi."""
    levels = np.geomspace(lo, hi, n)
    return levels, k0 * levels ** -k


@pytest.mark.parametrize("k, median, beta", [(2.5, 3.0, 0.5), (1.5, 1.0, 0.3),
                                             (3.5, 5.0, 0.7)])
def test_rate_against_the_closed_form(k, median, beta):
    """Lognormal fragility under lambda = k0 x^-k: lambda_ov = k0 median^-k exp(k^2 beta^2 / 2)."""
    k0 = 1e-4
    levels, rates = _power_law(k0, k, median * math.exp(-8 * beta), median * math.exp(8 * beta))
    fragility = Lognormal(median, beta)
    rate = overturning_rate(levels, rates, fragility.probability)
    expected = k0 * median ** -k * math.exp(k * k * beta * beta / 2)
    assert rate["rate_per_yr"] == pytest.approx(expected, rel=2e-4)
    assert rate["share_first_interval"] < 1e-6
    rows = contribution_by_intensity(levels, rates, fragility.probability)
    assert sum(r["rate_per_yr"] for r in rows) == pytest.approx(rate["rate_per_yr"], rel=1e-12)
    assert sum(r["share"] for r in rows) == pytest.approx(1.0, abs=1e-12)


def test_ends_of_a_short_curve_are_reported():
    levels, rates = _power_law(1e-4, 2.0, 0.5, 2.0)
    rate = overturning_rate(levels, rates, Lognormal(3.0, 0.3).probability)
    assert rate["share_at_last_level"] > 0.5          # the fragility lies above the curve
    assert rate["last_level_could_add_per_yr"] == pytest.approx(
        rates[-1] * (1 - Lognormal(3.0, 0.3).probability(np.array([2.0]))[0]))


def _age_quadrature(rate, mean, sd):
    """E[exp(-rate T)], T normal(mean, sd) truncated at 0, by numeric quadrature."""
    norm = stats.norm.sf(0, mean, sd)
    value, _ = integrate.quad(lambda t: math.exp(-rate * t) * stats.norm.pdf(t, mean, sd),
                              0, mean + 12 * sd, points=[mean], limit=200)
    return value / norm


@pytest.mark.parametrize("rate, mean, sd", [(1e-4, 15e3, 3e3), (5e-5, 15e3, 10e3),
                                            (1e-3, 2e3, 1.5e3), (2e-6, 100e3, 40e3)])
def test_survival_over_an_uncertain_age(rate, mean, sd):
    expected = _age_quadrature(rate, mean, sd)
    assert float(survival_probability(rate, mean, sd)) == pytest.approx(expected, rel=1e-7)
    assert float(survival_probability(rate, mean, 0.0)) == pytest.approx(math.exp(-rate * mean))


@pytest.mark.parametrize("rate, mean, sd", [(999.0, 1e7, 1e7), (1.0, 1e4, 1e3),
                                            (0.1, 2e3, 1.5e3), (50.0, 1e3, 5e3)])
def test_survival_when_rate_times_sd_is_large(rate, mean, sd):
    """r s >> 1: the closed form's exp(r^2 s^2 / 2) and Phi((mu - r s^2) / s) would cancel
    in digits (P above 1 from rounding): against quadrature in u = r t (the young ages,
    where the survivals lie)."""
    norm = stats.norm.cdf(mean / sd)
    value, _ = integrate.quad(lambda u: math.exp(-u) * stats.norm.pdf(u / rate, mean, sd)
                              / rate, 0, 60, limit=200)
    p = float(survival_probability(rate, mean, sd))
    assert 0 <= p <= 1 and p == pytest.approx(value / norm, rel=1e-6)


def test_rate_scale_bound_of_a_rate_too_small_for_any_float_factor():
    """A rate of 1e-317 per year over a day: no factor a float holds brings survival to
    5 % (None, as for a rate of 0), not a failed root search."""
    assert rate_scale_bound(1e-317, TruncatedNormal(1e-3), 0.05) is None
    assert rate_scale_bound(1e-317, TruncatedNormal(1e-3, 1e7), 0.05) is None


def test_rate_scale_bound():
    assert rate_scale_bound(1e-4, TruncatedNormal(15e3), 0.05) == pytest.approx(-math.log(0.05) / 1.5)
    factor = rate_scale_bound(1e-4, TruncatedNormal(15e3, 5e3), 0.05)
    assert _age_quadrature(factor * 1e-4, 15e3, 5e3) == pytest.approx(0.05, rel=1e-6)
    assert rate_scale_bound(0.0, TruncatedNormal(15e3), 0.05) is None


def test_intensity_scale_bound_under_a_power_law():
    """Intensities x c multiply a power law's rates by c^k: c = F^(1/k)."""
    k, median, beta = 2.5, 3.0, 0.5
    levels, rates = _power_law(1e-4, k, 0.02, 500.0, 60)
    fragility = Lognormal(median, beta)
    rate = overturning_rate(levels, rates, fragility.probability)["rate_per_yr"]
    for age, sd in ((15e3, 0.0), (15e3, 3e3)):
        c, note = intensity_scale_bound(levels, rates, fragility.probability,
                                        TruncatedNormal(age, sd), 0.05)
        assert note is None
        assert c == pytest.approx(rate_scale_bound(rate, TruncatedNormal(age, sd), 0.05) ** (1 / k), rel=1e-3)
    c, note = intensity_scale_bound(levels, rates, fragility.probability,
                                    TruncatedNormal(1.0), 0.05)
    assert c is None and "stays" in note


def test_sets_at_one_site():
    levels, rates = _power_law(1e-4, 2.5, 0.05, 300.0, 50)
    weak, strong = Lognormal(2.0, 0.4), Lognormal(4.0, 0.4)
    pair = [weak, strong]

    def rate(combine):
        return overturning_rate(levels, rates, lambda x: overturn_probability(
            pair, None, x, combine))["rate_per_yr"]
    single = [overturning_rate(levels, rates, f.probability)["rate_per_yr"] for f in pair]
    # the weaker specimen decides when the capacities are fully correlated: same beta,
    # so P_weak >= P_strong everywhere
    assert rate("any_correlated") == pytest.approx(single[0], rel=1e-9)
    assert single[0] < rate("any_common") < sum(single)
    # P(any) = P_w + P_s - P_w P_s, integrated term by term
    both = overturning_rate(levels, rates, lambda x: weak.probability(x)
                            * strong.probability(x))["rate_per_yr"]
    assert rate("any_common") == pytest.approx(sum(single) - both, rel=1e-9)


def test_pgv_pga_average_against_quadrature():
    surface = Logistic((1.0, 3.0, 2.0))
    ratio = RatioLognormal(0.1, 0.5)
    pga = np.array([0.5, 2.0, 6.0])
    got = overturn_probability([surface], ratio, pga)[0]
    for a, p in zip(pga, got):
        expected, _ = integrate.quad(
            lambda z: surface.probability(a, 0.1 * math.exp(0.5 * z)) * stats.norm.pdf(z),
            -10, 10)
        assert p == pytest.approx(expected, abs=1e-9)
    point = overturn_probability([surface], RatioLognormal(0.1, 0.0), pga)[0]
    np.testing.assert_allclose(point, surface.probability(pga, 0.1), rtol=1e-12)


def test_pgv_pga_from_the_ground_motion_model():
    model = RatioFromGmm(6.5, 20.0, 760.0, "SS", 0.7)
    m = model.medians
    mean, sd = model.ln_mean_sd(np.array([m["pga_m_s2"], 2 * m["pga_m_s2"]]))
    # at the median PGA the median ratio is the ratio of the medians; above it the
    # ratio falls, since PGV rises less than PGA (rho sigma_v / sigma_a < 1 here)
    assert math.exp(mean[0]) == pytest.approx(m["pgv_m_s"] / m["pga_m_s2"], rel=1e-12)
    slope = 0.7 * m["ln_std_pgv"] / m["ln_std_pga"]
    assert mean[1] - mean[0] == pytest.approx((slope - 1) * math.log(2), rel=1e-12)
    assert sd[0] == pytest.approx(m["ln_std_pgv"] * math.sqrt(1 - 0.49))


def test_fragility_draws_follow_their_intervals():
    fragility = Lognormal(3.0, 0.4, median_ci95=(2.0, 4.5), beta_ci95=(0.3, 0.6))
    draws = fragility.draws(20000, np.random.default_rng(1))
    ln_m = np.log([d.median_m_s2 for d in draws])
    assert np.std(ln_m) == pytest.approx(math.log(4.5 / 2.0) / (2 * 1.959964), rel=0.03)
    assert np.percentile(ln_m, [2.5, 97.5]) == pytest.approx(
        [math.log(3.0) - math.log(2.25) / 2, math.log(3.0) + math.log(2.25) / 2], abs=0.03)
    assert Lognormal(3.0, 0.4).draws(10, np.random.default_rng(1)) is None


def test_logistic_surface_writes_its_covariance():
    rng = np.random.default_rng(3)
    pga = np.exp(rng.uniform(math.log(0.5), math.log(10.0), 2000))
    ratio = np.exp(rng.uniform(math.log(0.05), math.log(0.5), 2000))
    toppled = rng.random(2000) < 1 / (1 + np.exp(-(1 + 3 * np.log(pga) + 2 * np.log(ratio))))
    fit = logistic_surface(pga, ratio, toppled)
    cov = np.array(fit["cov"])
    np.testing.assert_allclose(np.sqrt(np.diag(cov)), [fit["se"][k] for k in ("b0", "b1", "b2")],
                               rtol=1e-9)
    assert np.allclose(cov, cov.T) and np.all(np.linalg.eigvalsh(cov) > 0)


# ---------------------------------------------------------------- the command
def _fragility_json(path):
    """A fragility.json as campaign fragility writes it (the keys survival reads)."""
    data = {"columns": {"monolithic": {
        "description": "3D YADE monolithic column",
        "PGA": {"median": 3.0, "beta": 0.4, "median_ci95": [2.4, 3.75],
                "beta_ci95": [0.3, 0.55], "unit": "m/s^2", "note": None},
        "logistic": {"coefficients": {"b0": 1.0, "b1": 3.0, "b2": 2.0},
                     "se": {"b0": 0.3, "b1": 0.2, "b2": 0.25},
                     "cov": [[0.09, 0.03, 0.05], [0.03, 0.04, 0.01], [0.05, 0.01, 0.0625]],
                     "note": None}}}}
    path.write_text(json.dumps(data))
    return path


def test_command_writes_survival(tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["survival", "--hazard", str(CASE_14), "--site", "2", "--median-g", "0.3",
               "--beta", "0.4", "--age-ka", "15", "--out", str(out)])
    assert rc == 0
    summary = json.loads((out / "survival.json").read_text())
    assert (out / "survival.png").stat().st_size > 0
    rate = summary["annual_overturning_rate_per_yr"]
    assert summary["survival_probability"] == pytest.approx(math.exp(-rate * 15e3))
    assert summary["rate_scale_bound_5pct"] == pytest.approx(-math.log(0.05) / (rate * 15e3))
    assert summary["survival_interval"] is None
    assert summary["hazard"]["investigation_time_yr"] == 50.0
    assert summary["pgv_pga"] is None and summary["pgv_pga_used"] is False
    curve = load_hazard(CASE_14, 2)
    assert summary["contribution_by_intensity"][-1]["lo_m_s2"] == curve.levels_m_s2[-1]


def test_command_with_a_campaign_fragility_and_a_set(tmp_path):
    fragility = _fragility_json(tmp_path / "fragility.json")
    curve = tmp_path / "curve.csv"
    levels, rates = _power_law(1e-4, 2.5, 0.05, 300.0, 30)
    curve.write_text("pga_m_s2,annual_rate_per_yr\n"
                     + "".join(f"{float(x)!r},{float(r)!r}\n" for x, r in zip(levels, rates)))
    out = tmp_path / "out"
    rc = main(["survival", "--hazard", str(curve), "--fragility", str(fragility),
               "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.4", "--median-g", "0.5",
               "--beta", "0.5", "--age-ka", "15", "--age-sd-ka", "3", "--draws", "200",
               "--out", str(out)])
    assert rc == 0
    summary = json.loads((out / "survival.json").read_text())
    assert summary["pgv_pga"]["source"] == "user" and summary["pgv_pga_used"]
    first = summary["specimens"][0]
    assert first["survival_interval"][0] < first["survival_interval"][1]
    assert summary["specimens"][1]["survival_interval"] is None     # a stated lognormal
    sets = summary["site_set"]
    assert summary["survival_probability"] == sets["common_shaking"]["survival_probability_all"]
    assert (sets["independent"]["survival_probability_all"]
            <= sets["common_shaking"]["survival_probability_all"]
            <= sets["fully_correlated"]["survival_probability_all"])


@pytest.mark.parametrize("extra, message", [
    (["--median-g", "0.3"], "one --beta per --median-g"),
    (["--median-g", "0.3", "--beta", "0.4", "--age-ka", "0"], "--age-ka 0 outside"),
    (["--median-g", "-1", "--beta", "0.4"], "--median-g -1 outside"),
    (["--median-g", "0.3", "--beta", "0.4", "--magnitude", "6"], "both --magnitude and"),
    (["--median-g", "0.3", "--beta", "0.4", "--magnitude", "6", "--distance-km", "10",
      "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3"], "not both"),
    (["--median-g", "0.3", "--beta", "0.4", "--draws", "-1"], "--draws"),
    ([], "no fragility"),
    (["--logistic", "1,2"], "expected three numbers"),
    (["--logistic=1,-2,3"], "b1 must be positive"),
    (["--logistic=-3,3,1.5"], "PGV/PGA"),
])
def test_command_refuses_bad_options_in_one_line(tmp_path, capsys, extra, message):
    out = tmp_path / "out"
    argv = ["survival", "--hazard", str(CASE_14), "--site", "0", "--out", str(out)] + extra
    if "--age-ka" not in extra:
        argv += ["--age-ka", "15"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("change, message", [
    (lambda d: d.pop("columns"), "no 'columns'"),
    (lambda d: d["columns"]["monolithic"]["PGA"].update(median=None, note="not fitted here"),
     "not fitted here"),
    (lambda d: d["columns"]["monolithic"]["PGA"].update(median_ci95=[0, 3]), "median_ci95"),
    (lambda d: d["columns"]["monolithic"]["PGA"].update(unit="g"), "unknown unit"),
])
def test_bad_fragility_files_one_line(tmp_path, change, message):
    data = json.loads(_fragility_json(tmp_path / "fragility.json").read_text())
    change(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match=message) as caught:
        load_campaign_fragility(path, None, "pga")
    assert "\n" not in str(caught.value)


def test_command_refuses_a_bad_hazard_file_and_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("pga_g,annual_rate_per_yr\n0.1,1e-3\n0.2,2e-3\n")
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(bad), "--median-g", "0.3", "--beta", "0.4",
                 "--age-ka", "15", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "non-monotonic" in err and len(err.splitlines()) == 1 and not out.exists()
    fragility = _fragility_json(tmp_path / "fragility.json")
    assert main(["survival", "--hazard", str(CASE_14), "--site", "0", "--fragility",
                 str(fragility), "--age-ka", "15", "--out", str(out)]) == 2
    assert "PGV/PGA" in capsys.readouterr().err and not out.exists()


def test_reads_what_campaign_fragility_writes(tmp_path):
    """The campaign's own fits (pipeline.campaign.fragility) written as fragility.json
    and read back: the same numbers, the covariance used."""
    rng = np.random.default_rng(5)
    pga = np.repeat(np.geomspace(0.5, 8.0, 8), 60)
    ratio = np.tile(np.repeat([0.05, 0.1, 0.2], 20), 8)
    toppled = rng.random(pga.size) < Logistic((-4.0, 3.0, 1.0)).probability(pga, ratio)
    table = pd.DataFrame({"column": "monolithic", "toppled": toppled, "pga_m_s2": pga,
                          "pgv_m_s": pga * ratio, "pgv_pga_s": ratio,
                          "level_m_s2": pga})
    columns, _ = _column_fits(table, {"monolithic": "3D YADE monolithic column"}, 0.165, 2.0)
    path = write_fragility_file(tmp_path, FragilityFile(columns=columns))
    surface = load_campaign_fragility(tmp_path)
    written = json.loads(path.read_text())["columns"]["monolithic"]["logistic"]
    assert surface.coefficients == tuple(written["coefficients"][k] for k in ("b0", "b1", "b2"))
    np.testing.assert_allclose(surface.cov, written["cov"])
    lognormal = load_campaign_fragility(path, "monolithic", "pga")
    written = json.loads(path.read_text())["columns"]["monolithic"]["PGA"]
    assert lognormal.median_m_s2 == written["median"] and lognormal.beta == written["beta"]
    assert lognormal.median_ci95 == tuple(written["median_ci95"])


def test_rate_scale_bound_of_dated_ages():
    """A lower bound is a known age's closed form; an interval's factor brings its closed
    form (exp(-r lo) - exp(-r hi)) / (r (hi - lo)) to 5 %."""
    assert rate_scale_bound(1e-4, LowerBound(15e3), 0.05) == \
        pytest.approx(-math.log(0.05) / 1.5)
    factor = rate_scale_bound(1e-4, UniformInterval(13e3, 22e3), 0.05)
    r = factor * 1e-4
    assert (math.exp(-r * 13e3) - math.exp(-r * 22e3)) / (r * 9e3) == \
        pytest.approx(0.05, rel=1e-6)
