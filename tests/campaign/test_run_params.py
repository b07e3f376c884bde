"""RunParams: one spelling of every run parameter from a campaign's spec to the scene's
params.json and the run's summary.json.  No YADE: the scene files are written and the
scene itself is not started (a still run writes its summary without it)."""
import dataclasses
import json
import re
from pathlib import Path

import pytest

from pipeline import paper, simulate as simulate_module
from pipeline.campaign.column_file import matched_kn
from pipeline.campaign.runs import column_specs, run_column_spec, twin
from pipeline.files import InputError
from pipeline.outcome.summary import RunSummary
from pipeline.scenario import Column, Drive, RunParams
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.time_step import dt_factor_for

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "yade_scripts" / "column_scene.py"
SPECIMEN = ROOT / "records" / "shake_table" / "sp1.json"      # a scanned rock (mesh)


def _cases():
    doric = ColumnGeometry.load("doric-peristyle")
    rock = ColumnGeometry.load(SPECIMEN)
    return {
        "twin": twin(),
        "drums described": twin(column="drums", column_file=doric.to_dict(),
                                kn=matched_kn(doric)),
        "mesh specimen": {"column": "monolithic", "column_file": rock.to_dict(),
                          "damping": 0.1, "rotate_deg": 180.0},
        "scaled member": {**twin(hd=7.5, height=5.2, mu_s=0.6, mu_k=0.5, damping=0.3,
                                 rim_phase_deg=12.5), "scale": 0.37, "window": [0.5, 3.5]},
        "numerics": twin(rim_points=32, dt_factor=0.15, quiet_motion="simulate"),
    }


@pytest.fixture(scope="module")
def pulse(pulse_file):
    return pulse_file


class SceneWritten(Exception):
    pass


def _scene_params(spec, run_dir, monkeypatch):
    """params.json that run_column_spec writes for ``spec`` (the scene not started)."""
    def no_yade(run_dir, timeout_s=None):
        raise SceneWritten
    monkeypatch.setattr(simulate_module, "run_yade", no_yade)
    run_dir.mkdir(parents=True)
    try:
        run_column_spec(spec, run_dir)
    except SceneWritten:
        pass
    return json.loads((run_dir / "params.json").read_text())


def test_flat_names_are_one_spelling_of_the_parameter_classes():
    names = [n for g in RunParams.GROUPS for n in RunParams.names(g)]
    assert len(names) == len(set(names))                 # no name in two groups
    assert set(RunParams().to_dict()) == set(names)
    assert {"column", "hd", "height", "kn", "mu_s", "rim_points", "window", "scale"} <= \
        set(names)
    with pytest.raises(InputError, match="unknown run parameter.*density_kg_m3"):
        RunParams.from_dict({"density_kg_m3": 2700.0})
    with pytest.raises(InputError, match="--hd 0.5 outside"):
        RunParams.from_dict({"hd": 0.5})
    with pytest.raises(InputError, match="--window needs START < END"):
        RunParams.from_dict({"window": [3.0, 1.0]})
    with pytest.raises(InputError, match="column must be a Column, got Drive"):
        RunParams(Drive((0.0, 1.0)))


@pytest.mark.parametrize("name", list(_cases()))
def test_the_scene_gets_every_key_it_reads_from_the_same_parameters(name, pulse, tmp_path,
                                                                    monkeypatch):
    (spec,) = column_specs([(pulse, _cases()[name])], tmp_path)
    flat = spec.params.to_dict()
    assert RunParams.from_dict(json.loads(json.dumps(flat))) == spec.params   # via JSON
    params = _scene_params(spec, tmp_path / "run", monkeypatch)
    text = SCENE.read_text()          # what the scene requires, at the top and in numerics
    read = set(re.findall(r'\bP\["(\w+)"\]', text))
    nested = set(re.findall(r'NUMERICS\["(\w+)"\]', text))
    assert {"columns", "contact", "numerics", "t_max", "output"} <= read
    assert read <= set(params), sorted(read - set(params))
    assert nested <= set(params["numerics"]), sorted(nested - set(params["numerics"]))
    p = spec.params
    assert params["contact"] == dataclasses.asdict(p.contact)
    for key, value in dataclasses.asdict(p.numerics).items():
        if key != "dt_factor" or value is not None:         # None: the stable default
            assert params["numerics"][key] == value, key
    assert [c["name"] for c in params["columns"]] == [s.name for s in p.column.specs()]


@pytest.mark.parametrize("name", ["twin", "scaled member", "drums described"])
def test_the_summary_names_the_parameters_as_the_spec(name, pulse, tmp_path):
    """A run of scale 0 moves nothing: its summary is written without YADE."""
    flat = {**_cases()[name], "scale": 0.0}
    (spec,) = column_specs([(pulse, flat)], tmp_path)
    run_column_spec(spec, tmp_path / "run")
    summary = RunSummary.load(tmp_path / "run")
    assert not summary.simulated
    given = {k: v for k, v in summary.parameters.items() if k in spec.params.to_dict()}
    assert set(given) == set(spec.params.to_dict())
    p = spec.params                   # the summary says the time-step factor the scene used
    assert given.pop("dt_factor") == dt_factor_for(p.contact, p.numerics)
    given["dt_factor"] = p.numerics.dt_factor
    if spec.params.column.column_file is None:
        assert RunParams.from_dict(given) == spec.params
    else:                   # the description's name, its sizes and the description
        g = spec.params.column.geometry
        assert summary.parameters["column_file"] == g.name
        assert summary.parameters["geometry"] == g.to_dict()
        assert summary.parameters["height"] == g.height
        rest = {k: v for k, v in given.items() if k not in ("column_file", "hd", "height",
                                                             "n_drums", "density")}
        assert rest == {k: v for k, v in spec.params.to_dict().items() if k in rest}


def test_an_old_summary_still_loads_under_the_new_names(tmp_path):
    old = {"record": "GM20", "parameters": {"column": "both", "hd": paper.COLUMN_HD,
                                            "height_m": 4.0, "density_kg_m3": 2700.0,
                                            "window_s": [1.0, 9.0], "kn": 1e8}}
    (tmp_path / "summary.json").write_text(json.dumps(old))
    p = RunSummary.load(tmp_path).parameters
    assert (p["height"], p["density"], p["window"]) == (4.0, 2700.0, [1.0, 9.0])
    assert not {"height_m", "density_kg_m3", "window_s"} & set(p)


def test_a_run_without_a_column_file_is_the_column_class_default():
    assert RunParams.from_dict(twin()).column == Column()
