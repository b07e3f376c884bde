"""Survival on one measure and with its uncertainties: P below a pulse grid (continuity and
the closed form of its rate under a power-law hazard), RotD50 against the vector peak
(closed forms of motions along a line and of circular motion, real records against Boore
& Kishida 2017), the spread of a column campaign's members (closed forms per member), and
several hazard curves (OpenQuake's real mean and quantile curves)."""
import json
import math

import numpy as np
import pytest
from scipy import stats

from pipeline import RECORDS_DIR, paper
from pipeline.cli import main
from tests.refusal import refused
from pipeline.constants import STANDARD_GRAVITY
from pipeline.hazard import load_hazard
from pipeline.hazard.fragility.components import records_fraction
from pipeline.hazard.fragility import Lognormal, RatioLognormal, load_campaign_fragility
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.survival import overturning_rate, rate_outside
from pipeline.motion.measures import horizontal_peak, rotd_peak
from pipeline.records import rotd50_fraction

G = STANDARD_GRAVITY
C45 = math.cos(math.radians(45.0))
HAZARD = RECORDS_DIR / "hazard"
CASE_37 = {"mean": HAZARD / "oq_classical_case_37_hazard_curve-mean-PGA.csv",
           **{q: HAZARD / f"oq_classical_case_37_quantile_curve-{q}-PGA.csv"
              for q in ("0.16", "0.5", "0.84")}}


def _grid_file(path, pga_g, ratios, p_of, uplift_g=None, n=10 ** 6):
    """A pulse-grid fragility.json (as campaign fragility --pulses writes it) with cell
    fractions p_of(pga_m_s2) the same at every PGV/PGA and the 2D block's uplift."""
    cells = [{"pga_g": a, "pgv_pga_s": r, "n": n, "overturned": int(round(n * p_of(a * G))),
              "P_per_set": [p_of(a * G)], "sets": [0]} for a in pga_g for r in ratios]
    section = {"pga_g": list(pga_g), "pgv_pga_s": list(ratios), "members": 1,
               "models": {"monolithic": {"cells": cells, "logistic": {
                   "coefficients": {"b0": 0.0, "b1": 10.0, "b2": 0.0}, "cov": None,
                   "se": {"b0": 0.1, "b1": 0.1, "b2": 0.1}}}}}
    if uplift_g is not None:
        section["block2d"] = {"alpha_rad": math.atan(uplift_g), "uplift_g": uplift_g}
    path.write_text(json.dumps({"mode": "pulses", "specimen": "test rock",
                                "pulse_grid": section}))
    return path


# ---------------------------------------------------------------- below the grid

def _power_law_curve(path, low_m_s2, high_m_s2):
    """A plain hazard table of the rate 1e-4 x^-2.5 per year at 60 PGA levels (m/s^2)."""
    levels = np.geomspace(low_m_s2, high_m_s2, 60)
    path.write_text("pga_m_s2,annual_rate_per_yr\n" + "".join(
        f"{float(x)!r},{float(1e-4 * x ** -2.5)!r}\n" for x in levels))
    return path

def test_below_the_grid_p_is_continuous_and_zero_below_the_uplift(tmp_path):
    # P = 0.25 at the grid's first PGA (0.2 g), the uplift acceleration 0.1 g
    path = _grid_file(tmp_path / "f.json", [0.2, 0.4, 0.8], [0.05, 0.2],
                      lambda a: {0.2: 0.25, 0.4: 0.6, 0.8: 0.9}[round(a / G, 6)], uplift_g=0.1)
    ramp = load_campaign_fragility(path)
    ratio = np.full(5, 0.1)
    below = np.array([0.05, 0.0999, math.sqrt(0.02), 0.19999, 0.2]) * G
    # 0 below the uplift; half the edge's P at the geometric mean of 0.1 and 0.2 g (linear
    # in ln PGA); the edge's P at the edge: continuous
    assert ramp.probability(below, ratio) == pytest.approx(
        [0.0, 0.0, 0.125, 0.25, 0.25], abs=1e-4)
    sweep = np.geomspace(0.01, 0.8, 400) * G
    assert np.all(np.diff(ramp.probability(sweep, np.full(400, 0.1))) >= -1e-12)   # monotone
    edge = load_campaign_fragility(path, below="edge")
    assert edge.probability(below, ratio) == pytest.approx([0, 0, 0.25, 0.25, 0.25], abs=1e-6)
    zero = load_campaign_fragility(path, below="zero")
    assert zero.probability(below, ratio) == pytest.approx([0, 0, 0, 0, 0.25], abs=1e-6)
    described = ramp.describe()["below_grid"]
    assert (described["choice"], described["applied"]) == ("ramp", "ramp")
    assert described["uplift_pga_g"] == pytest.approx(0.1)
    # without an uplift acceleration in the file the ramp is P = 0 below the grid, said
    bare = load_campaign_fragility(_grid_file(tmp_path / "g.json", [0.2, 0.4, 0.8], [0.05, 0.2],
                                              lambda a: 0.25))
    assert bare.describe()["below_grid"]["applied"] == "zero"
    assert "no uplift acceleration" in bare.describe()["below_grid"]["note"]
    # a file with the smallest uplift of its runs ramps from that one, not their median
    data = json.loads(path.read_text())
    data["pulse_grid"]["block2d"]["uplift_g_smallest"] = 0.05
    path.write_text(json.dumps(data))
    smallest = load_campaign_fragility(path)
    assert smallest.describe()["below_grid"]["uplift_pga_g"] == pytest.approx(0.05)
    assert smallest.probability(np.array([0.049, 0.1]) * G, np.full(2, 0.1)) == pytest.approx(
        [0.0, 0.25 * math.log(2) / math.log(4)], abs=1e-4)


def test_rate_below_the_grid_against_its_closed_form(tmp_path):
    """lambda = k0 x^-k; P below the grid p1 ln(x / a_u) / L (L = ln(a_1 / a_u)) from a_u:
    rate below = p1 k0 a_u^-k (1 - e^(-kL) (1 + kL)) / (k L); with the edge's P held,
    p1 k0 (a_u^-k - a_1^-k)."""
    k0, k, p1 = 1e-4, 2.5, 0.3
    a_u, a_1 = 0.1 * G, 0.25 * G
    grid_g = np.geomspace(0.25, 2.0, 12)
    def p_of(a):
        return min(1.0, p1 + 0.5 * math.log(a / a_1))
    # PGV/PGA 0.01-1 s: the lognormal PGV/PGA (0.1 s, sigma 0.3) stays inside the grid
    path = _grid_file(tmp_path / "f.json", grid_g, [0.01, 1.0], p_of, uplift_g=0.1)
    grid = load_campaign_fragility(path)
    levels = np.geomspace(0.02, 40.0, 90)
    rates = k0 * levels ** -k
    ratio = RatioLognormal(0.1, 0.3)
    def probability(x, f=grid):
        return overturn_probability([f], ratio, x)[0]
    total = overturning_rate(levels, rates, probability)["rate_per_yr"]
    below, above = rate_outside(levels, rates, probability, a_1, grid_g[-1] * G)
    L = math.log(a_1 / a_u)
    closed = p1 * k0 * a_u ** -k * (1 - math.exp(-k * L) * (1 + k * L)) / (k * L)
    assert below == pytest.approx(closed, rel=2e-3)
    # above the grid P is the surface, 1 there (logit 10 ln PGA): the rate above is lambda(last)
    assert above == pytest.approx(k0 * (grid_g[-1] * G) ** -k, rel=2e-3)
    variants = grid.variants()
    zero = overturning_rate(levels, rates, lambda x: probability(x, variants["zero"]))
    edge = overturning_rate(levels, rates, lambda x: probability(x, variants["edge"]))
    assert zero["rate_per_yr"] == pytest.approx(total - closed, rel=2e-3)
    assert edge["rate_per_yr"] == pytest.approx(
        total - closed + p1 * k0 * (a_u ** -k - a_1 ** -k), rel=2e-3)


def test_survival_json_reports_the_rate_outside_the_grid(tmp_path):
    path = _grid_file(tmp_path / "f.json", np.geomspace(0.2, 2.0, 8), [0.05, 0.2],
                      lambda a: min(1.0, 0.3 + 0.5 * math.log(a / (0.2 * G)))
                      , uplift_g=0.1)
    curve = _power_law_curve(tmp_path / "curve.csv", 0.02, 40.0)
    summary = _survival(tmp_path / "out", "--hazard", curve, "--fragility", path,
                        "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3", "--age-ka", "1",
                        "--draws", "0", "--hazard-component", "rotd100")
    outside = summary["outside_grid"]
    rate = summary["annual_overturning_rate_per_yr"]
    assert outside["share_below_grid"] == pytest.approx(outside["rate_below_grid_per_yr"] / rate)
    assert outside["rate_per_yr_zero_below_grid"] <= rate <= \
        outside["rate_per_yr_edge_held_below_grid"]
    assert outside["rate_per_yr_zero_below_grid"] == pytest.approx(
        rate - outside["rate_below_grid_per_yr"], rel=1e-9)
    assert summary["specimens"][0]["fragility"]["below_grid"]["applied"] == "ramp"


# ---------------------------------------------------------------- RotD50 and the vector peak
@pytest.mark.parametrize("azimuth_deg", [0.0, 30.0, 117.3])
def test_rotd50_of_a_motion_along_a_line_is_its_peak_times_cos45(azimuth_deg):
    t = np.linspace(0.0, 2.0, 2001)
    a = np.sin(2 * np.pi * 1.3 * t) * np.exp(-t)          # any signal along the line
    theta = math.radians(azimuth_deg)
    series = np.column_stack([a * math.sin(theta), a * math.cos(theta), np.zeros_like(a)])
    peak = np.abs(a).max()
    assert rotd_peak(series, 50.0, 0.5) == pytest.approx(peak * C45, rel=5e-3)
    assert rotd_peak(series, 100.0, 0.5) == pytest.approx(peak, rel=1e-4)


def test_rotd_of_circular_motion_is_the_same_at_every_percentile():
    t = np.linspace(0.0, 3.0, 6001)
    series = np.column_stack([2.0 * np.cos(7 * t), 2.0 * np.sin(7 * t), np.zeros_like(t)])
    for percentile in (0, 50, 100):
        assert rotd_peak(series, percentile, 1.0) == pytest.approx(2.0, rel=1e-5)


def test_real_records_rotd50_against_the_vector_peak_and_boore_kishida():
    """For any motion RotD50 >= cos 45 deg RotD100 (each rotated peak is at least RotD100
    |cos(theta - theta_max)|); RotD100 is the horizontal vector peak; NGA-West2 records
    scatter about RotD100 / RotD50 = exp(0.1858) (Boore & Kishida 2017, PGA) with a
    sigma of 0.084 in ln."""
    from pipeline.records import processed_motion
    for record in (paper.SWEEP_RECORD,):
        motion, _ = processed_motion(record, cache_dir=None)
        assert rotd_peak(motion.acc, 100.0, 0.5) == pytest.approx(
            horizontal_peak(motion.acc)[0], rel=1e-4)
        fraction = rotd50_fraction(record)
        assert C45 <= fraction <= 1.0
        assert abs(math.log(1.0 / fraction) - 0.1858) < 4 * 0.084


def test_records_fraction_falls_back_to_boore_kishida():
    # Boore & Kishida (2017) PGA: ln(RotD100/RotD50) = c0 + r1 ln(R/50) + m1 (M-5.5) +
    # m2 (M-5.5)^2 with c0 0.18577, r1 -0.011155, m1 -0.0043515, m2 -0.0014585
    expected = math.exp(-(0.18577 - 0.011155 * math.log(10 / 50) - 0.0043515 * 1.0
                          - 0.0014585 * 1.0))
    found = records_fraction(["not-a-record"], None, 6.5, 10.0)
    assert found["fraction"] == pytest.approx(expected, rel=1e-4)
    assert "Boore & Kishida" in found["source"] and found["per_record"] == {}
    found = records_fraction(["A", "B"], lambda r: {"A": 0.8, "B": 0.9}[r])
    assert found["fraction"] == pytest.approx(math.sqrt(0.8 * 0.9))
    assert "Boore" not in found["source"]


# ---------------------------------------------------------------- a column campaign's members
MEMBERS = (2.0, 4.0)          # medians (m/s^2) of the two members' lognormal fragilities
BETA = 0.3


def _survival(out, *args):
    """survival.json of ``survival args --out out``, which succeeds."""
    assert main(["survival", *map(str, args), "--out", str(out)]) == 0
    return json.loads((out / "survival.json").read_text())


def _column_campaign(directory, records=("not-a-record",), runs_table=True):
    """fragility.json and fragility_runs.csv of a column campaign whose two members topple
    with lognormal fragilities of medians MEMBERS: at each of 40 PGA levels 60 runs per
    member, round(60 P) of them toppled."""
    directory.mkdir()
    rows = ["column,member,record_id,pga_m_s2,pgv_pga_s,toppled"]
    for member, median in enumerate(MEMBERS):
        for level in np.geomspace(0.5, 16.0, 40):
            k = int(round(60 * stats.norm.cdf(math.log(level / median) / BETA)))
            for run in range(60):
                rows.append(f"monolithic,{member},R,{float(level)!r},{0.05 if run % 2 else 0.2},"
                            f"{run < k}")
    if runs_table:
        (directory / "fragility_runs.csv").write_text("\n".join(rows) + "\n")
    pooled = {"unit": "m/s^2", "median": math.sqrt(MEMBERS[0] * MEMBERS[1]), "beta": 0.5,
              "median_ci95": [2.7, 2.95], "beta_ci95": [0.45, 0.55]}
    (directory / "fragility.json").write_text(json.dumps({
        "records": list(records), "block2d": {"alpha_rad": 0.2, "p_per_s": 2.0},
        "columns": {"monolithic": {"PGA": pooled, "logistic": {
            "coefficients": {"b0": -3.0, "b1": 3.0, "b2": 0.0}, "cov": None,
            "se": {"b0": 0.1, "b1": 0.1, "b2": 0.1}}}}}))
    return directory


def test_column_members_spread_meets_each_members_closed_form(tmp_path):
    campaign = _column_campaign(tmp_path / "campaign")
    fragility = load_campaign_fragility(campaign, "monolithic", "pga")
    fits = fragility.members()
    assert [f.median_m_s2 for f in fits] == pytest.approx(MEMBERS, rel=0.03)
    curve = _power_law_curve(tmp_path / "curve.csv", 0.05, 300.0)
    summary = _survival(tmp_path / "out", "--hazard", curve, "--fragility", campaign,
                        "--column", "monolithic", "--fragility-form", "pga", "--age-ka", "2",
                        "--draws", "50", "--hazard-component", "rotd100")
    expected = [math.exp(-2000.0 * 1e-4 * m ** -2.5 * math.exp(0.5 * (2.5 * BETA) ** 2))
                for m in MEMBERS]
    assert summary["survival_per_parameter_set"] == pytest.approx(expected, rel=0.03)
    assert summary["survival_parameter_set_range"] == pytest.approx(
        [min(expected), max(expected)], rel=0.03)
    # the logistic form: each member's own surface, its P = 0.5 near the member's median
    surface = load_campaign_fragility(campaign, "monolithic", "pga-pgv")
    for fit, median in zip(surface.members(), MEMBERS):
        assert fit.probability(np.array([median]), np.array([0.1]))[0] == \
            pytest.approx(0.5, abs=0.05)


def test_column_campaign_without_runs_table_says_so(tmp_path):
    campaign = _column_campaign(tmp_path / "campaign", runs_table=False)
    fragility = load_campaign_fragility(campaign, "monolithic", "pga")
    assert fragility.members() is None
    assert "fragility_runs.csv" in fragility.note


def test_column_campaign_on_rotd50_from_its_records(tmp_path):
    campaign = _column_campaign(tmp_path / "campaign", records=(paper.SWEEP_RECORD,))
    fragility = load_campaign_fragility(campaign, "monolithic", "pga", component="rotd50",
                                        record_fraction=rotd50_fraction)
    measure = fragility.describe()["pga_measure"]
    f = rotd50_fraction(paper.SWEEP_RECORD)
    assert measure["fraction"] == pytest.approx(f)
    assert "computed from the motion" in measure["source"]
    # P on the hazard's PGA x is the campaign's P at x / f
    inner = Lognormal(math.sqrt(MEMBERS[0] * MEMBERS[1]), 0.5)
    x = np.array([1.0, 2.5, 6.0])
    assert fragility.probability(x) == pytest.approx(inner.probability(x / f))
    # each member's own fit is put on the same measure
    for member, median in zip(fragility.members(), MEMBERS):
        assert member.probability(np.array([median * f]))[0] == pytest.approx(0.5, abs=0.05)


# ---------------------------------------------------------------- several hazard curves
def test_quantile_curves_of_one_calculation_order_the_survival(tmp_path):
    curves = {k: load_hazard(p, 0) for k, p in CASE_37.items()}
    assert {k: c.source["kind"] for k, c in curves.items()} == {
        "mean": "mean", "0.16": "quantile-0.16", "0.5": "quantile-0.5",
        "0.84": "quantile-0.84"}
    # the files state quantile curves ordered at every level
    assert np.all(curves["0.16"].rates_per_yr <= curves["0.5"].rates_per_yr)
    assert np.all(curves["0.5"].rates_per_yr <= curves["0.84"].rates_per_yr)
    argv = ["--site", "0", "--median-g", "0.15", "--beta", "0.4", "--age-ka", "10",
            "--draws", "0"]
    summary = _survival(tmp_path / "out", *argv, *[a for k in ("mean", "0.16", "0.5", "0.84")
                                                   for a in ("--hazard", CASE_37[k])])
    rows = summary["hazard_curves"]
    assert [r["kind"] for r in rows] == ["mean", "quantile-0.16", "quantile-0.5",
                                          "quantile-0.84"]
    assert rows[0]["survival_probability"] == summary["survival_probability"]
    s = {r["kind"]: r["survival_probability"] for r in rows}
    # larger rates at every level, a larger rate of overturning: survival ordered
    assert s["quantile-0.16"] >= s["quantile-0.5"] >= s["quantile-0.84"]
    assert summary["survival_range_over_curves"] == [min(s.values()), max(s.values())]
    # the same curve given alone: the same result
    single = _survival(tmp_path / "alone", *argv, "--hazard", CASE_37["0.84"])
    assert single["survival_probability"] == pytest.approx(s["quantile-0.84"], rel=1e-12)
    assert "hazard_curves" not in single


def test_below_grid_without_a_grid_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    refused(capsys, ["survival", "--hazard", CASE_37["mean"], "--site", "0", "--median-g",
                     "0.2", "--beta", "0.4", "--age-ka", "1", "--below-grid", "zero",
                     "--out", out], "--below-grid applies to a pulse-grid", out)


def test_beside_and_above_the_grid_p_carries_the_surface_from_the_edge(tmp_path):
    """Outside the grid's PGV/PGA range and above its PGA, P follows the logistic surface
    from the nearest edge cell: continuous there, and its log-odds differ from the
    surface's by the same shift as at the edge cell (closed form); --below-grid logistic
    keeps the raw surface."""
    from scipy.special import logit

    from pipeline.hazard.fragility import Logistic
    coefficients = (1.0, 3.0, 2.0)
    path = _grid_file(tmp_path / "f.json", [0.2, 0.4, 0.8], [0.1, 0.3],
                      lambda a: {0.2: 0.25, 0.4: 0.6, 0.8: 0.9}[round(a / G, 6)], uplift_g=0.1)
    data = json.loads(path.read_text())
    data["pulse_grid"]["models"]["monolithic"]["logistic"]["coefficients"] = dict(
        zip(("b0", "b1", "b2"), coefficients))
    path.write_text(json.dumps(data))
    grid = load_campaign_fragility(path)
    surface = Logistic(coefficients)
    a = np.full(3, 0.4 * G)
    # beside: PGV/PGA just inside and just outside the lower edge 0.1 s meet
    inside, outside = grid.probability(a[:2], np.array([0.1, 0.0999]))
    assert outside == pytest.approx(inside, abs=1e-3)
    # far beside: the edge cell's log-odds plus the surface's change from the edge
    for ratio in (0.03, 1.0):
        edge_ratio = 0.1 if ratio < 0.1 else 0.3
        expected = logit(0.6) + (logit(surface.probability(0.4 * G, ratio))
                                 - logit(surface.probability(0.4 * G, edge_ratio)))
        assert logit(grid.probability(0.4 * G, ratio)) == pytest.approx(expected, abs=1e-6)
    # above the grid's last PGA, from the 0.8 g cell
    expected = logit(0.9) + (logit(surface.probability(1.6 * G, 0.2))
                             - logit(surface.probability(0.8 * G, 0.2)))
    assert logit(grid.probability(1.6 * G, 0.2)) == pytest.approx(expected, abs=1e-6)
    raw = load_campaign_fragility(path, below="logistic")
    assert raw.probability(0.4 * G, 0.03) == pytest.approx(surface.probability(0.4 * G, 0.03))
