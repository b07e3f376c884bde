"""The member study on toy tables: observations never from likelihood members, the same
draws for every likelihood size, and a sharper direction density narrowing the arcs."""
import dataclasses

import numpy as np

from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.study import member_study, split_for_study
from pipeline.inversion.study_summary import placement_summary, study_answer, study_summary, warning_rates


def test_observations_come_from_members_no_likelihood_uses(make_away_table):
    table = make_away_table(members=20)
    usable, pool = split_for_study(table, observation_members=6)
    assert list(pool.members) == list(range(14, 20))
    assert not set(usable.members) & set(pool.members)


def test_more_likelihood_members_narrow_the_arc_on_the_same_draws(make_away_table):
    table = make_away_table(members=40, scatter_deg=25.0, p_fall=(1.0, 0.8, 0.6, 0.4))
    grid = CandidateGrid(radius_km=22, step_km=1.5, strike_step_deg=30)
    trials = member_study(table, grid, likelihood_members=(3, 24, 48), observation_members=16,
                          trials=4, likelihoods=("independent",), fallen_per_site=(1, 10),
                          site_counts=(1,))
    assert sorted(trials["likelihood_members"].unique()) == [3, 24]     # 48 does not fit
    a = trials[trials["likelihood_members"] == 3].set_index(["fallen_per_site", "trial"])
    b = trials[trials["likelihood_members"] == 24].set_index(["fallen_per_site", "trial"])
    for key in ("strike_deg", "true_back_azimuth_deg", "standing_observed", "slice"):
        assert (a[key] == b[key]).all()                  # the draws do not depend on L
    summary = study_summary(trials)
    # the arcs given (a warning that the source may lie beyond gives no direction)
    given = trials[(trials["fallen_per_site"] == 10) & ~trials["reach_warning"].astype(bool)]
    widths = given.groupby("likelihood_members")["width95_deg"].median()
    assert widths[24] < widths[3]
    assert np.allclose(summary["p_true_mw_median"], 1.0)   # one magnitude in the table
    answer = study_answer(summary)
    assert set(answer) == {"independent"} and "24 members per node" in answer["independent"]


def test_the_answer_names_the_fewest_columns_that_bound_or_narrow():
    import pandas as pd
    rows = []
    for size, coverage in ((3, 0.55), (48, 0.88)):
        for sites, fallen, width in ((1, 30, 150.0), (3, 10, 55.0), (3, 30, 20.0)):
            calibrated = size == 48 and (sites, fallen) == (3, 10) and coverage > 0
            rows.append({"likelihood": "independent", "likelihood_members": size,
                         "sites": sites, "fallen_per_site": fallen,
                         "fallen_total": sites * fallen, "width_median_deg": width,
                         "coverage_back_azimuth_95": 0.93 if calibrated else coverage,
                         "coverage_ci95": (0.89, 0.96) if calibrated else (0.83, 0.92),
                         "calibrated": calibrated, "credible_area_95_km2_median": 4.0,
                         "coverage_distance_95": 0.9,
                         "coverage_epicentre_95": 0.8, "coverage_mw_95": 1.0})
    summary = pd.DataFrame(rows)
    bound = study_answer(summary)["independent"]
    assert "48 members per node: 3 site(s) with 10 fallen column(s) each bound" in bound
    assert "(20 deg, coverage 0.55 with 3 members)" in bound
    summary["calibrated"] = False
    narrow = study_answer(summary)["independent"]
    assert "no tested configuration bounds" in narrow
    assert "3 site(s) x 10 fallen narrow the median 95 % arc to 55 deg" in narrow


def test_the_rows_do_not_depend_on_the_processes(make_away_table):
    """Two processes give the same trials, row for row, as one (each trial's draws are
    seeded by S, K and the trial), and progress reports every configuration."""
    table = make_away_table(members=24, scatter_deg=20.0, p_fall=(1.0, 0.8, 0.6, 0.4))
    grid = CandidateGrid(radius_km=22, step_km=2, strike_step_deg=30)
    kwargs = dict(likelihood_members=(3, 6), observation_members=16, trials=2,
                  fallen_per_site=(1, 3), site_counts=(1,))
    done = []
    one = member_study(table, grid, jobs=1, **kwargs)
    two = member_study(table, grid, jobs=2, progress=lambda *c: done.append(c), **kwargs)
    assert len(one) > 0
    assert one.equals(two)
    assert done == [("independent", 3), ("independent", 6), ("predictive", 3),
                    ("predictive", 6)]



def test_member_study_command_on_a_table_file(make_away_table, tmp_path, capsys):
    """invert --member-study --table FILE: no YADE, the four files, the answer printed."""
    import json

    from pipeline import cli
    table = make_away_table(members=24, scatter_deg=20.0, p_fall=(1.0, 0.8, 0.6, 0.4))
    table = dataclasses.replace(table, info={**table.info, "runs": 1536, "yade_wall_s": 7200.0,
                                             "code_version": "0123abcd"})
    path = tmp_path / "forward_table_toy.npz"
    table.save(path)
    out = tmp_path / "inversion" / "member-study"
    assert cli.main(["invert", "--member-study", "--table", str(path), "--out", str(out),
                     "--trials", "2", "--radius", "22", "--step", "2"]) == 0
    for name in ("member_study.csv", "member_study_summary.csv", "member_study.png",
                 "member_study_source.png"):
        assert (out / name).stat().st_size > 0
    result = json.loads((out / "member_study.json").read_text())
    assert result["likelihood_members"] == [3, 6]          # 24 - 16 observed: 8 usable
    assert set(result["answer"]) == {"independent", "predictive"}
    assert set(result["beyond_hypothesis"]) == {"independent", "predictive"}
    assert "members per node" in capsys.readouterr().out
    assert cli.main(["invert", "--member-study", "--demo"]) == 2
    from pipeline.report import member_study_section
    section = member_study_section(tmp_path)
    assert result["answer"]["predictive"] in section and "member_study.png" in section
    assert "member_study_source.png" in section
    assert "distance covered or warned" in section and "between the rings" in section
    assert "By where the source lies" in section and (out / "member_study_placements.csv"
                                                      ).stat().st_size > 0
    fractions = [s["fraction"] for s in result["toppled_fraction_by_slice"]]
    assert len(fractions) == len(table.slices) and all(0 < f < 1 for f in fractions)
    assert f"Mw {table.slices[0]['mw']:g}" in section and "Columns toppled in the table" in section
    # the table's provenance, and that it came from another version of the model code
    assert "The forward table: 1536 runs, 2.0 h of YADE time, read from " \
           "`forward_table_toy.npz`, model code 0123abcd (this checkout's is" in section


def test_truths_lie_off_the_likelihoods_nodes_too(make_away_table):
    """Strikes between the candidates' steps; sites between the likelihood table's rings
    (its inner rings 5 and 10 km left out), beyond its last ring (20 km left out: the
    source lies beyond the reach, and the inversion says so) and just beyond it (every
    site between 10 and 15 km)."""
    table = make_away_table(members=24, scatter_deg=20.0, p_fall=(1.0, 0.8, 0.6, 0.4))
    grid = CandidateGrid(radius_km=22, step_km=2, strike_step_deg=30)
    rows = member_study(table, grid, likelihood_members=(6,), observation_members=16,
                        trials=8, likelihoods=("independent",), fallen_per_site=(3,),
                        site_counts=(1, 3))
    # one magnitude per mechanism: no source between magnitudes
    assert set(rows["placement"]) == {"node", "between", "between_spokes", "beyond",
                                      "just_beyond"}
    assert (rows["strike_deg"] % 30 != 0).all()
    distances = rows["site_distances_km"].str.split().apply(lambda d: [float(v) for v in d])
    between = rows["placement"] == "between"
    assert all(set(d) <= {5.0, 10.0} for d in distances[between])
    beyond = rows["placement"] == "beyond"
    assert all(d[0] == 20.0 for d in distances[beyond])
    just = rows["placement"] == "just_beyond"
    assert all(10.0 < min(d) and max(d) <= 15.0 for d in distances[just])
    assert (rows.loc[just, "sites_beyond"] == rows.loc[just, "sites"]).all()
    assert not rows.loc[beyond | just, "within_reach"].any()
    # a warning gives no direction (the toy's likelihood members all fall at every ring,
    # so the falls cannot tell the distance and the warning need not come: the study
    # counts its hits; tests/inversion/test_reach.py checks one by construction)
    warned = rows["reach_warning"].astype(bool) & ~rows["no_candidate"].astype(bool)
    assert (rows.loc[warned, "width95_deg"] == 360.0).all()
    assert rows.loc[~(beyond | just), "within_reach"].all()
    summary = study_summary(rows)
    for column in ("coverage_distance_95", "coverage_epicentre_95_or_warned",
                   "coverage_distance_95_or_warned", "beyond_reach_warned",
                   "warned_within_reach", "coverage_back_azimuth_95_between"):
        assert column in summary
    assert summary["beyond_reach_warned"].between(0.0, 1.0).all()
    placements = placement_summary(rows).set_index("placement")
    assert placements.loc["beyond the reach", "trials"] == (beyond | just).sum()
    assert placements.loc["beyond the reach", "reach_warning"] == \
        rows.loc[beyond | just, "reach_warning"].mean()
    well = rows["within_reach"].astype(bool) & ~rows["at_reach_edge"].astype(bool)
    for placement in ("node", "between", "between_spokes"):
        part = (rows["placement"] == placement) & well
        if part.any():
            assert placements.loc[f"{placement}, well within the reach", "trials"] == \
                part.sum()
    # the fit check's warnings are among the warnings given
    assert (rows["fit_warning"].astype(bool) <= rows["reach_warning"].astype(bool)).all()
    rates = warning_rates(placement_summary(rows))["independent"]
    assert {"hit_fit_rate", "false_alarm_fit_rate"} <= set(rates)
    assert rates["hit_rate"] == placements.loc["beyond the reach", "reach_warning"]
    assert set(rates) >= {"false_alarm_rate", "hit_rate", "false_alarm_rate_ci95"}
    # the test of the sources beyond: its warnings are among the warnings given, and the
    # rates per number of sites are those of the trials with that many sites
    assert (rows["beyond_warning"].astype(bool) <= rows["reach_warning"].astype(bool)).all()
    assert {"hit_beyond_test_rate", "false_alarm_beyond_test_rate"} <= set(rates)
    for n, by in rates["by_sites"].items():
        part = (beyond | just) & (rows["sites"] == int(n))
        if part.any():
            assert by["hit_trials"] == part.sum()
            assert by["hit_rate"] == rows.loc[part, "reach_warning"].astype(bool).mean()
    assert (summary["trials_node"] + summary["trials_between"] + summary["trials_beyond"]
            + summary["trials_between_spokes"] + summary["trials_just_beyond"]
            == summary["trials"]).all()
    # between spokes: the first site from the source halfway between the kept spokes
    spokes = rows[rows["placement"] == "between_spokes"]
    from_strike = (spokes["true_back_azimuth_deg"] + 180.0 - spokes["strike_deg"]) % 360.0
    assert np.allclose((from_strike + 1e-6) % 60.0, 30.0 + 1e-6, atol=1e-6)


def test_the_shell_beyond_the_reach_is_summed_by_sites_and_sites_beyond():
    """Hand-made trials: beyond the reach a refusal counts as covered, a region holding
    the truth too, and the rest not; well within, P(beyond) is averaged without the
    refusals; only the largest likelihood size counts."""
    import pandas as pd

    from pipeline.inversion.study_summary import beyond_hypothesis
    base = {"likelihood": "predictive", "likelihood_members": 48, "at_reach_edge": False,
            "mw_in_95": True, "placement": "node"}
    rows = [  # beyond the reach, 3 sites: 1 beyond (held), 1 beyond (missed), 2 (refused)
        {**base, "within_reach": False, "sites": 3, "sites_beyond": 1, "no_candidate": False,
         "distance_in_95": True, "epicentre_in_95": True, "p_beyond": 0.8,
         "beyond_in_95": True},
        {**base, "within_reach": False, "sites": 3, "sites_beyond": 1, "no_candidate": False,
         "distance_in_95": False, "epicentre_in_95": False, "p_beyond": 0.01,
         "beyond_in_95": False, "mw_in_95": False},
        {**base, "within_reach": False, "sites": 3, "sites_beyond": 2, "no_candidate": True,
         "distance_in_95": False, "epicentre_in_95": False, "p_beyond": float("nan"),
         "beyond_in_95": False, "mw_in_95": False},
        # just beyond, 3 sites, all 3 beyond: held
        {**base, "placement": "just_beyond", "within_reach": False, "sites": 3,
         "sites_beyond": 3, "no_candidate": False, "distance_in_95": True,
         "epicentre_in_95": True, "p_beyond": 0.3, "beyond_in_95": True},
        # well within, 3 sites: P(beyond) 0.02 and 0.04, and a refusal (left out)
        {**base, "within_reach": True, "sites": 3, "sites_beyond": 0, "no_candidate": False,
         "distance_in_95": True, "epicentre_in_95": True, "p_beyond": 0.02,
         "beyond_in_95": False},
        {**base, "within_reach": True, "sites": 3, "sites_beyond": 0, "no_candidate": False,
         "distance_in_95": True, "epicentre_in_95": False, "p_beyond": 0.04,
         "beyond_in_95": True},
        # a smaller likelihood size: not counted
        {**base, "likelihood_members": 3, "within_reach": True, "sites": 3, "sites_beyond": 0,
         "no_candidate": False, "distance_in_95": False, "epicentre_in_95": False,
         "p_beyond": 0.9, "beyond_in_95": True}]
    out = beyond_hypothesis(pd.DataFrame(rows))["predictive"]
    assert out["likelihood_members"] == 48
    pooled = out["beyond"]["3"]["all"]
    assert pooled["trials"] == 4 and pooled["refused"] == 1 / 4
    assert pooled["coverage_distance_95"] == 3 / 4 and pooled["coverage_mw_95"] == 3 / 4
    assert pooled["p_beyond_mean"] == (0.8 + 0.01 + 0.3) / 3     # the refusal left out
    just = out["just_beyond"]["3"]
    assert set(just) == {"all", "3"} and just["all"]["trials"] == 1
    assert just["3"]["p_beyond_mean"] == 0.3 and just["3"]["coverage_epicentre_95"] == 1.0
    assert out["beyond"]["3"]["1"]["coverage_epicentre_95"] == 0.5
    assert out["beyond"]["3"]["2"]["coverage_epicentre_95"] == 1.0
    well = out["well_within"]["3"]
    assert well["trials"] == 2 and well["p_beyond_mean"] == 0.03
    assert well["beyond_in_95"] == 0.5 and well["coverage_epicentre_95"] == 0.5


def test_just_beyond_sites_lie_between_the_reach_and_one_and_a_half_times_it():
    """Sources just beyond a 10 km reach, the pool's rings 10 and 20 km about them: every
    site between 10 and 15 km (JUST_BEYOND_FACTOR x 10), the first the nearest, on the
    first's node azimuth or a neighbour, turned by the strike; each column from the 20 km ring's members with the
    site's log-distance weight ln(r / 10) / ln 2 (the toy's 10 km members fall toward the
    node azimuth, its 20 km members away from it)."""
    import math

    from pipeline.inversion.study import JUST_BEYOND_FACTOR, just_beyond_sites
    from pipeline.inversion.table import ForwardTable
    from tests.inversion.conftest import AZIMUTHS, DISTANCES, SLICES
    falls = [[[[[float((theta + (180.0 if r == 20.0 else 0.0)) % 360.0)] * 4
                for _ in range(2)] for theta in AZIMUTHS] for r in DISTANCES]
             for _ in SLICES]
    pool = ForwardTable.toy(SLICES, DISTANCES, AZIMUTHS, falls)
    assert JUST_BEYOND_FACTOR == 1.5
    far, near, weights = 0, 0, 0.0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        strike = float(rng.uniform(0.0, 360.0))
        sites = just_beyond_sites(pool, 0, 10.0, strike, 3, 40, rng)
        r = [math.hypot(e, n) for _, e, n, _ in sites]
        assert all(10.0 < d <= 15.0 + 1e-9 for d in r) and r == sorted(r)
        first = None
        for (_, e, n, cols), d in zip(sites, r):
            node = (math.degrees(math.atan2(e, n)) - strike) % 360.0
            assert min(abs(node - a) % 360.0 for a in AZIMUTHS) < 1e-6
            first = node if first is None else first
            # the first site's node azimuth or a neighbour (the toy's spokes 30 deg apart)
            assert min((node - first) % 360.0, (first - node) % 360.0) < 30.0 + 1e-6
            turned = [(c.downfall_azimuth_deg - strike - node + 90.0) % 360.0 for c in cols]
            assert len(cols) == 40 and all(c.fallen for c in cols)
            far += sum(t > 180.0 for t in turned)  # fell away from the node azimuth
            near += sum(t <= 180.0 for t in turned)
            weights += 40 * math.log(d / 10.0) / math.log(2.0)
    # 2400 columns: the share from the 20 km ring within 4 standard errors of its weight
    assert abs(far - weights) < 4.0 * math.sqrt(weights * (1 - weights / (far + near)))
    # no ring beyond the reach in the pool: no site
    assert just_beyond_sites(pool, 0, 20.0, 0.0, 3, 3, np.random.default_rng(0)) is None
