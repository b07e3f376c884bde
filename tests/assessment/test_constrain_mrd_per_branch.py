"""constrain --joint-hazard with a rate density per realisation (``mrd-rlzs``, written by
no engine yet: synthetic files from the shipped extract): each branch its realisation's,
against files holding that realisation's rate density as their mean; the mean's for every
branch where the file holds fewer realisations than the tree's branches, said in
constrain.json; a misshapen ``mrd-rlzs`` refused in one line with nothing written."""
import json
import shutil

import h5py
import numpy as np
import pytest

from pipeline import RECORDS_DIR
from pipeline.cli import main
from tests.refusal import refused

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
ROCK = ["--logistic=4,3,1", "--age-ka", "10", "--draws", "0"]


def _file(tmp_path, name, mean=None, realisations=None):
    """The shipped extract with its ``mrd`` replaced by ``mean`` and ``mrd-rlzs`` added."""
    path = tmp_path / name
    shutil.copyfile(CASE / "mrd_pga_pgv.hdf5", path)
    with h5py.File(path, "r+") as f:
        if mean is not None:
            del f["mrd"]
            f["mrd"] = mean
        if realisations is not None:
            f["mrd-rlzs"] = realisations
    return path


def _mrds():
    """(the shipped mrd, another: PGV three cells higher, as if a branch's PGV ran higher)."""
    with h5py.File(CASE / "mrd_pga_pgv.hdf5", "r") as f:
        mrd = f["mrd"][()]
    return mrd, np.roll(mrd, 3, axis=0)           # axis 0: PGV


def _constrain(tmp_path, name, path):
    out = tmp_path / name
    assert main(["constrain", "--logic-tree", str(CASE), "--joint-hazard", str(path), *ROCK,
                 "--out", str(out)]) == 0
    return json.loads((out / "constrain.json").read_text())


def test_each_branch_its_realisations_rate_density(tmp_path):
    mrd, other = _mrds()
    both = _constrain(tmp_path, "both",
                      _file(tmp_path, "both.hdf5", realisations=np.stack([mrd, other], -1)))
    assert both["pgv_pga"]["per_branch"] is True
    assert [g["branch_indices"] for g in both["pgv_pga"]["groups"]] == [[0], [1]]
    first = _constrain(tmp_path, "first", _file(tmp_path, "first.hdf5"))
    second = _constrain(tmp_path, "second", _file(tmp_path, "second.hdf5", mean=other))
    p = [b["survival_probability"] for b in both["branches"]]
    assert p[0] == first["branches"][0]["survival_probability"]
    assert p[1] == second["branches"][1]["survival_probability"]
    assert p[1] != first["branches"][1]["survival_probability"]


def test_fewer_realisations_than_branches_the_mean_said(tmp_path):
    mrd, _ = _mrds()
    one = _constrain(tmp_path, "one", _file(tmp_path, "one.hdf5",
                                            realisations=mrd[..., None]))
    assert one["pgv_pga"]["per_branch"] is False
    assert "holds 1 realisations'" in one["pgv_pga"]["branches"]


@pytest.mark.parametrize("shape", [(39, 39, 2), (39, 38, 1, 2), (39, 39, 1, 0)])
def test_misshapen_realisations_one_line_nothing_written(tmp_path, capsys, shape):
    path = _file(tmp_path, "bad.hdf5", realisations=np.zeros(shape))
    out = tmp_path / "out"
    refused(capsys, ["constrain", "--logic-tree", CASE, "--joint-hazard", path, *ROCK,
                     "--out", out], "mrd-rlzs is", out)
