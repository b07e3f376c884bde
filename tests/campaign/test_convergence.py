"""The convergence campaign's comparison: a setting that samples the defaults'
distribution agrees, a setting whose falls turn is called different; specs are
independent samples per setting with the rim phase over one rim spacing."""
import numpy as np
import pandas as pd

from pipeline.campaign.convergence import VARIANTS, compare_variants, variant_ranges


def _members(rng, variant, n, p, centre_deg, spread_deg=25.0):
    rows = []
    for m in range(n):
        fell = bool(rng.random() < p)
        rows.append({"record_id": "R", "column": "drums", "variant": variant, "member": m,
                     "toppled": fell, "downfall_azimuth_deg":
                     (rng.normal(centre_deg, spread_deg)) % 360 if fell else np.nan})
    return rows


def test_a_turned_distribution_is_called_and_a_resampled_one_is_not():
    rng = np.random.default_rng(11)
    rows = (_members(rng, "default", 60, 0.8, 350.0) + _members(rng, "rim 32", 60, 0.8, 355.0)
            + _members(rng, "rim 64", 60, 0.8, 80.0) + _members(rng, "dt 0.15", 60, 0.1, 350.0))
    result = compare_variants(pd.DataFrame(rows), {"default": 10.0, "rim 64": 30.0})
    by = {r["variant"]: r for r in result["rows"]}
    assert not by["rim 32"]["fisher_differs"] and not by["rim 32"]["kuiper_differs"]
    assert by["rim 64"]["kuiper_differs"] and not by["rim 64"]["fisher_differs"]
    assert by["dt 0.15"]["fisher_differs"]
    assert set(result["differing"]) == {"R drums rim 64", "R drums dt 0.15"}
    assert result["cost_vs_default"] == {"default": 1.0, "rim 64": 3.0}
    assert "fisher_p" not in by["default"]          # the reference is not tested against itself
    assert result["p_toppled_untested"] == []


def test_a_record_where_every_member_fell_is_named_untested():
    rng = np.random.default_rng(3)
    rows = [dict(r, record_id="ALL") for r in
            _members(rng, "default", 20, 1.0, 10.0) + _members(rng, "rim 32", 20, 1.0, 12.0)]
    rows += _members(rng, "default", 20, 0.5, 10.0) + _members(rng, "rim 32", 20, 1.0, 10.0)
    result = compare_variants(pd.DataFrame(rows))
    assert result["p_toppled_untested"] == ["ALL drums"]


def test_the_rim_phase_spans_one_spacing_of_each_setting():
    for numerics in VARIANTS.values():
        lo, hi, _ = variant_ranges(numerics)["rim_phase_deg"]
        assert lo == 0.0 and hi * numerics.get("rim_points", 16) == 360.0


def test_specs_sample_each_setting_independently(tmp_path):
    from pipeline.campaign.convergence import convergence_specs
    specs = convergence_specs(["RSN126-GAZLI"], tmp_path, members=3)
    assert len(specs) == 3 * len(VARIANTS) and len({s.run_id for s in specs}) == len(specs)
    by = {}
    for s in specs:
        by.setdefault(s.tags.variant, []).append(s.params)
    assert [p.numerics.rim_points for p in by["rim 64"]] == [64] * 3
    assert [p.numerics.dt_factor for p in by["dt 0.15"]] == [0.15] * 3
    assert all(p.numerics.rim_points == 16 and p.numerics.dt_factor is None
               for p in by["default"])                  # the model's defaults
    assert [p.contact.mu_s for p in by["default"]] != [p.contact.mu_s for p in by["rim 32"]]


def test_the_report_says_where_p_toppled_was_not_tested(tmp_path):
    import json
    from pipeline.report.ensembles import convergence_section
    rng = np.random.default_rng(5)
    rows = _members(rng, "default", 10, 1.0, 10.0) + _members(rng, "rim 32", 10, 1.0, 12.0)
    result = compare_variants(pd.DataFrame(rows), {"default": 10.0, "rim 32": 25.0})
    (tmp_path / "convergence").mkdir()
    (tmp_path / "convergence" / "convergence.json").write_text(json.dumps(result))
    text = convergence_section(tmp_path)
    assert "P(toppled) is not tested for R drums" in text
    assert "rim 32 2.50x" in text
