"""Campaigns take a contact file as `run` does: its values reach every run's parameters
(damping and friction fixed, kn the base of a sampled factor, the shake-table grid's
points over it), a field set twice is one line, a bad file is refused before any run."""
import json

import pytest

from pipeline import cli
from pipeline.campaign import ensemble, ensemble_members
from pipeline.campaign.definitions import records_specs
from pipeline.campaign.shake_table import specs as shake_table_specs

FILE = {"kn": 3.0e8, "damping": 0.07, "restitution": 0.95, "restitution_se": 0.004}


@pytest.fixture
def contact(tmp_path):
    path = tmp_path / "contact.json"
    path.write_text(json.dumps(FILE))
    return str(path)


def test_column_campaign_runs_carry_the_files_kn_and_damping(tmp_path, contact, pulse_file):
    specs = records_specs([pulse_file], tmp_path / "c", contact_file=contact)
    (spec,) = specs
    assert spec.params.contact.kn == FILE["kn"] and spec.params.contact.damping == FILE["damping"]
    plain = records_specs([pulse_file], tmp_path / "c")[0]
    assert plain.params.contact.damping != FILE["damping"] and plain.run_id != spec.run_id


def test_ensemble_fixes_the_files_damping_and_multiplies_its_kn(tmp_path, contact, pulse_file):
    specs = ensemble.ensemble_specs([pulse_file], tmp_path / "e", members=6, contact_file=contact)
    members = [s for s in specs if s.tags.member >= 0]
    assert {s.params.contact.damping for s in specs} == {FILE["damping"]}
    factors = [s.params.contact.kn / FILE["kn"] for s in members]
    lo, hi, _ = ensemble_members.ENSEMBLE_RANGES["kn_factor"]
    assert all(lo - 1e-6 <= f <= hi + 1e-6 for f in factors) and len(set(factors)) == 6
    nominal = next(s for s in specs if s.tags.member == -1)
    assert nominal.params.contact.kn == FILE["kn"]
    assert len({s.params.contact.mu_s for s in members}) == 6       # friction still sampled


def test_shake_table_grid_points_override_the_files_values(tmp_path, contact):
    specs = shake_table_specs(None, tmp_path / "s", grid="damping=0.2;mu_s=0.5,0.7",
                              tests=["Test011"], contact_file=contact)
    assert len(specs) == 2 and all(
        s.params.contact.damping == 0.2 and s.params.contact.kn == FILE["kn"] for s in specs)
    (base,) = shake_table_specs(None, tmp_path / "s", grid="mu_s=0.5", tests=["Test011"],
                                contact_file=contact)
    assert base.params.contact.damping == FILE["damping"] and base.params.contact.mu_s == 0.5


@pytest.mark.parametrize("argv, words", [
    (["friction", "--records", "GM20"], "friction campaign's sweep"),
    (["ensemble", "--record", "GM20", "--vary", "damping=0.1,0.2"], "--vary"),
    (["fragility", "--pulses", "vsr", "--column-file", "records/shake_table/sp1.json",
      "--ranges", "damping=0.05:0.1"], "--ranges"),
])
def test_a_field_set_twice_is_one_line(tmp_path, capsys, contact, argv, words):
    text = json.loads(open(contact).read())
    text["mu_s"] = 0.7
    with open(contact, "w") as f:
        json.dump(text, f)
    out = tmp_path / "out"
    code = cli.main(["campaign", *argv, "--contact-file", contact, "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and words in err and "sets" in err
    assert not out.exists()


@pytest.mark.parametrize("name", ["records", "ensemble", "fragility", "shake-table", "columns",
                                  "slenderness", "synthetic"])
def test_a_bad_contact_file_is_refused_before_any_run(tmp_path, capsys, name):
    bad = tmp_path / "contact.json"
    bad.write_text('{"restitution": 0.95}')
    out = tmp_path / "out"
    extra = ["--record", "GM20"] if name == "ensemble" else []
    code = cli.main(["campaign", name, *extra, "--contact-file", str(bad), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "no kn and damping" in err
    assert not out.exists()


def test_campaign_json_says_which_file_and_its_values(tmp_path, contact, pulse_file,
                                                      monkeypatch):
    import pipeline.campaign as campaign
    monkeypatch.setattr(campaign, "execute", lambda *a, **k: ([], False))   # no YADE run
    campaign.run_campaign("records", records=[pulse_file], campaign_dir=tmp_path / "c",
                          options={"contact_file": contact}, animations=0)
    written = json.loads((tmp_path / "c" / "campaign.json").read_text())["contact_file"]
    assert written["file"] == contact and len(written["sha256"]) == 64
    assert written["values"] == {"kn": FILE["kn"], "damping": FILE["damping"]}
