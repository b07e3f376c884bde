"""A contact file's values range-checked as the flags are, each refusal blaming where
the value came from: the file and its key, or the flag the user gave."""
import pytest

from pipeline.cli import main
from pipeline.files import InputError


def test_a_files_value_is_blamed_on_the_file_a_flags_on_the_flag(tmp_path):
    from pipeline.scenario.contact_file import checked_contact
    path = tmp_path / "contact.json"
    with pytest.raises(InputError, match=r"^--contact-file contact.json: 'damping' 5 outside"):
        checked_contact({"kn": 1e6, "damping": 5.0}, path)
    with pytest.raises(InputError, match=r"^--mu-s 5 outside"):
        checked_contact({"kn": 1e6, "damping": 0.1}, path, mu_s=5.0)
    assert checked_contact({"kn": 1e6, "damping": 0.1}, path, mu_s=0.6).damping == 0.1


def test_run_blames_the_file_for_its_damping_not_a_flag_never_given(tmp_path, capsys):
    contact = tmp_path / "contact.json"
    contact.write_text('{"kn": 1e6, "damping": 5}')
    out = tmp_path / "out"
    assert main(["run", "--record", "GM1", "--contact-file", str(contact),
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "error: --contact-file contact.json: 'damping' 5 outside the allowed " \
                  "range [0, 1]"
    assert not out.exists()
