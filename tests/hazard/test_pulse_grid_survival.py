"""Survival from a pulse-grid fragility (cells over PGA x PGV/PGA) and the motion at a site
from its standing and fallen columns, against closed forms."""
import json
import math

import numpy as np
import pytest
from scipy import stats

from pipeline.cli import main
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.fragility import Logistic, Lognormal, RatioLognormal, \
    load_campaign_fragility
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.site_motion import motion_bound
from pipeline.hazard.survival import overturning_rate

G = STANDARD_GRAVITY


def _grid_json(path, pga_g, ratios, p_of, n=16, sets=2, p_set_of=None, logistic=None,
               uplift_g=None):
    """A pulse-grid fragility.json as campaign fragility --pulses writes it, with cell
    fractions p_of(pga_m_s2, ratio) (rounded to counts of n), per-set P and (``uplift_g``)
    the 2D block's uplift acceleration."""
    cells = []
    for a in pga_g:
        for r in ratios:
            k = int(round(n * p_of(a * G, r)))
            per_set = [float(p_set_of(s, a * G, r)) if p_set_of else k / n for s in range(sets)]
            cells.append({"pga_g": a, "pgv_pga_s": r, "n": n, "overturned": k, "P": k / n,
                          "P_per_set": per_set, "sets": list(range(sets))})
    model = {"cells": cells}
    if logistic is not None:
        model["logistic"] = {"coefficients": dict(zip(("b0", "b1", "b2"), logistic)),
                             "se": {"b0": 0.1, "b1": 0.1, "b2": 0.1}, "cov": None}
    data = {"mode": "pulses", "specimen": "test rock",
            "pulse_grid": {"pga_g": list(pga_g), "pgv_pga_s": list(ratios), "members": sets,
                           "models": {"monolithic": model}}}
    if uplift_g is not None:
        data["pulse_grid"]["block2d"] = {"alpha_rad": math.atan(uplift_g),
                                         "uplift_g": uplift_g}
    path.write_text(json.dumps(data))
    return path


def test_grid_is_bilinear_in_log_space_and_the_surface_outside(tmp_path):
    # P linear in ln PGA and ln PGV/PGA is reproduced exactly by bilinear interpolation
    pga_g, ratios = [0.1, 0.2, 0.4, 0.8], [0.05, 0.1, 0.2]
    def p_of(a, r):
        return 0.5 + 0.2 * math.log(a / (0.2 * G)) + 0.1 * math.log(r / 0.1)
    path = _grid_json(tmp_path / "f.json", pga_g, ratios, p_of, n=100000,
                      logistic=(-2.0, 3.0, 0.5))
    grid = load_campaign_fragility(path, below="logistic")
    a = np.array([0.13, 0.3, 0.55, 0.79]) * G
    r = np.array([0.06, 0.15, 0.11, 0.19])
    expected = [p_of(x, y) for x, y in zip(a, r)]
    assert grid.probability(a, r) == pytest.approx(expected, abs=1e-4)
    outside_a, outside_r = np.array([0.05 * G, 2.0 * G, 0.3 * G]), np.array([0.1, 0.1, 0.5])
    surface = Logistic((-2.0, 3.0, 0.5))
    assert grid.probability(outside_a, outside_r) == pytest.approx(
        surface.probability(outside_a, outside_r))
    assert load_campaign_fragility(path, None, "pga-pgv").coefficients == (-2.0, 3.0, 0.5)


def _power_law(k0, k, lo, hi, n=60):
    levels = np.geomspace(lo, hi, n)
    return levels, k0 * levels ** -k


def test_survival_from_a_fine_grid_of_a_lognormal_meets_the_closed_form(tmp_path):
    # lognormal fragility under lambda = k0 x^-k: rate = k0 median^-k exp(k^2 beta^2 / 2)
    median, beta, k0, k = 3.0, 0.4, 1e-4, 2.5
    lognormal = Lognormal(median, beta)
    pga_g = np.geomspace(0.02, 5.0, 80) / 1.0
    path = _grid_json(tmp_path / "f.json", pga_g, [0.05, 0.2],
                      lambda a, r: float(lognormal.probability(a)), n=10 ** 6)
    grid = load_campaign_fragility(path)
    levels, rates = _power_law(k0, k, 0.01, 100.0, 80)
    ratio = RatioLognormal(0.1, 0.3)
    rate = overturning_rate(levels, rates, lambda x: overturn_probability([grid], ratio, x)[0])
    closed = k0 * median ** -k * math.exp(0.5 * (k * beta) ** 2)
    assert rate["rate_per_yr"] == pytest.approx(closed, rel=0.02)


def _plain_curve(path):
    levels, rates = _power_law(1e-4, 2.5, 0.05, 300.0, 40)
    path.write_text("pga_m_s2,annual_rate_per_yr\n"
                    + "".join(f"{float(x)!r},{float(r)!r}\n" for x, r in zip(levels, rates)))
    return path


def test_parameter_sets_and_monte_carlo_error_reported_apart(tmp_path):
    # two parameter sets with lognormal medians 2 and 4 m/s^2; the pooled P their mean
    sets = [Lognormal(2.0, 0.4), Lognormal(4.0, 0.4)]
    def p_set(s, a, r):
        return float(sets[s].probability(a))
    def pooled(a, r):
        return 0.5 * (p_set(0, a, r) + p_set(1, a, r))
    curve = _plain_curve(tmp_path / "curve.csv")
    runs = {}
    for n in (8, 800):
        path = _grid_json(tmp_path / f"f{n}.json", np.geomspace(0.01, 10.0, 40), [0.05, 0.2],
                          pooled, n=n, p_set_of=p_set, logistic=(-2.0, 3.0, 0.5))
        out = tmp_path / f"out{n}"
        assert main(["survival", "--hazard", str(curve), "--fragility", str(path),
                     "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3", "--age-ka", "2",
                     "--draws", "120", "--hazard-component", "rotd100",
                     "--out", str(out)]) == 0
        runs[n] = json.loads((out / "survival.json").read_text())
    wide, narrow = (r["survival_interval"] for r in (runs[8], runs[800]))
    assert narrow[1] - narrow[0] < 0.3 * (wide[1] - wide[0])     # MC error ~ 1/sqrt(n)
    assert narrow[0] <= runs[800]["survival_probability"] <= narrow[1]
    # each set's survival: exp(-rate t), rate in closed form for its lognormal
    expected = [math.exp(-2000.0 * 1e-4 * f.median_m_s2 ** -2.5 * math.exp(0.5 * (2.5 * 0.4) ** 2))
                for f in sets]
    assert runs[800]["survival_per_parameter_set"] == pytest.approx(expected, rel=0.02)
    assert runs[800]["survival_parameter_set_range"] == pytest.approx(
        [min(expected), max(expected)], rel=0.02)
    # on a RotD50 hazard curve: a pulse is the field motion's strongest direction, so each
    # set's median on the curve's PGA is its median / (RotD100 / RotD50), Boore & Kishida
    # (2017) at their reference M 5.5, 50 km: exp(c0) = exp(0.185774509)
    out = tmp_path / "rotd50"
    assert main(["survival", "--hazard", str(curve), "--fragility", str(tmp_path / "f800.json"),
                 "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3", "--age-ka", "2",
                 "--draws", "0", "--out", str(out)]) == 0
    rotd50 = json.loads((out / "survival.json").read_text())
    c45 = math.cos(math.radians(45.0))
    bk = math.exp(-0.185774509051029)
    expected = [math.exp(-2000.0 * 1e-4 * (bk * f.median_m_s2) ** -2.5
                         * math.exp(0.5 * (2.5 * 0.4) ** 2)) for f in sets]
    assert rotd50["survival_per_parameter_set"] == pytest.approx(expected, rel=0.02)
    measure = rotd50["specimens"][0]["fragility"]["pga_measure"]
    assert measure["fraction"] == pytest.approx(bk)
    assert measure["polarised_fraction"] == pytest.approx(c45)
    assert rotd50["hazard_component"] == "rotd50"


def test_bad_pulse_grid_files_one_line(tmp_path):
    path = _grid_json(tmp_path / "f.json", [0.1, 0.2], [0.1, 0.2], lambda a, r: 0.5)
    data = json.loads(path.read_text())
    data["pulse_grid"]["models"]["monolithic"]["cells"][0]["pga_g"] = 0.15
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="a cell off the grid") as caught:
        load_campaign_fragility(path)
    assert "\n" not in str(caught.value)
    with pytest.raises(InputError, match="no model 'drums'"):
        load_campaign_fragility(_grid_json(tmp_path / "g.json", [0.1, 0.2], [0.1, 0.2],
                                           lambda a, r: 0.5), "drums")


# ---------------------------------------------------------------- the motion at a site
@pytest.mark.parametrize("fallen, n", [(1, 4), (3, 4), (2, 7), (5, 6)])
def test_maximum_likelihood_pga_of_k_fallen_of_n(fallen, n):
    # identical lognormal columns: L = Phi(z)^k (1 - Phi(z))^(n-k), maximal at Phi(z) = k/n
    median, beta = 3.0, 0.4
    result = motion_bound([Lognormal(median, beta)] * n, [True] * fallen + [False] * (n - fallen))
    assert result["pga_ml_m_s2"] == pytest.approx(
        median * math.exp(beta * stats.norm.ppf(fallen / n)), rel=1e-6)
    lo, hi = result["pga_interval95_m_s2"]
    for end in (lo, hi):                   # ln L drops by chi2_1(0.95) / 2 at both ends
        z, z_ml = math.log(end / median) / beta, stats.norm.ppf(fallen / n)
        def ll(zz):
            return fallen * stats.norm.logcdf(zz) + (n - fallen) * stats.norm.logsf(zz)
        assert ll(z_ml) - ll(z) == pytest.approx(0.5 * stats.chi2.ppf(0.95, 1), abs=1e-6)
    assert lo < result["pga_ml_m_s2"] < hi


def test_all_standing_gives_an_upper_bound_only():
    # n standing: L = (1 - Phi(z))^n falls with PGA; 95 % bound where n ln(1 - Phi) = -1.92
    median, beta, n = 3.0, 0.4, 5
    result = motion_bound([Lognormal(median, beta)] * n, [False] * n)
    drop = 0.5 * stats.chi2.ppf(0.95, 1)
    bound = median * math.exp(beta * stats.norm.isf(math.exp(-drop / n)))
    assert result["pga_ml_m_s2"] is None and result["pga_interval95_m_s2"][0] is None
    assert result["pga_interval95_m_s2"][1] == pytest.approx(bound, rel=1e-6)
    assert "upper bound" in result["note"]


def _observations(path):
    path.write_text(json.dumps({"sites": [
        {"name": "A", "east_km": 0, "north_km": 0, "columns": [
            {"column": "monolithic", "state": "fallen", "downfall_azimuth_deg": 200},
            {"column": "monolithic", "state": "standing"},
            {"column": "monolithic", "state": "standing"},
            {"column": "monolithic", "state": "standing"}]},
        {"name": "B", "east_km": 5, "north_km": 0, "columns": [
            {"column": "drums", "state": "standing"}]}]}))
    return path


def test_command_writes_the_site_motion(tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["survival", "--observations", str(_observations(tmp_path / "obs.json")),
               "--observation-site", "A", "--median-g", "0.3", "--beta", "0.4",
               "--out", str(out)])
    assert rc == 0
    result = json.loads((out / "site_motion.json").read_text())
    assert (result["fallen"], result["standing"]) == (1, 3)
    assert result["pga_ml_g"] == pytest.approx(0.3 * math.exp(0.4 * stats.norm.ppf(0.25)),
                                               rel=1e-6)
    assert not (out / "survival.json").exists()


@pytest.mark.parametrize("extra, message", [
    (["--observation-site", "C", "--median-g", "0.3", "--beta", "0.4"], "no site 'C'"),
    (["--median-g", "0.3", "--beta", "0.4"], "2 sites"),
    (["--observation-site", "A"], "give one fragility"),
    (["--observation-site", "A", "--logistic=-3,3,1"], "--at-pgv-pga"),
    (["--observation-site", "A", "--logistic=-3,3,1", "--at-pgv-pga", "0"],
     "--at-pgv-pga 0 outside"),
])
def test_site_motion_refuses_bad_input_in_one_line(tmp_path, capsys, extra, message):
    out = tmp_path / "out"
    argv = ["survival", "--observations", str(_observations(tmp_path / "obs.json")),
            "--out", str(out)] + extra
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_report_section_says_not_run_yet_then_quotes_the_file(tmp_path):
    from pipeline.report import survival_section
    assert "Not run yet" in survival_section(tmp_path)
    path = _grid_json(tmp_path / "f.json", np.geomspace(0.05, 2.0, 12), [0.05, 0.2],
                      lambda a, r: float(Lognormal(3.0, 0.4).probability(a)),
                      p_set_of=lambda s, a, r: float(Lognormal(2.0 + 2 * s, 0.4).probability(a)),
                      logistic=(-2.0, 3.0, 0.5))
    out = tmp_path / "rock-survival"
    assert main(["survival", "--hazard", str(_plain_curve(tmp_path / "curve.csv")),
                 "--fragility", str(path), "--pgv-pga-median", "0.1", "--pgv-pga-sigma",
                 "0.3", "--age-ka", "2", "--draws", "20", "--out", str(out)]) == 0
    summary = json.loads((out / "survival.json").read_text())
    text = survival_section(tmp_path)
    assert "Not run yet" not in text
    assert f"{summary['survival_probability']:.3g}" in text
    lo, hi = summary["survival_parameter_set_range"]
    assert f"per parameter set {lo:.3g}-{hi:.3g}" in text
    assert "rock-survival/survival.png" in text
