"""Ages as they are dated: each survival E[exp(-r T)] against numerical integration over
the age's distribution (scipy quad), and the bad ages refused in one line."""
import json
import math

import numpy as np
import pytest
from scipy import integrate, stats

from pipeline.files import InputError
from pipeline.hazard.ages import (AgeKind, AgeSamples, LowerBound, TruncatedNormal,
                                  UniformInterval, load_age_samples)
from pipeline.hazard.survival import survival_probability

RATES = (0.0, 1e-6, 3e-5, 1e-4, 1e-3)     # 1/yr


def _expectation(density, lo, hi, rate):
    value, _ = integrate.quad(lambda t: math.exp(-rate * t) * density(t), lo, hi,
                              epsabs=0, epsrel=1e-12, limit=200)
    return value


@pytest.mark.parametrize("rate", RATES)
def test_interval_under_a_constant_rate_matches_its_closed_form(rate):
    age = UniformInterval(13_000.0, 22_000.0)           # deglaciation, 13-22 ka
    numeric = _expectation(lambda t: 1 / 9_000.0, 13_000.0, 22_000.0, rate)
    assert float(age.survival(rate)) == pytest.approx(numeric, rel=1e-10, abs=1e-300)


@pytest.mark.parametrize("rate", RATES)
def test_truncated_normal_matches_numerical_integration(rate):
    mu, s = 10_000.0, 6_000.0                          # truncation at 0 matters here
    law = stats.truncnorm(-mu / s, np.inf, loc=mu, scale=s)
    numeric = _expectation(law.pdf, 0.0, mu + 40 * s, rate)
    age = TruncatedNormal(mu, s)
    assert float(age.survival(rate)) == pytest.approx(numeric, rel=1e-8, abs=1e-300)
    assert float(age.survival(rate)) == pytest.approx(     # the scalar code's formula
        float(survival_probability(rate, mu, s)), rel=1e-12)


def test_lower_bound_bounds_every_age_at_least_that_old():
    bound = LowerBound(10_500.0)                        # ">10.5 ka"
    rates = np.array(RATES)
    np.testing.assert_allclose(bound.survival(rates), np.exp(-rates * 10_500.0), rtol=1e-14)
    for other in (UniformInterval(10_500.0, 11_000.0), UniformInterval(10_500.0, 50_000.0),
                  AgeSamples((10_500.0, 12_000.0, 40_000.0))):
        assert np.all(other.survival(rates) <= bound.survival(rates) * (1 + 1e-12))


def test_samples_are_averaged_and_converge_to_the_distribution():
    """Samples at the midpoints of n equal slices of an interval: their mean tends to the
    interval's closed form as 1/n^2 (the midpoint rule)."""
    rate, lo, hi = 1e-4, 13_000.0, 22_000.0
    exact = float(UniformInterval(lo, hi).survival(rate))
    errors = []
    for n in (10, 20):
        mids = lo + (np.arange(n) + 0.5) * (hi - lo) / n
        errors.append(abs(float(AgeSamples(tuple(mids)).survival(rate)) - exact))
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.01)
    samples = AgeSamples((1_000.0, 3_000.0))
    np.testing.assert_allclose(samples.survival(np.array([1e-4, 1e-3])),
                               [0.5 * (math.exp(-0.1) + math.exp(-0.3)),
                                0.5 * (math.exp(-1.0) + math.exp(-3.0))])


def test_degenerate_ages_are_the_known_age():
    rate = 2e-4
    for age in (UniformInterval(5_000.0, 5_000.0), TruncatedNormal(5_000.0, 0.0),
                AgeSamples((5_000.0,)), LowerBound(5_000.0)):
        assert float(age.survival(rate)) == pytest.approx(math.exp(-1.0), rel=1e-14)
    assert float(UniformInterval(0.0, 10.0).survival(0.0)) == 1.0


def test_every_kind_describes_itself():
    kinds = {age.kind for age in (LowerBound(1.0), UniformInterval(1.0, 2.0),
                                  AgeSamples((1.0,)), TruncatedNormal(1.0, 0.5))}
    assert kinds == set(AgeKind)
    assert UniformInterval(1.0, 2.0).describe().kind is AgeKind.INTERVAL


@pytest.mark.parametrize("make, message", [
    (lambda: UniformInterval(22_000.0, 13_000.0), "age interval upside down"),
    (lambda: UniformInterval(-1.0, 13_000.0), "lower end must be 0 to"),
    (lambda: LowerBound(math.nan), "lower bound on the age must be"),
    (lambda: TruncatedNormal(10.0, -1.0), "sd must be"),
    (lambda: TruncatedNormal(0.0, 1.0), "mean 0 with a spread"),
    (lambda: AgeSamples(()), "no age samples"),
    (lambda: AgeSamples((1.0, math.inf)), "age sample 2"),
    (lambda: LowerBound(True), "must be 0 to"),
])
def test_bad_ages_get_one_line(make, message):
    with pytest.raises(InputError, match=message):
        make()


def test_samples_from_a_file_column(tmp_path):
    path = tmp_path / "ages.csv"
    path.write_text("# exposure ages of rock 7\nsample,age_ka\n1,12.5\n2,13.0\n3,14.25\n")
    ages = load_age_samples(path, "age_ka", scale_to_yr=1000.0)
    assert ages.ages_yr == (12_500.0, 13_000.0, 14_250.0)
    with pytest.raises(InputError, match="no column 'age'"):
        load_age_samples(path, "age")
    path.write_text("age_ka\n12.5\nabout 13\n")
    with pytest.raises(InputError, match="data row 2, column age_ka: not a number"):
        load_age_samples(path, "age_ka")
    path.write_text("age_ka\n")
    with pytest.raises(InputError, match="no age samples"):
        load_age_samples(path, "age_ka")


@pytest.mark.parametrize("age", [UniformInterval(13_000.0, 22_000.0),
                                 TruncatedNormal(10_000.0, 6_000.0),
                                 AgeSamples((9_000.0, 12_000.0, 30_000.0)),
                                 LowerBound(10_500.0)])
def test_drawn_ages_average_to_the_closed_form(age):
    """A Monte Carlo over drawn ages (as a set of several specimens needs) gives each
    kind's closed form within its standard error."""
    rate = 1e-4
    survival = np.exp(-rate * age.draw(40_000, np.random.default_rng(7)))
    error = survival.std(ddof=1) / math.sqrt(survival.size)
    assert survival.mean() == pytest.approx(float(age.survival(rate)), abs=4 * error + 1e-15)


@pytest.mark.parametrize("age", [LowerBound(1e4), UniformInterval(1.3e4, 2.2e4),
                                 AgeSamples((1e4, 2e4, 4e4), "a file"),
                                 TruncatedNormal(1.5e4, 3e3)])
def test_an_age_described_reads_back_as_written(age):
    """Each kind's description is written with the keys of its kind only, and read back
    from its JSON to the same description."""
    described = age.describe()
    data = json.loads(json.dumps(described.as_json()))
    assert data["kind"] == age.kind.value and list(data)[-1] == "survival"
    assert type(described).from_json(data) == described
