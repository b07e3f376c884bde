"""Damage-state fragility of campaign fragility: per state P(the state or worse | IM) is
fitted as P(toppled) is, recovers known lognormal capacities, writes through the one
writer and reads back through the one reader, and refuses curves that contradict
themselves; its states are the damage measures' own."""
import json
import math

import numpy as np
import pandas as pd
import pytest

from pipeline.campaign.fragility_tables import damage_state_fits
from pipeline.files import InputError
from pipeline.hazard.fragility.damage_states import STATES, ColumnStates, StateFits
from pipeline.hazard.fragility.file import (ColumnFits, FragilityFile, read_fragility_file,
                                            write_fragility_file)
from pipeline.outcome.damage import DamageState

MEDIANS = {"slight": 1.0, "moderate": 2.0, "severe": 4.0, "collapse": 8.0}   # m/s^2
BETA = 0.35


def _table(n=1500, seed=7):
    """Runs of one column whose capacity to each state is lognormal (MEDIANS, BETA),
    the states nested through one draw per run (a run that reaches a worse state has
    reached the milder ones); PGV/PGA drawn over two values."""
    rng = np.random.default_rng(seed)
    pga = np.exp(rng.uniform(math.log(0.3), math.log(30.0), n))
    z = rng.standard_normal(n)
    rank = np.zeros(n, int)
    for k, state in enumerate(STATES, start=1):
        rank[pga >= MEDIANS[state] * np.exp(BETA * z)] = k
    ratio = rng.choice([0.1, 0.3], n)
    labels = np.array(("none", *STATES))[rank]
    return pd.DataFrame({"column": "drums", "damage_state": labels, "pga_m_s2": pga,
                         "pgv_m_s": pga * ratio, "pgv_pga_s": ratio,
                         "toppled": rank == len(STATES)})


def test_the_states_are_the_damage_measures_states():
    assert STATES == tuple(s.label for s in DamageState if s != DamageState.NONE)


def test_each_state_recovers_its_lognormal_capacity():
    table = _table()
    fits = damage_state_fits(table, {"drums": "the drum column"}, alpha=0.2, p=1.5)
    entry = fits["drums"]
    assert entry.runs == len(table) and [s.state for s in entry.states] == list(STATES)
    for state in entry.states:
        fit = state.fits["PGA"]
        lo, hi = fit.median_ci95
        assert lo < MEDIANS[state.state] < hi, (state.state, fit.median, lo, hi)
        assert fit.beta == pytest.approx(BETA, abs=4 * (fit.beta_ci95[1] - fit.beta) / 1.96)
        assert fit.toppled == state.reached and fit.n == state.runs
        # the binned fractions with their Wilson intervals (the Monte Carlo error)
        assert sum(b["n"] for b in fit.bins) == state.runs
        assert all(b["ci95"][0] <= b["fraction"] <= b["ci95"][1] for b in fit.bins)
        assert state.logistic.b[1] > 0            # rises with PGA
    reached = [s.reached for s in entry.states]
    assert reached == sorted(reached, reverse=True)
    assert entry.state("collapse").reached == int(table["toppled"].sum())


def test_runs_without_damage_measures_are_left_out_and_the_2d_block_has_none():
    table = _table(200)
    table.loc[:19, "damage_state"] = ""        # summaries written before the measures
    block = table.assign(column="block2d", damage_state=np.nan)
    fits = damage_state_fits(pd.concat([table, block]), {"drums": "d"}, 0.2, 1.5)
    assert set(fits) == {"drums"} and fits["drums"].runs == 180
    assert damage_state_fits(block, {}, 0.2, 1.5) is None


def test_written_and_read_back_through_the_file(tmp_path):
    fits = damage_state_fits(_table(300), {"drums": "the drum column"}, 0.2, 1.5)
    column = ColumnFits(description="d", model="3D", runs=300, toppled=1,
                        order=("description", "model", "runs", "toppled"))
    file = FragilityFile(columns={"drums": column}, damage_states=fits,
                         order=("columns",))
    path = write_fragility_file(tmp_path, file)
    written = json.loads(path.read_text())
    assert list(written["damage_states"]["drums"]["states"]) == list(STATES)
    read = read_fragility_file(path)
    assert read.damage_states == fits
    assert json.loads(json.dumps(FragilityFile.of(written).to_json())) == written


def test_curves_that_contradict_themselves_are_refused():
    good = damage_state_fits(_table(300), {"drums": "d"}, 0.2, 1.5)["drums"]
    slight, moderate = good.states[:2]
    with pytest.raises(InputError, match="must be one of"):
        StateFits(state="heavy", runs=3, reached=1)
    with pytest.raises(InputError, match="reached"):
        StateFits(state="slight", runs=3, reached=4)
    with pytest.raises(InputError, match="mildest first"):
        ColumnStates(description="d", runs=300, states=(moderate, slight))
    worse = StateFits(state="moderate", runs=300, reached=slight.reached + 1)
    with pytest.raises(InputError, match="a worse state by more runs"):
        ColumnStates(description="d", runs=300, states=(slight, worse))
    written = {"columns": {"drums": {"runs": 1, "toppled": 0}},
               "damage_states": {"drums": {**good.to_json(), "runs": 299}}}
    with pytest.raises(InputError, match="damage_states.drums"):
        FragilityFile.of(written)


def test_the_report_shows_each_state_as_the_file_states_it(tmp_path):
    from pipeline.report import fragility_section
    fits = damage_state_fits(_table(300), {"drums": "the drum column"}, 0.2, 1.5)
    column = ColumnFits(description="d", model="3D", runs=300, toppled=1,
                        order=("description", "model", "runs", "toppled"))
    write_fragility_file(tmp_path / "fragility", FragilityFile(
        columns={"drums": column}, records=("R1",), members=1, damage_states=fits,
        order=("records", "members", "columns")))
    text = fragility_section(tmp_path)
    for state in fits["drums"].states:
        row = next(line for line in text.splitlines()
                   if line.startswith("| the drum column") and f"| {state.state} " in line)
        cells = [c.strip() for c in row.strip("|").split("|")]
        fit = state.fits["PGA"]
        assert cells[2] == f"{state.reached} of {state.runs}"
        assert cells[3].startswith(f"{fit.median:.3g} [{fit.median_ci95[0]:.2f}, ")


def test_the_figure_draws_every_state(tmp_path):
    from pipeline.figures.damage_states import plot_damage_states
    fits = damage_state_fits(_table(300), {"drums": "d", "monolithic": "m"}, 0.2, 1.5)
    path = plot_damage_states(FragilityFile(damage_states=fits), tmp_path / "ds.png")
    assert path.stat().st_size > 10_000


def test_fragility_levels_give_each_state_or_worse_per_level():
    """fragility_levels.csv's per-state columns against a hand count: at level 1, states
    none, slight, severe, collapse (a run without damage measures left out); at level 2,
    moderate and collapse twice; the Wilson intervals from their closed form."""
    from scipy import stats

    from pipeline.campaign.fragility_tables import level_table
    rows = [(1.0, "none"), (1.0, "slight"), (1.0, "severe"), (1.0, "collapse"), (1.0, ""),
            (2.0, "moderate"), (2.0, "collapse"), (2.0, "collapse")]
    table = pd.DataFrame({"record_id": "R", "level_m_s2": [r[0] for r in rows],
                          "damage_state": [r[1] for r in rows], "column": "drums",
                          "pgv_m_s": 0.1, "toppled": [r[1] == "collapse" for r in rows]})
    levels = level_table(table)
    one = levels[(levels["record_id"] == "R") & (levels["level_m_s2"] == 1.0)].iloc[0]
    two = levels[(levels["record_id"] == "R") & (levels["level_m_s2"] == 2.0)].iloc[0]
    z = stats.norm.ppf(0.975)

    def wilson(k, n):
        p, d = k / n, 1 + z * z / n
        half = z / d * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        return (p + z * z / (2 * n)) / d - half, (p + z * z / (2 * n)) / d + half
    hand = {(1.0, "slight"): 3, (1.0, "moderate"): 2, (1.0, "severe"): 2,
            (1.0, "collapse"): 1, (2.0, "slight"): 3, (2.0, "moderate"): 3,
            (2.0, "severe"): 2, (2.0, "collapse"): 2}
    for row, level, n in ((one, 1.0, 4), (two, 2.0, 3)):
        assert row["n_drums_states"] == n
        for state in STATES:
            k = hand[(level, state)]
            assert row[f"p_drums_{state}"] == pytest.approx(k / n)
            assert (row[f"p_drums_{state}_lo"], row[f"p_drums_{state}_hi"]) == \
                pytest.approx(wilson(k, n), abs=1e-9)
    assert one["p_drums"] == pytest.approx(1 / 5) and one["n_drums"] == 5   # toppled: all runs
    pooled = levels[levels["record_id"] == "all records"]
    assert list(pooled["p_drums_collapse"]) == pytest.approx([1 / 4, 2 / 3])
