"""constrain --joint-hazard: PGV/PGA at each PGA level from the shipped mean rate density
(one distribution for every branch, said in constrain.json); beside another PGV/PGA
source it is refused in one line with nothing written."""
import json

from pipeline import RECORDS_DIR
from pipeline.cli import main

CASE = RECORDS_DIR / "hazard" / "openquake_postproc_case_mrd"
BASE = ["constrain", "--logic-tree", str(CASE), "--joint-hazard",
        str(CASE / "mrd_pga_pgv.hdf5"), "--logistic=-2,3,1", "--age-ka", "10",
        "--draws", "0"]


def test_the_mean_rate_density_gives_pgv_pga_for_every_branch(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*BASE, "--out", str(out)]) == 0, capsys.readouterr().err
    summary = json.loads((out / "constrain.json").read_text())
    assert "mean rate density" in summary["pgv_pga"]["source"]
    assert summary["pgv_pga"]["per_branch"] is False
    assert "mean's only" in summary["pgv_pga"]["branches"]
    assert summary["branch_count"] == 2


def test_beside_another_pgv_pga_source_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    code = main([*BASE, "--magnitude", "6", "--distance-km", "20", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and len(err) == 1 and "--joint-hazard" in err[0]
    assert not out.exists()
