"""RunSpec: a run's id comes from what defines the run, never from a campaign's tags; a
spec cannot be changed after it is made."""
import pickle
from dataclasses import replace

import numpy as np
import pytest

from pipeline.campaign.spec import RunSpec
from pipeline.campaign.tags import ConvergenceTags, EnsembleTags
from pipeline.files import InputError, content_hash
from pipeline.scenario import Column, Contact, RunParams


def test_the_run_id_follows_motion_content_and_parameters_not_tags(tmp_path):
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    np.savez(a, x=np.arange(3))
    b.write_bytes(a.read_bytes())                      # same content, other name
    one = RunSpec.create("A", "A", a, {"hd": 6.0}, "code1", EnsembleTags(3, 1))
    assert RunSpec.create("B", "B", b, {"hd": 6.0}, "code1").run_id == one.run_id
    assert RunSpec.create("A", "A", a, {"hd": 6.1}, "code1").run_id != one.run_id
    assert RunSpec.create("A", "A", a, {"hd": 6.0}, "code2").run_id != one.run_id
    # a default given or left out is the same run
    assert RunSpec.create("A", "A", a, {"hd": 6.0, "kn": Contact().kn}, "code1").run_id \
        == one.run_id
    assert RunSpec.create("A", "A", a, RunParams(Column(hd=6.0)), "code1").run_id == one.run_id
    # the id is the hash of (code, motion content, parameters) alone: tags, the trajectory
    # kept, a cost estimate or a description's name change nothing
    expected = content_hash("code1", a, RunParams(Column(hd=6.0)).to_dict())
    assert one.run_id == expected
    assert RunSpec.create("A", "A", a, {"hd": 6.0}, "code1", ConvergenceTags("x", 2, 9),
                          keep_trajectory=False, core_s=5.0).run_id == expected
    tagged = replace(one, tags=replace(one.tags, member=4))
    assert tagged.run_id == one.run_id and tagged.tags.member == 4
    assert one.tags.member == 3 and tagged.tags.seed == 1
    assert tagged.params.column.hd == 6.0 and tagged.params.contact == Contact()
    assert pickle.loads(pickle.dumps(tagged)) == tagged        # to a Dask worker and back


def test_a_spec_is_read_only_and_checked():
    spec = RunSpec("A", "A", "/m.npz", RunParams(), "id1")
    with pytest.raises(TypeError):
        spec["member"]                                  # not a mapping: attributes
    with pytest.raises(AttributeError):
        spec.run_id = "other"
    with pytest.raises(TypeError):
        EnsembleTags(member=1, seed=2, stage="x")       # no tag a campaign does not declare
    assert spec.keep_trajectory and not replace(spec, keep_trajectory=False).keep_trajectory
    with pytest.raises(InputError, match="tags dataclass"):
        RunSpec("A", "A", "/m.npz", RunParams(), "id1", {"member": 1})
    with pytest.raises(InputError, match="run_id"):
        RunSpec("A", "A", "/m.npz", RunParams(), "")
    with pytest.raises(InputError, match="RunParams"):
        RunSpec("A", "A", "/m.npz", {"hd": 6.0}, "id1")
    with pytest.raises(InputError, match="unknown run parameter.*height_m"):
        RunSpec.create("A", "A", "/m.npz", {"height_m": 6.0}, "code1")
    with pytest.raises(InputError, match="--scale 25 outside"):
        RunSpec.create("A", "A", "/m.npz", {"scale": 25.0}, "code1")


def test_every_campaign_is_found_without_importing_its_module_first():
    """Campaigns outside pipeline.campaign (the inversion's) come from the entry points,
    not from a command that happens to import them."""
    import subprocess
    import sys
    code = ("from pipeline import campaign; import sys; "
            "print(' '.join(campaign.names())); "
            "print('pipeline.cli.invert' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split("\n")
    assert {"inversion-forward", "inversion-truth", "ensemble"} <= set(out[0].split())
    assert out[1] == "False"
