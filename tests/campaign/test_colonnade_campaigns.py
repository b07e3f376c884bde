"""A colonnade where the campaigns take a column file: records, friction, synthetic and
ensemble run it whole (its description in every run's parameters, the contact stiffness
of its heaviest column), slenderness and fragility refuse it in one line, ensemble
members perturb every column alike, and a campaign writes the
colonnade's own outcomes (colonnades.csv).  No YADE: specs, and a pulse below the
columns' uplift threshold end to end."""
import json
import math

import pandas as pd
import pytest

from pipeline import campaign, cli, paper
from pipeline.campaign.column_file import matched_kn
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse
from pipeline.scenario.colonnade_file import load, to_dict
from pipeline.scenario.geometry import ColumnGeometry

SHIPPED = "parthenon-north-flank"      # four doric-peristyle columns, 3 epistyles, 3 frieze
TAKING = ("records", "friction", "synthetic", "ensemble")
OPTIONS = {"ensemble": {"members": 2}}


@pytest.fixture(scope="module")
def record(pulse_file):
    return pulse_file


def _specs(name, record, campaign_dir, **options):
    return campaign.get(name).specs([record], campaign_dir,
                                    **{**OPTIONS.get(name, {}), **options})


@pytest.mark.parametrize("name", TAKING)
def test_campaigns_run_the_colonnade_whole(name, record, tmp_path):
    specs = _specs(name, record, tmp_path, column_file=SHIPPED)
    doric_kn = matched_kn(ColumnGeometry.load("doric-peristyle"))
    for spec in specs:
        colonnade = spec.params.column.colonnade
        assert colonnade is not None and colonnade.name == SHIPPED
        assert [c.name for c in colonnade.columns] == ["N1", "N2", "N3", "N4"]
        assert len(colonnade.epistyles) == 3 and len(colonnade.frieze) == 3
        assert spec.column_description == to_dict(load(SHIPPED))
        if name != "ensemble" or spec.tags.member == -1:
            assert spec.params.contact.kn == doric_kn
    paper_kn = _specs(name, record, tmp_path / "paper", column_file=SHIPPED,
                      stiffness="paper")
    assert all(s.params.contact.kn <= 2.0 * paper.COLUMN_KN_N_M for s in paper_kn)


@pytest.mark.parametrize("name", ("slenderness", "fragility", "columns"))
def test_campaigns_that_scale_one_column_refuse_a_colonnade_in_one_line(name, record,
                                                                        tmp_path):
    out = tmp_path / "out"
    option = {"column_files": [SHIPPED]} if name == "columns" else {"column_file": SHIPPED}
    with pytest.raises(InputError) as exc:
        _specs(name, record, out, **option)
    message = str(exc.value)
    assert "\n" not in message and SHIPPED in message and "campaign records" in message
    assert not out.exists()


def test_ensemble_members_perturb_every_column_alike(record, tmp_path):
    """One height and diameter tolerance for the whole colonnade, no sampled tilt or
    offsets (they would part or overlap beams laid joint to joint)."""
    specs = _specs("ensemble", record, tmp_path, column_file=SHIPPED, members=2)
    described = to_dict(load(SHIPPED))["columns"][0]["column"]["blocks"]
    heights = set()
    for spec in [s for s in specs if s.tags.member >= 0]:
        columns = spec.params.column.column_file["columns"]
        tall = {round(math.fsum(b["height"] for b in c["column"]["blocks"]), 9)
                for c in columns}
        assert len(tall) == 1
        heights |= tall
        for c in columns:
            for block, before in zip(c["column"]["blocks"], described):
                assert block.get("offset_m") == before.get("offset_m")
                assert block.get("tilt_deg") == before.get("tilt_deg")
        placed = spec.params.column.colonnade
        assert len({round(c.capital().z, 9) for c in placed.columns}) == 1
    assert len(heights) == 2 and all(abs(h / 10.43 - 1) <= 0.01 + 1e-9 for h in heights)
    again = _specs("ensemble", record, tmp_path, column_file=SHIPPED, members=2)
    assert [s.run_id for s in again] == [s.run_id for s in specs]          # seeded


@pytest.mark.parametrize("name, table", [("records", "runs.csv"),
                                         ("ensemble", "members.csv")])
def test_a_still_colonnade_campaign_writes_its_colonnade_outcomes(name, table, tmp_path):
    """A pulse below the columns' uplift threshold: YADE is not started; every column and
    beam stands, and colonnades.csv says so for the colonnade as a whole."""
    path = tmp_path / "weak.npz"
    m = one_sine_pulse(30.0, 0.5, duration=2.0)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": "weak"}).save(path)
    out = tmp_path / ("colonnade" if name == "records" else name)   # the report's folder
    extra = ["--members", "1", "--max-members", "1"] if name == "ensemble" else []
    assert cli.main(["campaign", name, "--records", str(path), "--column-file", SHIPPED,
                     "--out", str(out), "--jobs", "1", "--animations", "0", *extra]) == 0
    done = json.loads((out / "campaign.json").read_text())
    assert done["column_file"]["name"] == SHIPPED and not done["failed"]
    runs = pd.read_csv(out / table)
    assert set(runs["column"]) == {"N1", "N2", "N3", "N4", "E1", "E2", "E3", "F1", "F2", "F3"}
    assert not runs["toppled"].astype(bool).any()
    whole = pd.read_csv(out / "colonnades.csv")
    assert len(whole) == runs["run_id"].nunique()
    assert (whole["colonnade"] == SHIPPED).all()
    assert (whole[["columns", "columns_fallen", "beams", "beams_fallen"]].to_numpy()
            == [4, 0, 6, 0]).all()
    from pipeline.stats.colonnade import ColonnadeStatistics
    (group,) = ColonnadeStatistics.load(out).groups        # one record, members only
    members = len(whole) - (name == "ensemble")             # the nominal run is no sample
    assert group.runs == members and group.fallen[0].count == members
    assert (group.parallel.of, group.in_sequence.of) == (0, 0)
    assert (out / "colonnade_statistics.png").exists()
    assert "colonnade_falls.png" in done["figures"] and (out / "colonnade_falls.png").exists()
    if name == "records":                     # the report's section from these files
        from pipeline.report import colonnade_section
        text = colonnade_section(tmp_path)
        row = next(line for line in text.splitlines() if line.startswith("| weak"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[1:4] == ["0 of 4", "0 of 6", "-"]
        assert cells[6] == "N1 none, N2 none, N3 none, N4 none" and float(cells[7]) == 0.0
        assert "| weak     |      1 | 1.00 [0.21, 1.00]" in text     # P(0 fell), Wilson
        assert "colonnade_statistics.png" in text
        assert "Not run yet" in colonnade_section(tmp_path / "nothing")
