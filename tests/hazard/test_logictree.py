"""A logic tree constrained by survival, against independent references: a step fragility
at one of the curves' levels (no integration error: the posterior weights in closed
form), the engine's own mean and quantile curves from its realisations, a lognormal
fragility under power-law branches (closed form), the joint survival of specimens of
differing ages, and the loader's one-line refusals (and a fuzz of the plain table)."""
import json
import math
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import integrate, stats

from pipeline import RECORDS_DIR
from pipeline.cli import main
from pipeline.files import InputError
from pipeline.hazard import load_hazard
from pipeline.hazard.ages import TruncatedNormal
from pipeline.hazard.constrain import (FLOOR, bayes, branch_rates, cell_matrix, eliminate,
                                       log_survival_fixed, log_survival_sampled,
                                       motion_at_rate, weighted_mean,
                                       weighted_quantile)
from pipeline.hazard.constrain_assess import constrain_tree
from pipeline.hazard.fragility import Fragility, Lognormal
from pipeline.hazard.logictree import LogicTree, load_logic_tree
from pipeline.hazard.set_probability import overturn_probability
from pipeline.hazard.survival import overturning_rate

CASE_11 = RECORDS_DIR / "hazard" / "openquake_logictree_case_11"
CASE_19 = RECORDS_DIR / "hazard" / "openquake_logictree_case_19"


@dataclass(frozen=True)
class Step(Fragility):
    """P(overturn | PGA) = 1 at and above ``at_m_s2``, else 0."""
    at_m_s2: float
    uses_ratio = False
    label = "step"

    def probability(self, pga_m_s2, pgv_pga_s=None):
        return (np.asarray(pga_m_s2, float) >= self.at_m_s2).astype(float)

    def draws(self, n, rng):
        return None

    def describe(self):
        return {"form": "step", "at_m_s2": self.at_m_s2}


def _power_law_tree(ks, exponent, lo, hi, n=40, weights=None):
    """Branches lambda_i(x) = k_i x^-exponent (x in m/s^2) at n common levels."""
    levels = np.geomspace(lo, hi, n)
    rates = np.array([k * levels ** -exponent for k in ks])
    w = np.full(len(ks), 1.0 / len(ks)) if weights is None else np.asarray(weights, float)
    return LogicTree(tuple(str(k) for k in range(len(ks))), tuple(f"b{k}" for k in
                                                                   range(len(ks))),
                     w, levels, rates)


def _set_rates(tree, cells, fragilities):
    """The rates of each of a list of sets (tuples of indices into ``fragilities``)."""
    def rates(members):
        chosen = [fragilities[j] for j in members]
        return branch_rates(cells, tree.levels_m_s2, tree.rates_per_yr,
                            lambda x: overturn_probability(chosen, None, x, "any_common"))
    return lambda sets: [rates(m) for m in sets]


# ---------------------------------------------------------------- (a) step fragility
def test_step_fragility_gives_the_posterior_in_closed_form():
    """A step at level x_k: lambda_ov,i = lambda_i(x_k) exactly (the cells above x_k
    telescope), P_s,i = exp(-lambda_i(x_k) t), w_i' = w_i P_s,i / sum."""
    tree = _power_law_tree([2e-4, 1e-4, 5e-5, 1e-5], 2.2, 0.2, 20.0, 25,
                           weights=[0.1, 0.4, 0.3, 0.2])
    k, age = 11, 8000.0
    step = Step(tree.levels_m_s2[k])
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    rate = _set_rates(tree, cells, [step])([(0,)])[0]
    lam = tree.rates_per_yr[:, k]
    np.testing.assert_allclose(rate, lam, rtol=1e-12)
    p = np.exp(-lam * age)
    posterior = bayes(tree.weights, log_survival_fixed(_set_rates(tree, cells, [step]), [age]))
    np.testing.assert_allclose(posterior, tree.weights * p / (tree.weights @ p), rtol=1e-10)
    kept = eliminate(tree.weights, p, 0.05)
    expected = np.where(p >= 0.05, tree.weights, 0) / tree.weights[p >= 0.05].sum()
    np.testing.assert_allclose(kept, expected, rtol=1e-12)


def test_two_ages_multiply_the_intervals():
    """Steps at x_a (younger, t1) and x_b (older, t2): -ln P = t1 lambda(min(x_a, x_b)) +
    (t2 - t1) lambda(x_b), the intervals of a Poisson process being independent."""
    tree = _power_law_tree([1e-4, 3e-5], 2.0, 0.5, 10.0, 20)
    a, b = 12, 7
    fragilities = [Step(tree.levels_m_s2[a]), Step(tree.levels_m_s2[b])]
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    t1, t2 = 3000.0, 11000.0
    got = log_survival_fixed(_set_rates(tree, cells, fragilities), [t1, t2])
    lam = tree.rates_per_yr
    np.testing.assert_allclose(got, -(t1 * lam[:, min(a, b)] + (t2 - t1) * lam[:, b]),
                               rtol=1e-12)
    swapped = log_survival_fixed(_set_rates(tree, cells, fragilities[::-1]), [t2, t1])
    np.testing.assert_allclose(swapped, got, rtol=1e-12)


def test_uncertain_differing_ages_against_quadrature():
    """Two identical steps, ages T_a, T_b independent truncated normals: P = E[exp(-lambda
    max(T_a, T_b))], by quadrature over the distribution of the maximum."""
    tree = _power_law_tree([1e-4], 2.0, 0.5, 10.0, 20)
    lam = float(tree.rates_per_yr[0, 5])
    step = Step(tree.levels_m_s2[5])
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    means, sds = np.array([8000.0, 12000.0]), np.array([3000.0, 2000.0])
    rng = np.random.default_rng(3)
    samples = np.column_stack([TruncatedNormal(m, sd).draw(4000, rng)
                               for m, sd in zip(means, sds)])
    log_p, se = log_survival_sampled(_set_rates(tree, cells, [step, step]), samples)
    dists = [stats.truncnorm(-m / s, np.inf, loc=m, scale=s) for m, s in zip(means, sds)]

    def density(t):                     # of max(T_a, T_b)
        return dists[0].pdf(t) * dists[1].cdf(t) + dists[1].pdf(t) * dists[0].cdf(t)
    expected, _ = integrate.quad(lambda t: math.exp(-lam * t) * density(t), 0, 40000,
                                 limit=200)
    assert math.exp(log_p[0]) == pytest.approx(expected, rel=4 * se[0])
    assert 0 < se[0] < 0.05


# ---------------------------------------------------------------- (b) the engine's own
def _poe(path):
    curve = load_hazard(path)
    time = curve.source["investigation_time_yr"]
    return -np.expm1(-curve.rates_per_yr * time)


def test_the_engines_mean_and_quantiles_from_its_realisations():
    """OpenQuake's logictree case 11: its mean curve (the weighted mean of probabilities of
    exceedance) and its 0.1 and 0.9 quantile curves from the three realisations and
    weights, within the 7 digits of the export."""
    tree = load_logic_tree(CASE_11)
    assert tree.branch_paths == ("b1_b2~b1", "b1_b3~b1", "b1_b4~b1")
    np.testing.assert_allclose(tree.weights, [0.2, 0.6, 0.2])
    assert tree.levels_m_s2.size == 3                     # the 1 g level has poe 0
    assert any("rates are 0" in n for n in tree.notes)
    poe = -np.expm1(-tree.rates_per_yr * tree.source["investigation_time_yr"])
    np.testing.assert_allclose(weighted_mean(poe, tree.weights),
                               _poe(CASE_11 / "hazard_curve-mean.csv"), rtol=2e-6)
    for q in ("0.1", "0.9"):
        np.testing.assert_allclose(weighted_quantile(poe, tree.weights, float(q)),
                                   _poe(CASE_11 / f"quantile_curve-{q}.csv"), rtol=2e-6)


def test_the_engines_rate_mean_of_case_19_from_its_realisations():
    """OpenQuake's logictree case 19 (use_rates = true, 50 years): its mean curve is the
    weighted mean of the 16 realisations' annual rates, not of their probabilities (these
    differ by up to 5 % here); its 0.1 and 0.9 quantiles from the realisations too; within
    the 7 digits of the export and the float32 weights of realizations_13.csv."""
    tree = load_logic_tree(CASE_19)
    assert tree.size == 16 and tree.branch_paths[15] == "A~DD"
    np.testing.assert_allclose(tree.weights[[0, 3, 15]], [0.04, 0.08, 0.16], rtol=1e-7)
    time = tree.source["investigation_time_yr"]
    assert time == 50.0
    assert tree.levels_m_s2[0] / 9.80665 == pytest.approx(0.0137)
    n = tree.levels_m_s2.size                             # the top levels' poe 0 dropped
    mean = load_hazard(CASE_19 / "hazard_curve-mean-PGA_13.csv")
    np.testing.assert_allclose(mean.levels_m_s2[:n], tree.levels_m_s2, rtol=1e-12)
    np.testing.assert_allclose(weighted_mean(tree.rates_per_yr, tree.weights),
                               mean.rates_per_yr[:n], rtol=2e-6)
    poe = -np.expm1(-tree.rates_per_yr * time)
    assert not np.allclose(weighted_mean(poe, tree.weights), _poe(CASE_19 / "hazard_curve-mean-"
                                                                   "PGA_13.csv")[:n], rtol=1e-2)
    for q in ("0.1", "0.9"):
        curve = load_hazard(CASE_19 / f"quantile_curve-{q}-PGA_13.csv")
        m = min(n, curve.levels_m_s2.size)
        np.testing.assert_allclose(weighted_quantile(tree.rates_per_yr, tree.weights,
                                                     float(q))[:m],
                                   curve.rates_per_yr[:m], rtol=2e-6)


def test_the_realizations_file_and_its_directory_are_one_tree():
    a = load_logic_tree(CASE_11)
    b = load_logic_tree(CASE_11 / "realizations.csv")
    np.testing.assert_array_equal(a.rates_per_yr, b.rates_per_yr)


# ---------------------------------------------------------------- (c) power law
@pytest.mark.parametrize("exponent, median, beta", [(2.5, 3.0, 0.5), (1.5, 1.0, 0.3)])
def test_lognormal_under_power_law_branches(exponent, median, beta):
    """lambda_i(x) = k_i x^-K, lognormal fragility: lambda_ov,i = k_i m^-K exp(K^2 beta^2 /
    2); the posterior weights from exp(-lambda_ov,i t)."""
    ks = np.array([3e-4, 1e-4, 4e-5])
    tree = _power_law_tree(ks, exponent, median * math.exp(-8 * beta),
                           median * math.exp(8 * beta), 60, weights=[0.25, 0.5, 0.25])
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    fragility = Lognormal(median, beta)
    rates = _set_rates(tree, cells, [fragility])([(0,)])[0]
    closed = ks * median ** -exponent * math.exp(exponent ** 2 * beta ** 2 / 2)
    np.testing.assert_allclose(rates, closed, rtol=2e-4)
    age = 0.5 / closed[1]
    summary, rows, _ = constrain_tree(tree, [fragility], None, [TruncatedNormal(age)], "bayes",
                                      FLOOR, 0, 0)
    p = np.exp(-closed * age)
    expected = tree.weights * p / (tree.weights @ p)
    np.testing.assert_allclose([r.posterior_bayes for r in rows], expected, rtol=1e-3)
    for k in range(tree.size):     # the same cells as survival's per-curve integration
        one = overturning_rate(tree.levels_m_s2, tree.rates_per_yr[k], fragility.probability)
        assert rates[k] == pytest.approx(one["rate_per_yr"], rel=1e-12)


def test_draws_in_one_matrix_product_equal_the_per_draw_loop(monkeypatch):
    """Fragility draws integrated at once (their cell probabilities, draws x cells, times
    the branches' cell rates, cells x branches) give each draw's rates as one matrix-vector
    product per draw does; constrain's Monte Carlo intervals, computed in chunks of draws,
    are the percentiles of the per-draw survivals of two specimens of differing ages."""
    tree = _power_law_tree([3e-4, 1e-4, 4e-5, 2e-5], 2.3, 0.3, 20.0, 30,
                           weights=[0.1, 0.4, 0.3, 0.2])
    cells = cell_matrix(tree.levels_m_s2, tree.rates_per_yr)
    first = Lognormal(3.0, 0.4, median_ci95=(2.5, 3.6), beta_ci95=(0.3, 0.5))
    second = Lognormal(5.0, 0.3, median_ci95=(4.0, 6.0))
    drawn = first.draws(25, np.random.default_rng(5))
    batched = branch_rates(cells, tree.levels_m_s2, tree.rates_per_yr,
                           lambda x: np.array([d.probability(x) for d in drawn]))
    loop = np.array([branch_rates(cells, tree.levels_m_s2, tree.rates_per_yr, d.probability)
                     for d in drawn])
    assert batched.shape == (25, tree.size)
    np.testing.assert_allclose(batched, loop, rtol=1e-12)
    monkeypatch.setattr("pipeline.hazard.constrain_assess.draw_chunk", lambda cells: 7)
    summary, _, _ = constrain_tree(tree, [first, second], None,
                                   [TruncatedNormal(3e3), TruncatedNormal(9e3)], "bayes",
                                   FLOOR, 25, 2)
    rng = np.random.default_rng(2)                  # known ages: only the draws use it
    pairs = list(zip(first.draws(25, rng), second.draws(25, rng)))
    survival = np.exp([log_survival_fixed(_set_rates(tree, cells, list(pair)),
                                          [3000.0, 9000.0]) for pair in pairs])
    np.testing.assert_allclose(summary.monte_carlo.survival_interval,
                               np.percentile(survival, (2.5, 97.5), axis=0).T, rtol=1e-12)


def test_ground_motion_at_a_rate_of_a_power_law():
    """x at which k x^-K = r: (k / r)^(1/K), exact under log-log interpolation."""
    levels = np.geomspace(0.1, 30, 15)
    rates = 1e-4 * levels ** -2.5
    assert motion_at_rate(levels, rates, 4e-4) == pytest.approx((1e-4 / 4e-4) ** (1 / 2.5),
                                                                rel=1e-12)
    assert motion_at_rate(levels, rates, 1.0) is None              # above the curve


# ---------------------------------------------------------------- (d) refusals
def _plain(tmp_path, body, name="tree.csv"):
    path = tmp_path / name
    path.write_text("# a logic tree\nbranch,weight,pga_g,annual_rate_per_yr\n" + body)
    return path


GOOD = "a,0.4,0.1,1e-2\na,0.4,0.5,1e-3\nb,0.6,0.1,2e-2\nb,0.6,0.5,3e-3\n"


@pytest.mark.parametrize("body, words", [
    ("a,0.4,0.1,1e-2\na,0.4,0.5,1e-3\nb,0.5,0.1,2e-2\nb,0.5,0.5,3e-3\n", "sum to 0.9"),
    ("a,-0.4,0.1,1e-2\na,-0.4,0.5,1e-3\nb,1.4,0.1,2e-2\nb,1.4,0.5,3e-3\n", "weight -0.4"),
    ("a,nan,0.1,1e-2\na,nan,0.5,1e-3\nb,0.6,0.1,2e-2\nb,0.6,0.5,3e-3\n", "weight nan"),
    ("a,0.4,0.1,1e-2\na,0.4,0.5,1e-3\nb,0.6,0.1,2e-2\nb,0.6,0.6,3e-3\n", "different levels"),
    ("a,0.4,0.1,1e-2\na,0.4,0.5,inf\nb,0.6,0.1,2e-2\nb,0.6,0.5,3e-3\n", "finite"),
    ("a,0.4,0.1,1e-2\na,0.4,0.5,1e-3\nb,0.6,0.1,2e-2\nb,0.6,0.5,3e-1\n", "non-monotonic"),
    ("a,0.4,0.1,1e-2\na,0.5,0.5,1e-3\nb,0.6,0.1,2e-2\nb,0.6,0.5,3e-3\n", "has weight"),
    ("a,1,0.1,1e-2\n", "at least 2"),
])
def test_plain_table_refusals(tmp_path, body, words):
    with pytest.raises(InputError) as err:
        load_logic_tree(_plain(tmp_path, body))
    assert words in str(err.value) and "\n" not in str(err.value)


def test_plain_table_reads_and_refuses_another_imt(tmp_path):
    tree = load_logic_tree(_plain(tmp_path, GOOD))
    assert tree.branch_ids == ("a", "b") and tree.rates_per_yr.shape == (2, 2)
    np.testing.assert_allclose(tree.levels_m_s2, [0.980665, 4.903325])   # 0.1, 0.5 g
    path = tmp_path / "sa.csv"
    path.write_text("branch,weight,sa(0.2)_g,annual_rate_per_yr\n" + GOOD)
    with pytest.raises(InputError, match="IMT SA"):
        load_logic_tree(path)


def test_weights_that_sum_to_one_in_decimals_are_not_noted(tmp_path):
    """Weights written to the last digit (1/3 three times, 1/500 five hundred times) sum to
    1 within the rounding of their sum: no note; 0.3333333 three times is noted."""
    for n, text, noted in [(3, repr(1 / 3), False), (500, repr(1 / 500), False),
                           (3, "0.3333333", True)]:
        rows = [f"b{i},{text},{x},{r}" for i in range(n) for x, r in ((0.1, 1e-2), (0.5, 1e-3))]
        tree = load_logic_tree(_plain(tmp_path, "\n".join(rows) + "\n", f"w{n}{noted}.csv"))
        assert any("summed to" in note for note in tree.notes) == noted
        assert tree.weights.sum() == pytest.approx(1.0, abs=1e-15)


def _copy_case(tmp_path, realizations=None, drop=None):
    for f in CASE_11.glob("*.csv"):
        if f.name != drop:
            (tmp_path / f.name).write_text(f.read_text())
    if realizations is not None:
        (tmp_path / "realizations.csv").write_text(realizations)
    return tmp_path


@pytest.mark.parametrize("realizations, drop, words", [
    ("rlz_id,branch_path,weight\n0,a,0.2\n1,b,0.6\n2,c,0.2\n3,d,0\n", None, "no PGA hazard"),
    ("rlz_id,branch_path,weight\n0,a,0.4\n1,b,0.6\n", None, "without a branch"),
    ("rlz_id,branch_path,weight\n0,a,0.2\n1,b,0.6\n1,c,0.2\n", None, "twice"),
    (None, "hazard_curve-smltp_b1_b3-gsimltp_b1.csv", "no PGA hazard curve"),
    ("rlz_id,branch_path,weight\n0,a,0.2\n1,b,0.6\n2,c,0.3\n", None, "sum to 1.1"),
])
def test_openquake_refusals(tmp_path, realizations, drop, words):
    with pytest.raises(InputError) as err:
        load_logic_tree(_copy_case(tmp_path, realizations, drop))
    assert words in str(err.value) and "\n" not in str(err.value)


def test_openquake_curves_on_different_levels(tmp_path):
    _copy_case(tmp_path)
    path = tmp_path / "hazard_curve-smltp_b1_b4-gsimltp_b1.csv"
    path.write_text(path.read_text().replace("poe-0.4000000", "poe-0.4500000"))
    with pytest.raises(InputError, match="different levels"):
        load_logic_tree(tmp_path)


# ---------------------------------------------------------------- (e) fuzz
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(st.text(alphabet=st.sampled_from("ab,.-#e0123456789 \ninfa"), max_size=200))
def test_plain_loader_fuzz(tmp_path, text):
    """Whatever the rows, the loader gives a tree or one line of InputError."""
    path = tmp_path / "fuzz.csv"
    path.write_text("branch,weight,pga_g,annual_rate_per_yr\n" + text)
    try:
        tree = load_logic_tree(path)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert abs(tree.weights.sum() - 1) < 1e-12 and np.all(tree.rates_per_yr > 0)
    assert np.all(np.diff(tree.levels_m_s2) > 0)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.floats(0.01, 1.0), min_size=1, max_size=6),
       st.lists(st.floats(1e-6, 1e-1), min_size=2, max_size=8, unique=True))
def test_plain_loader_round_trip(tmp_path, raw_weights, rates):
    """A written table is read back: weights, levels and rates as written."""
    weights = np.array(raw_weights) / sum(raw_weights)
    rates = sorted(rates, reverse=True)
    levels = np.geomspace(0.01, 2.0, len(rates))
    rows = [f"b{i},{float(w)!r},{float(x)!r},{r * (i + 1)!r}" for i, w in enumerate(weights)
            for x, r in zip(levels, rates)]
    tree = load_logic_tree(_plain(tmp_path, "\n".join(rows) + "\n", "rt.csv"))
    np.testing.assert_allclose(tree.weights, weights, rtol=1e-12)
    np.testing.assert_allclose(tree.rates_per_yr[-1], np.array(rates) * len(weights))


# ---------------------------------------------------------------- the command
def test_command_writes_its_files(tmp_path):
    out = tmp_path / "out"
    status = main(["constrain", "--logic-tree", str(CASE_11), "--median-g", "0.3", "--beta",
                   "0.4", "--median-g", "0.5", "--beta", "0.3", "--age-ka", "1", "--age-ka",
                   "3", "--draws", "20", "--out", str(out)])
    assert status == 0
    names = {p.name for p in out.iterdir()}
    assert {"branch_weights.csv", "prior_curves.csv", "constrained_curves.csv",
            "constrain.json", "constrain.png"} <= names
    summary = json.loads((out / "constrain.json").read_text())
    for key in ("branches", "rule", "prior", "posterior", "ground_motion_at_rates",
                "members", "warnings", "assumptions"):
        assert key in summary
    w = np.array([b["prior_weight"] for b in summary["branches"]])
    p = np.array([b["survival_probability"] for b in summary["branches"]])
    post = np.array([b["posterior_bayes"] for b in summary["branches"]])
    np.testing.assert_allclose(post, w * p / (w @ p), rtol=1e-9)
    assert summary["monte_carlo"] is None            # a stated fragility: no draws
    assert summary["members"] is None


def test_monte_carlo_interval_holds_the_headline():
    """Draws of a fragility with stated 95 % intervals: each branch's survival interval
    holds the survival of the estimate itself."""
    tree = load_logic_tree(CASE_11)
    fragility = Lognormal(3.0, 0.4, median_ci95=(2.5, 3.6), beta_ci95=(0.3, 0.5))
    summary, rows, _ = constrain_tree(tree, [fragility], None, [TruncatedNormal(2e3)],
                                      "bayes", FLOOR, 200, 0)
    for row in rows:
        lo, hi = row.survival_interval
        assert lo < row.survival_probability < hi
    assert summary.monte_carlo.draws == 200


@pytest.mark.parametrize("extra, words", [
    (["--age-ka", "1", "--age-ka", "2", "--age-ka", "3"], "one --age-ka per specimen"),
    (["--age-ka", "0"], "--age-ka"),
    (["--age-ka", "1", "--floor", "1"], "--floor"),
    (["--age-ka", "1", "--age-sd-ka", "-1"], "--age-sd-ka"),
    ([], "--age-ka"),
])
def test_command_refusals_write_nothing(tmp_path, capsys, extra, words):
    out = tmp_path / "out"
    status = main(["constrain", "--logic-tree", str(CASE_11), "--median-g", "0.3", "--beta",
                   "0.4", "--out", str(out)] + extra)
    assert status == 2 and not out.exists()
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err


def test_a_standing_column_reweights_power_law_branches_in_closed_form(tmp_path):
    """The archaeoseismologists' version: a column campaign's fragility.json (its
    lognormal PGA fit, median 3 m/s^2, beta 0.4, on the campaign's own PGA) and an age of
    2.5 ka under three power-law branches lambda_i(x) = k_i x^-K written as a plain table:
    lambda_ov,i = k_i m^-K exp(K^2 beta^2 / 2), w_i' = w_i exp(-lambda_ov,i t) / sum
    (the curves span 2e-3 to 900 m/s^2, so their ends hold a negligible rate)."""
    from tests.hazard.test_reader_robustness import COLUMN
    fragility = tmp_path / "fragility.json"
    fragility.write_text(json.dumps(COLUMN))
    ks, exponent, weights = (2e-3, 5e-4, 1e-4), 2.0, (0.2, 0.5, 0.3)
    levels = np.geomspace(2e-3, 900.0, 121)
    rows = ["branch,weight,pga_m_s2,annual_rate_per_yr"]
    rows += [f"b{i},{w},{float(x)!r},{float(k * x ** -exponent)!r}"
             for i, (k, w) in enumerate(zip(ks, weights)) for x in levels]
    tree = tmp_path / "tree.csv"
    tree.write_text("\n".join(rows) + "\n")
    out = tmp_path / "out"
    status = main(["constrain", "--logic-tree", str(tree), "--fragility", str(fragility),
                   "--fragility-form", "pga", "--hazard-component", "rotd100",
                   "--age-ka", "2.5", "--draws", "0", "--out", str(out)])
    assert status == 0
    summary = json.loads((out / "constrain.json").read_text())
    lam = np.array(ks) * 3.0 ** -exponent * math.exp(exponent ** 2 * 0.4 ** 2 / 2)
    p = np.exp(-lam * 2500.0)
    got = np.array([b["survival_probability"] for b in summary["branches"]])
    np.testing.assert_allclose(got, p, rtol=1e-3)
    post = np.array([b["posterior_bayes"] for b in summary["branches"]])
    w = np.array(weights)
    np.testing.assert_allclose(post, w * p / (w @ p), rtol=1e-3)


def test_a_plain_tree_above_100_g_is_refused(tmp_path):
    tree = tmp_path / "tree.csv"
    tree.write_text("branch,weight,pga_g,annual_rate_per_yr\na,1,0.1,0.01\na,1,150,1e-9\n")
    with pytest.raises(InputError, match=r"level 150 g: levels must be positive, at least 1e-06 and at most 100 g"):
        load_logic_tree(tree)


def test_a_note_shared_by_branches_is_said_once_naming_them():
    """OpenQuake's case 19: four branches (one in-slab model) end at the same level; the
    loader says it once for the four, never twice for one text."""
    notes = load_logic_tree(CASE_19).notes
    texts = [n.split(": ", 1)[1] for n in notes if n.startswith("rlz-")]
    assert len(texts) == len(set(texts))
    named = [n.split(": ", 1)[0].split(", ") for n in notes if n.startswith("rlz-")]
    assert all(len(group) == 4 for group in named)
