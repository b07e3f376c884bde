"""--vs30, --mechanism and --pga-pgv-correlation are inputs of the ground-motion model:
where no model gives PGV/PGA (the rate density's events hold theirs, a stated lognormal
PGV/PGA, no PGV/PGA at all) each is refused in one line with nothing written, not left
unused without a word; with --magnitude/--distance-km or --disaggregation it is taken."""
import json

import pytest

from pipeline.cli import main
from tests.refusal import refused

CASE = "records/hazard/openquake_postproc_case_mrd"
MRD = f"{CASE}/mrd_pga_pgv.hdf5"
CURVE = "records/hazard/usgs_nshm2014r1_curves_-118_34_vs760.json"
CONSTRAIN = ["constrain", "--logic-tree", CASE, "--logistic=-1,3,1.5", "--age-ka", "15",
             "--draws", "0"]
SURVIVAL = ["survival", "--hazard", CURVE, "--median-g", "0.3", "--beta", "0.4", "--age-ka",
            "15", "--draws", "0"]
STATED = ["--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.5"]
MODEL = [("--vs30", "1000"), ("--mechanism", "RS"), ("--pga-pgv-correlation", "0.733")]


@pytest.mark.parametrize("flag, value", MODEL)
@pytest.mark.parametrize("base, route", [
    (CONSTRAIN, ["--joint-hazard", MRD]),
    (CONSTRAIN, STATED),
    (SURVIVAL, STATED),
    (SURVIVAL, []),
])
def test_a_model_input_without_the_model_is_refused(tmp_path, capsys, base, route, flag,
                                                    value):
    out = tmp_path / "out"
    refused(capsys, [*base, *route, flag, value, "--out", out],
            f"{flag} applies with --magnitude/--distance-km or --disaggregation", out)


def test_with_the_model_each_is_taken(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*SURVIVAL, "--magnitude", "6.5", "--distance-km", "10",
                 *[v for pair in MODEL for v in pair], "--out", str(out)]) == 0, \
        capsys.readouterr().err
    said = json.loads((out / "survival.json").read_text())["pgv_pga"]
    assert (said["vs30_m_s"], said["mechanism"], said["pga_pgv_correlation"]) == \
        (1000.0, "RS", 0.733)
