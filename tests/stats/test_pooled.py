"""The paper's question pooled over records, and two ensembles compared: against known
distributions, Holm's procedure by hand and the symmetry of turning every direction."""
import numpy as np
import pandas as pd

from pipeline.stats.ensemble import compare_ensembles, holm_reject
from pipeline.stats.pooled import pooled_answer, pooled_summary


def _records(rng, n_records, members, p, spread_deg=None, centre_deg=0.0):
    """Toppled flags and relative directions (deg) of ``n_records`` ensembles: falls
    uniform on the circle (``spread_deg`` None) or normal about ``centre_deg``."""
    toppled, relative = [], []
    for _ in range(n_records):
        t = rng.random(members) < p
        r = (rng.uniform(-180, 180, members) if spread_deg is None
             else rng.normal(centre_deg, spread_deg, members))
        toppled.append(t)
        relative.append(np.where(t, r, np.nan))
    return toppled, relative


def test_falls_that_ignore_the_epicentre_give_the_no_relation_values():
    toppled, relative = _records(np.random.default_rng(4), 30, 24, 0.5)
    st = pooled_answer(toppled, relative, resamples=400)["statistics"]
    for name in ("fraction_toward", "fraction_away", "fraction_transverse",
                 "radial_alignment", "polarity"):
        assert st[name]["differs"] is False, (name, st[name])
    assert st["p_toppled"]["ci95"][0] < 0.5 < st["p_toppled"]["ci95"][1]


def test_falls_toward_the_epicentre_are_found_and_bounded():
    toppled, relative = _records(np.random.default_rng(5), 10, 16, 0.7, spread_deg=15.0)
    answer = pooled_answer(toppled, relative, resamples=400)
    st = answer["statistics"]
    assert st["polarity"]["differs"] and st["polarity"]["estimate"] > 0.9  # cos 15 deg spread
    assert st["fraction_toward"]["estimate"] > 0.95
    assert st["fraction_away"]["estimate"] == 0.0
    assert answer["falls"] == sum(int(t.sum()) for t in toppled)


def test_records_that_disagree_widen_the_interval_beyond_the_members():
    """Half the records fall toward, half away: each record alone is sure of its side, the
    pooled polarity is near 0 and its interval (records drawn again) is wide."""
    rng = np.random.default_rng(6)
    toward = _records(rng, 4, 20, 1.0, spread_deg=5.0, centre_deg=0.0)
    away = _records(rng, 4, 20, 1.0, spread_deg=5.0, centre_deg=180.0)
    st = pooled_answer(toward[0] + away[0], toward[1] + away[1], resamples=400)["statistics"]
    lo, hi = st["polarity"]["ci95"]
    assert lo < 0.0 < hi and hi - lo > 0.8
    assert st["radial_alignment"]["estimate"] > 0.95 and st["radial_alignment"]["differs"]


def test_turning_every_direction_and_back_azimuth_leaves_the_answer():
    rng = np.random.default_rng(7)
    rows = []
    for r in range(6):
        back = rng.uniform(0, 360)
        for m in range(-1, 10):
            for column in ("drums", "monolithic"):
                fell = bool(rng.random() < 0.6)
                rows.append({"record_id": f"R{r}", "member": m, "column": column,
                             "toppled": fell, "back_azimuth_deg": back,
                             "downfall_azimuth_deg": (back + rng.normal(30, 40)) % 360
                             if fell else np.nan})
    runs = pd.DataFrame(rows)
    turned = runs.assign(back_azimuth_deg=(runs["back_azimuth_deg"] + 123.0) % 360,
                         downfall_azimuth_deg=(runs["downfall_azimuth_deg"] + 123.0) % 360)
    a, b = pooled_summary(runs, resamples=200), pooled_summary(turned, resamples=200)
    for ca, cb in zip(a["columns"], b["columns"]):
        for name, st in ca["statistics"].items():
            assert np.allclose(st["estimate"], cb["statistics"][name]["estimate"], atol=1e-9)
            assert np.allclose(st["ci95"], cb["statistics"][name]["ci95"], atol=1e-9)
    assert a["records"] == 6 and a["members_per_record"]["R0"] == 10   # the nominal left out


def test_two_samples_of_one_distribution_agree_and_a_turned_one_does_not():
    rng = np.random.default_rng(8)
    t = np.ones(40, bool)
    same = compare_ensembles(t, rng.normal(90, 20, 40), t, rng.normal(90, 20, 40))
    turned = compare_ensembles(t, rng.normal(90, 20, 40), t, rng.normal(180, 20, 40))
    assert same["kuiper_p"] > 0.05 and turned["kuiper_p"] < 1e-4
    fewer = compare_ensembles(np.zeros(20, bool), np.full(20, np.nan), np.ones(20, bool),
                              rng.normal(0, 10, 20))
    assert fewer["fisher_p"] < 1e-6 and fewer["kuiper_p"] is None   # no falls to compare
    assert fewer["p_toppled_difference"] == 1.0


def test_holm_by_hand():
    # sorted 0.005 <= 0.05/4, 0.01 <= 0.05/3, then 0.03 > 0.05/2: stop
    assert holm_reject([0.01, 0.04, 0.03, None, 0.005]) == [True, False, False, None, True]
    assert holm_reject([None]) == [None]


def test_the_pooled_figure_takes_records_where_nothing_fell(tmp_path):
    from pipeline.figures.ensemble import plot_pooled
    rows = [{"record_id": r, "member": m, "column": c, "toppled": r == "A" and m == 0,
             "back_azimuth_deg": 10.0, "downfall_azimuth_deg": 40.0 if r == "A" and m == 0
             else np.nan} for r in ("A", "B", "C") for m in (-1, 0, 1)
            for c in ("drums", "monolithic")]
    runs = pd.DataFrame(rows)
    pooled = pooled_summary(runs, resamples=50)
    assert pooled["columns"][0]["records_with_falls"] == 1
    assert plot_pooled(runs, pooled, tmp_path).exists()


def test_the_report_section_says_the_size_and_the_answer(tmp_path):
    import json

    from pipeline.report import paper_question_section
    rng = np.random.default_rng(9)
    rows = [{"record_id": f"R{r}", "member": m, "column": c, "toppled": bool(rng.random() < .5),
             "back_azimuth_deg": 10.0 * r, "downfall_azimuth_deg": float(rng.uniform(0, 360))}
            for r in range(5) for m in (-1, 0) for c in ("drums", "monolithic")]
    pooled = pooled_summary(pd.DataFrame(rows), resamples=100)
    base = tmp_path / "paper-question"
    base.mkdir()
    (base / "pooled_summary.json").write_text(json.dumps(pooled))
    sizing = {"precision": 0.1, "arc_deg": 60.0, "batch": 1, "max_members": 1, "members": 1,
              "stopped_by": "member cap", "open": "P(toppled) +-0.4"}
    (base / "ensemble_summaries.json").write_text(json.dumps(
        [{"record": f"R{r}", "sizing": sizing} for r in range(5)]))
    text = paper_question_section(tmp_path)
    assert "1 member per record" in text and "a fixed ensemble" in text
    assert pooled["columns"][0]["answer"] in text


def test_the_cost_is_the_finished_runs_wall_times_summed_once_each(tmp_path):
    import json

    from pipeline.campaign.ensemble import yade_cost
    from pipeline.report import paper_question_section
    walls = {"a1": 1800.0, "b2": 5400.0, "c3": 0.0}          # c3: a run YADE never ran
    for run_id, wall in walls.items():
        folder = tmp_path / "paper-question" / "runs" / run_id
        folder.mkdir(parents=True)
        (folder / "summary.json").write_text(json.dumps({"record": "R", "wall_s": wall}))
    # a run listed once per column counts once; an unfinished run costs nothing yet
    cost = yade_cost(tmp_path / "paper-question", ["a1", "a1", "b2", "c3", "unfinished"])
    assert cost == {"runs": 3, "yade_wall_s_total": 7200.0}
    rows = [{"record_id": f"R{r}", "member": m, "column": "drums", "toppled": False,
             "back_azimuth_deg": 10.0, "downfall_azimuth_deg": np.nan}
            for r in range(3) for m in (-1, 0)]
    pooled = {**pooled_summary(pd.DataFrame(rows), resamples=20), "cost": cost}
    (tmp_path / "paper-question" / "pooled_summary.json").write_text(json.dumps(pooled))
    assert "3 YADE runs" in paper_question_section(tmp_path)
    assert "2.0 process-hours" in paper_question_section(tmp_path)
