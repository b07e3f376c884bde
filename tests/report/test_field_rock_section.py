"""The REPORT section of the field rock: it names the full-size command in both its sizes,
says that no published fragility exists, says what has not run, and quotes constrain.json."""
from pipeline.hazard.ages import TruncatedNormal
from pipeline.hazard.constrain_parts import (BranchRow, ConstrainSpecimen, CurveStatistics,
                                             MotionAtRate)
from pipeline.hazard.constrain_sites import BranchTest, BranchTestRow
from pipeline.hazard.hazard_described import TreeHazard
from pipeline.hazard.results import ConstrainResult
from pipeline.report import field_rock_section
from pipeline.report.field_rock import FIELD_ROCK_QUICK


def test_not_run_yet_names_the_commands_and_the_missing_comparison(tmp_path):
    full = field_rock_section(tmp_path)
    quick = field_rock_section(tmp_path, FIELD_ROCK_QUICK)
    for text in (full, quick):
        assert "`make field-rock`" in text
        assert "No published fragility exists for this rock" in text
        assert "not Arizona's" in text
    assert full.startswith("## Field rock: Double Rock\n")
    assert "Fragility: not run yet (`make field-rock`)" in full
    assert "Constrained hazard: not run yet (`make run-all`)" in quick


def test_the_constrained_hazard_is_quoted_and_a_hopeless_tree_is_said(tmp_path):
    """Two branches, both with survival below the floor: the section says the rock could
    not have stood under any of them, and shows the mean's change as written."""
    out = tmp_path / "field-rock-constrain"
    out.mkdir()
    branches = [BranchRow(branch="0", path="a", prior_weight=0.5, survival_probability=0.01,
                          posterior_bayes=0.8, posterior_eliminate=None),
                BranchRow(branch="1", path="b", prior_weight=0.5,
                          survival_probability=0.0025, posterior_bayes=0.2,
                          posterior_eliminate=None)]
    motion = [MotionAtRate(annual_rate_per_yr=1e-4, curve="mean", prior_m_s2=0.5 * 9.81,
                           posterior_m_s2=0.4 * 9.81, prior_g=0.5, posterior_g=0.4,
                           change_percent=-20.0),
              MotionAtRate(annual_rate_per_yr=1e-4, curve="fractile 0.16",
                           prior_m_s2=0.3 * 9.81, posterior_m_s2=0.3 * 9.81, prior_g=0.3,
                           posterior_g=0.3, change_percent=0.0)]
    test = BranchTest(0.05, tuple(
        BranchTestRow(b.branch, 0.5, b.survival_probability, True, (0,), 0, None,
                      b.survival_probability) for b in branches))
    curves = CurveStatistics(mean_rates_per_yr=[1e-3], fractiles={"0.5": [1e-3]})
    (out / "constrain.json").write_text(ConstrainResult(
        branch_count=2, rule="bayes", headline="", floor=0.05, specimen_count=1,
        specimens=[ConstrainSpecimen(fragility={}, age_ka=15, age_sd_ka=3,
                                     age=TruncatedNormal(15e3, 3e3).describe())], age_model="known ages",
        age_integration_se_max=None, branches=branches, levels_m_s2=[1.0], levels_g=[0.1],
        prior=curves, posterior=curves, posterior_eliminate=None, ground_motion_at_rates=motion,
        members=None, monte_carlo=None, sites=[], branch_test=test,
        hazard=TreeHazard(source={"format": "plain logic-tree table", "file": "tree.csv"},
                          notes=[], interpolation="", cells_per_interval=1),
        pgv_pga=None, warnings=["something said"], assumptions=[], draws=0, seed=0,
        software={}).text())
    text = field_rock_section(tmp_path)
    assert "### Constrained hazard" in text and "15 +- 3 ka" in text
    assert "below 0.05 (at most 0.01)" in text
    assert "| -20.0 %" in text
    assert "fractile 0.16" not in text          # the fractiles stay in the files
    assert "Warning: something said" in text
