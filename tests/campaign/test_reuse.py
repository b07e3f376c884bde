"""A run computed once is not computed again: campaigns beside each other share finished
runs of the same run id and worker."""
import json

from pipeline.campaign import reuse_finished
from pipeline.campaign.runs import run_column_spec
from pipeline.campaign.spec import RunSpec
from pipeline.scenario import RunParams


def _campaign(root, name, runs):
    """A finished campaign directory: campaign.json and runs {run_id: [file names]}."""
    d = root / name
    for run_id, files in runs.items():
        (d / "runs" / run_id).mkdir(parents=True)
        for f in files:
            (d / "runs" / run_id / f).write_text(json.dumps({"run": run_id, "file": f}))
    (d / "campaign.json").write_text(json.dumps({"campaign": name}))
    return d


def test_finished_runs_of_the_same_worker_are_copied_once(tmp_path):
    _campaign(tmp_path, "records", {"a": ["summary.json", "trajectory.npz"],
                                    "b": ["summary.json"], "c": ["trajectory.npz"]})
    _campaign(tmp_path, "verification", {"d": ["summary.json", "trajectory.npz"]})
    target = tmp_path / "ensemble"
    (target / "runs" / "b").mkdir(parents=True)
    (target / "runs" / "b" / "error.txt").write_text("an earlier attempt")
    def spec(run_id, keep_trajectory=True):
        return RunSpec("r", "r", "/m.npz", RunParams(), run_id,
                       keep_trajectory=keep_trajectory)
    specs = [spec("a", keep_trajectory=False), spec("b"), spec("c", keep_trajectory=False),
             spec("d"), spec("e", keep_trajectory=False)]
    assert reuse_finished(specs, target, run_column_spec) == 1
    assert sorted(p.name for p in (target / "runs" / "a").iterdir()) == ["summary.json"]
    assert json.loads((target / "runs" / "a" / "summary.json").read_text())["run"] == "a"
    # b kept no trajectory there but keeps one here; c never finished; d: another worker
    assert not (target / "runs" / "b" / "summary.json").exists()
    assert not (target / "runs" / "c").exists() and not (target / "runs" / "d").exists()
    assert reuse_finished(specs, target, run_column_spec) == 0      # nothing twice
    assert not list((target / "runs").glob("*.copying"))
