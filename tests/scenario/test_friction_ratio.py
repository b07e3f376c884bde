"""The rule mu_k = ratio x mu_s has one home (the contact type) and every place that
applies it gives the same kinetic friction: the paper's pair 0.6 / 0.7."""
import re
from pathlib import Path

import pytest

import pipeline
from pipeline.campaign import ensemble_members, pulse_grid
from pipeline.campaign.shake_table_experiments import grid_contact
from pipeline.scenario import Contact

PAPER_RATIO = 0.6 / 0.7          # the paper's mu_k / mu_s, the calibration's choice for SP1


def test_the_ratio_is_defined_once_in_the_contact_type():
    homes = [p.relative_to(Path(pipeline.__file__).parent).as_posix()
             for p in Path(pipeline.__file__).parent.rglob("*.py")
             if re.search(r"^\s*MU_K_OVER_MU_S\s*=", p.read_text(), re.M)]
    assert homes == ["scenario/parameters.py"]


@pytest.mark.parametrize("mu_s", [0.3, 0.5, 0.75])
def test_every_place_gives_a_static_friction_the_same_kinetic_one(mu_s):
    expected = pytest.approx(PAPER_RATIO * mu_s, abs=5e-5)
    assert Contact(mu_s=mu_s).mu_k == expected
    assert grid_contact({"mu_s": mu_s})["mu_k"] == expected
    member = ensemble_members.sample_members(1, 3, {"mu_s": (mu_s, mu_s, "lin")})[0]
    assert member["mu_k"] == expected
    assert pulse_grid.sample_sets(1, 3, {"mu_s": (mu_s, mu_s)})[0]["mu_k"] == expected


def test_the_papers_friction_sweep_keeps_its_own_rule(monkeypatch, tmp_path):
    """Fig. 10's sweep: "the coefficient of kinematic friction mu_k was always set to 84%
    of mu_s" (Hinzen 2009): a fact of the paper's experiment, not the contact rule."""
    from pipeline.campaign import definitions
    monkeypatch.setattr(definitions, "column_specs", lambda runs, campaign_dir: runs)
    runs = definitions.friction_specs(["a record"], tmp_path)
    pairs = {(p["mu_s"], p["mu_k"]) for _, p in runs}
    assert len(pairs) == 9
    for mu_s, mu_k in pairs:
        assert mu_k == pytest.approx(0.84 * mu_s, abs=5e-5)
