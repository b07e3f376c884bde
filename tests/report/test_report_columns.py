"""The report's real-columns section comes from campaign columns' own table."""
from pipeline.report import columns_section


def test_columns_section_shows_the_campaign_table(tmp_path):
    assert "Not run yet" in columns_section(tmp_path)
    (tmp_path / "columns").mkdir()
    (tmp_path / "columns" / "columns.md").write_text(
        "# Real columns on the same records\n\n| description | toppled |\n|---|---|\n"
        "| doric-peristyle | True |\n")
    text = columns_section(tmp_path)
    assert text.startswith("## Real columns on the same records (campaign columns)")
    assert "| doric-peristyle | True |" in text and text.count("# Real columns") == 1


def test_fragility_section_shows_the_fits_the_file_states(tmp_path):
    import json

    from pipeline.report import fragility_section
    assert "Not run yet" in fragility_section(tmp_path)
    (tmp_path / "fragility").mkdir()
    (tmp_path / "fragility" / "fragility.json").write_text(json.dumps({
        "records": ["NF04"], "members": 4, "columns": {"monolithic": {
            "description": "3D YADE monolithic column", "runs": 40, "toppled": 17,
            "PGA": {"median": 3.21, "beta": 0.41, "median_ci95": [2.5, 4.0], "unit": "m/s^2"},
            "PGV": {"median": None, "beta": None, "median_ci95": None, "unit": "m/s"},
            "logistic": {"form": "x"}}}}))
    text = fragility_section(tmp_path)
    row = next(line for line in text.splitlines() if line.startswith("| 3D YADE"))
    assert [c.strip() for c in row.strip("|").split("|")] == [
        "3D YADE monolithic column", "40 (17)", "3.21 [2.50, 4.00], beta 0.41", "-"]
