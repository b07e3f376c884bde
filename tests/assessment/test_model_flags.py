"""--vs30, --mechanism and --pga-pgv-correlation are inputs of the ground-motion model:
where no model gives PGV/PGA (the rate density's events hold theirs, a stated lognormal
PGV/PGA, no PGV/PGA at all) each is refused in one line with nothing written, not left
unused without a word; with --magnitude/--distance-km or --disaggregation it is taken and
the summary says it, the correlation with where it comes from."""
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


def _pgv_pga(tmp_path, capsys, *argv):
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    return json.loads((out / "survival.json").read_text())["pgv_pga"]


def test_with_the_model_each_is_taken_and_said(tmp_path, capsys):
    said = _pgv_pga(tmp_path, capsys, *SURVIVAL, "--magnitude", "6.5", "--distance-km",
                    "10", *[v for pair in MODEL for v in pair])
    assert (said["vs30_m_s"], said["mechanism"], said["pga_pgv_correlation"]) == \
        (1000.0, "RS", 0.733)
    assert said["pga_pgv_correlation_source"].startswith("predicted: Bradley (2012)")


@pytest.mark.parametrize("rho, source", [(None, "observed: NGA-West2 residuals"),
                                         ("0.7", "given: neither 0.654")])
def test_the_disaggregation_route_says_its_model(tmp_path, capsys, rho, source):
    """The bins' ground-motion model, Vs30, mechanism and correlation, as the scenario
    route says them."""
    said = _pgv_pga(tmp_path, capsys, "survival", "--hazard",
                    f"{CASE}/hazard_curve-mean-PGA_6.csv", "--disaggregation",
                    f"{CASE}/disaggregation/Mag_Dist-mean-0_7.csv", "--logistic=-1,3,1.5",
                    "--age-ka", "15", "--draws", "0", "--vs30", "1000", "--mechanism", "NS",
                    *([] if rho is None else ["--pga-pgv-correlation", rho]))
    assert said["bins_used"] == 14 and said["model"].startswith("Boore, Stewart")
    assert (said["vs30_m_s"], said["mechanism"], said["pga_pgv_correlation"]) == \
        (1000.0, "NS", 0.654 if rho is None else float(rho))
    assert said["pga_pgv_correlation_source"].startswith(source)
