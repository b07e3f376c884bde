"""What a site's columns say when their damage states were seen: the likelihood of each
column's range of states under fragilities per damage state, against closed forms of
lognormal fragilities (docs/survival.md)."""
import json
import math

import numpy as np
import pytest
from scipy import stats

from pipeline.cli import main
from pipeline.files import InputError
from pipeline.hazard.damage_states import STATES, StateFragility
from pipeline.hazard.fragility import Lognormal
from pipeline.hazard.site_motion import motion_bound
from pipeline.outcome.damage import DamageState

DROP = 0.5 * stats.chi2.ppf(0.95, 1)
G = 9.80665


def lognormals(medians, beta):
    """A StateFragility of lognormals (m/s^2) for slight, moderate, severe, collapse
    (None: not given)."""
    return StateFragility(tuple(None if m is None else Lognormal(m, beta) for m in medians))


def test_the_states_are_those_of_the_damage_measures():
    assert STATES == tuple(s.label for s in DamageState)


@pytest.mark.parametrize("n", [1, 3])
def test_columns_seen_in_one_state_bound_the_pga_about_the_geometric_mean(n):
    # L = (Phi(z_moderate) - Phi(z_severe))^n, z_k = ln(a / m_k) / beta: symmetric in
    # ln a about (ln m2 + ln m3) / 2, so the maximum is sqrt(m2 m3) and the interval's
    # ends lie symmetric about it in ln a (lo hi = ML^2)
    m2, m3, beta = 2.0, 5.0, 0.4
    fragility = lognormals((1.0, m2, m3, 9.0), beta)
    result = motion_bound([fragility] * n, [(2, 2)] * n)
    ml = math.sqrt(m2 * m3)
    assert result["pga_ml_m_s2"] == pytest.approx(ml, rel=1e-6)
    lo, hi = result["pga_interval95_m_s2"]
    assert lo * hi == pytest.approx(ml ** 2, rel=1e-6)

    def ll(a):
        z = np.log(a / np.array([m2, m3])) / beta
        return n * math.log(stats.norm.cdf(z[0]) - stats.norm.cdf(z[1]))
    for end in (lo, hi):
        assert ll(ml) - ll(end) == pytest.approx(DROP, abs=1e-6)
    assert result["note"] is None and result["fallen"] == 0
    assert result["column_states"] == [{"lowest": "moderate", "highest": "moderate"}] * n


def test_a_standing_column_at_least_slight_is_bounded_between_slight_and_collapse():
    # drums seen shifted: at least slight, standing: L = Phi(z_slight) - Phi(z_collapse),
    # maximal at sqrt(m1 m4) for lognormals of one beta
    m1, m4, beta = 1.5, 6.0, 0.5
    result = motion_bound([lognormals((m1, None, None, m4), beta)], [(1, 3)])
    assert result["pga_ml_m_s2"] == pytest.approx(math.sqrt(m1 * m4), rel=1e-6)
    lo, hi = result["pga_interval95_m_s2"]
    assert lo < math.sqrt(m1 * m4) < hi


def test_fell_and_stands_are_collapse_and_the_states_below_it():
    collapse = Lognormal(3.0, 0.4)
    plain = motion_bound([collapse] * 4, [True, False, False, True])
    ranged = motion_bound([StateFragility.toppling(collapse)] * 4,
                          [(4, 4), (0, 3), (0, 3), (4, 4)])
    assert plain == ranged
    assert plain["column_states"][1] == {"lowest": "none", "highest": "severe"}


def test_crossing_fragilities_give_no_negative_probability():
    # a slight state of wide beta runs below the moderate one's at small PGA: P(DS >=
    # slight) is the larger of the two, so P(slight) = P(>= slight) - P(>= moderate) >= 0
    fragility = StateFragility((Lognormal(1.0, 1.5), Lognormal(2.0, 0.2), None,
                                Lognormal(8.0, 0.3)))
    pga = np.geomspace(1e-3, 1e3, 400)
    wide, narrow = Lognormal(1.0, 1.5).probability(pga), Lognormal(2.0, 0.2).probability(pga)
    assert np.any(wide < narrow)                       # they do cross
    np.testing.assert_array_equal(fragility.at_least(1, pga), np.maximum(wide, narrow))
    assert np.all(fragility.probability(1, 1, pga) >= 0.0)
    assert np.all(fragility.at_least(0, pga) == 1.0)


def test_a_fragility_per_state_holds_four_states_and_collapse():
    with pytest.raises(InputError, match="needs 4 entries"):
        StateFragility((Lognormal(1.0, 0.4),) * 3)
    with pytest.raises(InputError, match="needs the collapse one"):
        StateFragility((Lognormal(1.0, 0.4),) * 3 + (None,))


def test_a_state_without_its_fragility_is_refused():
    with pytest.raises(InputError, match="state 'severe'") as caught:
        motion_bound([lognormals((1.0, 2.0, None, 9.0), 0.4)], [(2, 2)])
    assert "\n" not in str(caught.value)


# ---------------------------------------------------------------- the command
def _site(path, columns):
    path.write_text(json.dumps({"sites": [{"name": "A", "east_km": 0, "north_km": 0,
                                           "columns": columns}]}))
    return path


def test_survival_reads_the_states_and_their_stated_fragilities(tmp_path):
    obs = _site(tmp_path / "obs.json", [
        {"column": "drums", "state": "standing", "damage_state": "moderate"},
        {"column": "drums", "state": "standing", "residual_slide_m": 0.03,
         "base_width_m": 1.0}])                      # 0.03 D: moderate at least
    out = tmp_path / "out"
    assert main(["survival", "--observations", str(obs), "--median-g", "0.8", "--beta",
                 "0.4", "--state-lognormal", "moderate,0.2,0.4", "--state-lognormal",
                 "severe,0.4,0.4", "--out", str(out)]) == 0
    result = json.loads((out / "site_motion.json").read_text())
    assert result["column_states"] == [{"lowest": "moderate", "highest": "moderate"},
                                       {"lowest": "moderate", "highest": "severe"}]
    # L = (Phi(z2) - Phi(z3)) (Phi(z2) - Phi(z4)), its maximum found here independently
    a = np.geomspace(0.05, 2.0, 200001)
    z = [np.log(a / m) / 0.4 for m in (0.2, 0.4, 0.8)]
    ll = np.log(stats.norm.cdf(z[0]) - stats.norm.cdf(z[1])) + \
        np.log(stats.norm.cdf(z[0]) - stats.norm.cdf(z[2]))
    assert result["pga_ml_g"] == pytest.approx(a[np.argmax(ll)], rel=1e-4)
    assert set(result["state_fragilities"]["drums"]) == {"moderate", "severe"}
    assert result["fragilities"]["drums"]["median_m_s2"] == pytest.approx(0.8 * G)


@pytest.mark.parametrize("columns, extra, message", [
    ([{"column": "drums", "state": "standing", "damage_state": "moderate"}],
     ["--state-lognormal", "moderate,0.2,0.4"], "needs the fragility of damage state "
     "'severe'"),
    ([{"column": "drums", "state": "standing"}], ["--state-lognormal", "collapse,0.2,0.4"],
     "one of slight, moderate, severe"),
    ([{"column": "drums", "state": "standing"}],
     ["--state-lognormal", "slight,0.3,0.4", "--state-lognormal", "moderate,0.2,0.4"],
     "the median of moderate"),
    ([{"column": "drums", "state": "standing"}], ["--state-lognormal", "slight,0.3"],
     "STATE,MEDIAN_G,BETA"),
    ([{"column": "drums", "state": "standing"}], ["--state-lognormal", "slight,0.3,9"],
     "beta 9 outside"),
])
def test_survival_refuses_bad_states_in_one_line(tmp_path, capsys, columns, extra, message):
    out = tmp_path / "out"
    argv = ["survival", "--observations", str(_site(tmp_path / "obs.json", columns)),
            "--median-g", "0.8", "--beta", "0.4", "--out", str(out)] + extra
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_state_lognormal_needs_observations(capsys):
    assert main(["survival", "--state-lognormal", "slight,0.3,0.4", "--median-g", "0.8",
                 "--beta", "0.4", "--hazard", "x.csv", "--age-ka", "1"]) == 2
    assert "--state-lognormal applies with --observations" in capsys.readouterr().err
