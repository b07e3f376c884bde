"""An OpenQuake job rewritten for the constrained hazard (text only, no engine): on the
shipped QA case, the rewritten jobs hold the settings of the two jobs the engine was run
on to make records/hazard/openquake_postproc_case_mrd (written by hand from the case's
job.ini), the sites given, and file names that resolve from where the job is written."""
import configparser
import os

import pytest

from pipeline import RECORDS_DIR
from pipeline.files import InputError
from pipeline.hazard.oq_job import classical_text, disaggregation_text, load_job

INPUT = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd" / "input"
# settings the rewritten jobs set otherwise than the hand-written ones, on purpose
_OWN = {"description", "num_rlzs_disagg"}   # num_rlzs_disagg 0 (all) vs 2 (all of 2)


def _flat(text):
    """{key: value with blanks squeezed} over all sections; a key twice fails."""
    parser = configparser.ConfigParser(interpolation=None)
    parser.read_string(text)
    flat = {}
    for section in parser.sections():
        for key, value in parser.items(section, raw=True):
            assert key not in flat, f"{key} set twice"
            flat[key] = "".join(value.split())
    return flat


def _same_settings(rewritten, written_by_hand, directory):
    for key, value in written_by_hand.items():
        if key in _OWN:
            continue
        if key.endswith("_file"):
            assert (directory / rewritten[key]).resolve() == (INPUT / value).resolve()
            assert (directory / rewritten[key]).is_file()
        else:
            assert rewritten[key] == value, key
    assert set(rewritten) - set(written_by_hand) <= {"sites"} | _OWN


@pytest.mark.parametrize("make, shipped", [(classical_text, "job_pga_pgv.ini"),
                                           (disaggregation_text, "job_disagg.ini")])
def test_the_shipped_jobs_settings_and_no_site_given(tmp_path, make, shipped):
    job = load_job(INPUT / "job.ini")
    text = make(job, tmp_path)
    _same_settings(_flat(text), _flat((INPUT / shipped).read_text()), tmp_path)
    assert "sites" not in _flat(text)


def test_the_sites_given_replace_the_jobs(tmp_path):
    job_ini = tmp_path / "job" / "job.ini"
    job_ini.parent.mkdir()
    text = (INPUT / "job.ini").read_text().replace(
        "site_model_file = sites.csv", "sites_csv = sites.csv\nsite_model_file = sites.csv")
    job_ini.write_text(text)
    flat = _flat(classical_text(load_job(job_ini), tmp_path / "run",
                                [(11.202, 42.424), (-120.5, 35.25)]))
    assert flat["sites"] == "11.20200042.424000,-120.50000035.250000"
    assert "sites_csv" not in flat
    assert flat["site_model_file"] == os.path.join("..", "job", "sites.csv")
    assert flat["individual_rlzs"] == "true" and flat["postproc_func"] == "dummy.main"


@pytest.mark.parametrize("text, message", [
    ("not an ini\n", "not an ini file"),
    ("[general]\ncalculation_mode = classical\n", "no source_model_logic_tree_file")])
def test_bad_jobs_one_line(tmp_path, text, message):
    path = tmp_path / "job.ini"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as err:
        load_job(path)
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match="no such file"):
        load_job(tmp_path / "none.ini")
