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
