"""``--column-file`` on the campaigns: the description goes into every run's parameters
(so run ids differ) and into campaign.json, defaults keep their parameters bit for bit,
bad input is one InputError before anything is written, slenderness scales the block
heights, ensembles perturb the described blocks, fragility's 2D block takes the
described column's height and base width.  No YADE: specs and outputs only."""
import hashlib
import json
import math

import numpy as np
import pytest

from pipeline.cli._fields import from_args
from pipeline import campaign, cli, paper
from pipeline.campaign import pulse_block
from pipeline.campaign.fragility_block import block_runs
from pipeline.campaign.column_file import at_slenderness, column_file_help, perturbed
from pipeline.campaign.column_file import matched_kn
from pipeline.files import InputError
from pipeline.motion import Motion
from pipeline.motion.pulses import one_sine_pulse
from pipeline.scenario.geometry import ColumnGeometry

DORIC = "doric-peristyle"          # 10.43 m high, base diameter 1.905 m, 13 blocks
DORIC_KN = 2.3e9                   # matched_kn (docs/columns-and-model.md, "Contact stiffness of heavy columns")
CAMPAIGN_OPTIONS = {               # small but complete: every kind of run of each campaign
    "slenderness": {}, "friction": {}, "records": {}, "synthetic": {},
    "ensemble": {"members": 3}, "fragility": {"members": 2, "levels": (1.0, 4.0)}}
# sha256 (first 16 hex) of the run parameters (RunParams.to_dict) without --column-file on
# the pulse record ("scale" dropped: it depends on the motion's PGA; "window" too:
# synthetic runs have since been cut at their signal's end).  First computed before the
# option existed (commit 5b7b9e3, the run ids equal too); recomputed when the parameters
# became RunParams (every name, defaults included), after checking that each campaign's
# RunParams equal the parameters of the earlier specs read through RunParams.from_dict;
# ensemble and fragility recomputed when the members took the contact's one friction rule
# mu_k = 0.6/0.7 mu_s (was 0.84 mu_s), after checking that mu_k alone changed
DEFAULT_PARAMS_SHA = {"slenderness": "d904b5004c5c9092", "friction": "e9e8404856fb90c7",
                      "records": "ddef462ca301837f", "synthetic": "ddef462ca301837f",
                      "ensemble": "2533416a9c5b4b79", "fragility": "52db983860d24b9b"}


@pytest.fixture(scope="module")
def record(pulse_file):
    return pulse_file


def _specs(name, record, campaign_dir, **options):
    return campaign.get(name).specs([record], campaign_dir,
                                    **{**CAMPAIGN_OPTIONS[name], **options})


def _params_sha(specs):
    params = [{k: v for k, v in s.params.to_dict().items() if k not in ("scale", "window")}
              for s in specs]
    return hashlib.sha256(json.dumps(params, sort_keys=True).encode()).hexdigest()[:16]


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS))
def test_default_specs_are_unchanged(name, record, tmp_path):
    default = _specs(name, record, tmp_path / "a")
    explicit = _specs(name, record, tmp_path / "b", column_file=None)
    assert [s.params for s in default] == [s.params for s in explicit]
    assert [s.run_id for s in default] == [s.run_id for s in explicit]
    assert not any(s.column_description is not None for s in default)
    # only the ensemble's own drum columns (tilt, offsets) are descriptions by default
    assert {s.params.column.column_file["name"] for s in default
            if s.params.column.column_file is not None} \
        <= {"drums (ensemble member)"}
    assert _params_sha(default) == DEFAULT_PARAMS_SHA[name]


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS))
def test_described_specs_carry_the_description(name, record, tmp_path):
    default = _specs(name, record, tmp_path / "default")
    described = _specs(name, record, tmp_path / "doric", column_file=DORIC)
    assert len(described) == len(default)
    assert not {s.run_id for s in described} & {s.run_id for s in default}
    for spec in described:
        data = spec.params.column.column_file
        assert isinstance(data, dict) and data["name"].startswith(DORIC)
        assert len(data["blocks"]) == 13
        assert spec.column_description["name"] == DORIC
        assert spec.column_description == ColumnGeometry.load(DORIC).to_dict()
        assert spec.params.column.kind == "both"
    if name in ("friction", "records", "synthetic"):
        assert all(s.params.column.column_file == ColumnGeometry.load(DORIC).to_dict()
                   and s.params.contact.kn == DORIC_KN for s in described)
        # everything else as in the default run
        for a, b in zip(default, described):
            def rest(spec):
                return {k: v for k, v in spec.params.to_dict().items()
                        if k not in ("column_file", "kn")}
            assert rest(b) == rest(a)
    if name in ("ensemble", "fragility"):
        kn = [s.params.contact.kn for s in described]
        assert all(0.5 * DORIC_KN <= k <= 2.0 * DORIC_KN for k in kn)
    paper_kn = _specs(name, record, tmp_path / "paper", column_file=DORIC, stiffness="paper")
    assert all(s.params.contact.kn <= 2.0 * paper.COLUMN_KN_N_M for s in paper_kn)


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS))
def test_bad_column_file_is_one_line_before_anything_is_written(name, record, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"name": "x", "density": 2700,
                               "blocks": [{"shape": "cube", "height": 1.0}]}))
    for value, words in (("nosuch", ("nosuch", "no such file or shipped example", DORIC)),
                         (str(tmp_path / "missing.json"), ("missing.json", "no such file")),
                         (str(bad), ("bad.json", "unknown shape 'cube'"))):
        out = tmp_path / f"out-{name}"
        with pytest.raises(InputError) as exc:
            _specs(name, record, out, column_file=value)
        message = str(exc.value)
        assert "\n" not in message and all(w in message for w in words), message
        assert not out.exists()
    with pytest.raises(InputError, match="--stiffness"):
        _specs(name, record, tmp_path / "s", column_file=DORIC, stiffness="soft")


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS))
def test_cli_refuses_an_unknown_name_with_exit_2(name, tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["campaign", name, "--records", "GM20", "--column-file", "nosuch", "--out", str(out)]
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "nosuch" in err
    assert not out.exists()


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS) + ["columns"])
def test_one_option_definition_and_help_text(name):
    parser = cli.build_parser()
    command = parser._subparsers._group_actions[0].choices["campaign"]
    sub = command._subparsers._group_actions[0].choices[name]
    action = next(a for a in sub._actions if "--column-file" in a.option_strings)
    assert action.help.startswith(column_file_help(many=name == "columns"))
    args = parser.parse_args(["campaign", name, "--column-file", DORIC])
    options = from_args(campaign.get(name).options, args).kwargs()
    assert DORIC in (options.get("column_file"), *(options.get("column_files") or []))


def test_slenderness_scales_every_block_height_to_the_sweep():
    data = ColumnGeometry.load(DORIC).to_dict()
    six = at_slenderness(data, 6.0)
    heights = [b["height"] for b in six["blocks"]]
    # by hand: overall h/d 10.43 / 1.905 = 5.475; at h/d 6 the column is 6 x 1.905 =
    # 11.43 m high, every block x 11.43 / 10.43: drum 1 0.95 -> 1.041083413 m, the
    # abacus 0.35 -> 0.383557047 m
    assert heights[0] == pytest.approx(1.041083413, abs=1e-9)
    assert heights[-1] == pytest.approx(0.383557047, abs=1e-9)
    assert math.fsum(heights) == pytest.approx(11.43, abs=1e-7)
    three = at_slenderness(data, 3.0)
    assert three["blocks"][0]["height"] == pytest.approx(0.520541707, abs=1e-9)   # x 5.715/10.43
    for scaled in (six, three):
        g = ColumnGeometry.from_dict(scaled)
        assert g.base_width == 1.905
        for a, b in zip(data["blocks"], scaled["blocks"]):    # only heights change
            assert {k: v for k, v in a.items() if k != "height"} == \
                {k: v for k, v in b.items() if k != "height"}
    assert six["name"] == f"{DORIC} at h/d 6"


def test_slenderness_campaign_runs_the_scaled_column_with_its_own_kn(record, tmp_path):
    specs = _specs("slenderness", record, tmp_path, column_file=DORIC)
    assert [s.params.column.hd for s in specs] == list(paper.SLENDERNESS_HD)
    for spec in specs:
        g = ColumnGeometry.from_dict(spec.params.column.column_file)
        assert g.height / g.base_width == pytest.approx(spec.params.column.hd, rel=1e-8)
        assert spec.params.contact.kn == matched_kn(g)


def test_slenderness_too_tall_for_the_format_is_refused(tmp_path):
    shaft = {"shape": "frustum", "height": 10.0, "bottom_diameter": 3.5, "top_diameter": 3.5}
    one = {"name": "shaft", "density": 2700, "blocks": [shaft]}
    assert at_slenderness(one, 8.0)["blocks"][0]["height"] == pytest.approx(28.0)
    with pytest.raises(InputError, match="scaled to h/d 9: .*height"):
        at_slenderness(one, 9.0)                      # one block of 31.5 m: above 30 m
    wide = {**shaft, "bottom_diameter": 5.0, "top_diameter": 5.0}
    with pytest.raises(InputError, match="scaled to h/d 9: .*45 m high"):
        at_slenderness({**one, "blocks": [wide, wide]}, 9.0)    # a 45 m column: above 40 m


def test_perturbed_description_applies_tolerances_tilt_and_offsets():
    data = ColumnGeometry.load(DORIC).to_dict()
    rng = np.random.default_rng(3)
    member = perturbed(data, 1.01, 0.99, 0.33, 0.0, 0.003, rng)
    for k, (a, b) in enumerate(zip(data["blocks"], member["blocks"])):
        assert b["height"] == pytest.approx(a["height"] * 1.01, abs=1e-9)
        for key in ("bottom_diameter", "top_diameter", "width", "depth"):
            if key in a:
                assert b[key] == pytest.approx(a[key] * 0.99, abs=1e-9)
        if a.get("joined"):               # the abacus: carved with the echinus
            assert "tilt_deg" not in b and "offset_m" not in b
            continue
        assert b["tilt_deg"] == pytest.approx(0.0, abs=1e-6)   # 0.33 south + 0.33 north
        if k == 0:
            assert "offset_m" not in b
        else:
            assert 0 < math.hypot(*b["offset_m"]) <= 0.003
    leaning = perturbed(data, tilt_deg=0.33, tilt_azimuth_deg=90.0)
    assert leaning["blocks"][0]["tilt_deg"] == pytest.approx(0.33 * math.sqrt(2), abs=1e-6)
    assert leaning["blocks"][0]["tilt_azimuth_deg"] == pytest.approx(135.0, abs=1e-6)


def test_ensemble_members_are_the_perturbed_described_column(record, tmp_path):
    specs = _specs("ensemble", record, tmp_path, column_file=DORIC, members=4)
    nominal, members = specs[0], specs[1:]
    assert nominal.tags.member == -1
    assert nominal.params.column.column_file == ColumnGeometry.load(DORIC).to_dict()
    assert nominal.params.contact.kn == DORIC_KN
    heights = {round(math.fsum(b["height"] for b in s.params.column.column_file["blocks"]), 6)
               for s in members}
    assert len(heights) == 4 and all(abs(h / 10.43 - 1) <= 0.01 + 1e-9 for h in heights)
    for spec in members:
        blocks = spec.params.column.column_file["blocks"]
        assert any("offset_m" in b for b in blocks[1:])
        assert spec.params.column.geometry.to_dict() == spec.params.column.column_file
    again = _specs("ensemble", record, tmp_path, column_file=DORIC, members=4)
    assert [s.run_id for s in again] == [s.run_id for s in specs]   # seeded


def test_fragility_block_takes_the_described_height_and_base_width(record, tmp_path):
    specs = _specs("fragility", record, tmp_path, column_file=DORIC, azimuths=4)
    for spec in specs:
        data = spec.params.column.column_file
        g = ColumnGeometry.from_dict(data)
        height, width = pulse_block.block_size(spec.params)
        assert height == pytest.approx(g.height) and width == pytest.approx(g.base_width)
        assert abs(height / 10.43 - 1) <= 0.01 + 1e-9 and abs(width / 1.905 - 1) <= 0.01 + 1e-9
        assert not any("offset_m" in b for b in data["blocks"])       # as described
    table, _ = block_runs(specs)
    for spec in specs:
        rows = table[table["run_id"] == spec.run_id]
        height, width = pulse_block.block_size(spec.params)
        assert rows["height_m"].tolist() == pytest.approx([height] * 2)
        assert rows["alpha_rad"].tolist() == pytest.approx([math.atan(width / height)] * 2)


@pytest.mark.parametrize("name", sorted(CAMPAIGN_OPTIONS))
def test_outputs_name_the_column_file(name, record, tmp_path):
    """campaign.json gets ``column_file`` from the outputs (here without finished runs)."""
    specs = _specs(name, record, tmp_path, column_file=DORIC)
    result = campaign.get(name).outputs(specs, tmp_path, [], 0, figures=False)
    assert result["column_file"] == ColumnGeometry.load(DORIC).to_dict()
    default = _specs(name, record, tmp_path / "default")
    assert "column_file" not in campaign.get(name).outputs(default, tmp_path / "default", [],
                                                           0, figures=False)


@pytest.mark.parametrize("name, extra", [
    ("slenderness", []), ("friction", []), ("records", []),
    ("ensemble", ["--members", "2", "--vary", "drum_offset_mm=0,0"]),
    ("fragility", ["--members", "2", "--levels", "0.5", "--azimuths", "4"])])
def test_sub_threshold_campaign_names_the_column_file_end_to_end(name, extra, tmp_path):
    """A pulse below the described column's uplift threshold: YADE is not started, the
    tables and campaign.json are written and name the description."""
    path = tmp_path / "weak.npz"
    m = one_sine_pulse(30.0, 0.5, duration=2.0)
    Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": "weak"}).save(path)
    out = tmp_path / name
    assert cli.main(["campaign", name, "--records", str(path), "--column-file", DORIC,
                     "--out", str(out), "--jobs", "1", "--animations", "0", *extra]) == 0
    done = json.loads((out / "campaign.json").read_text())
    assert done["column_file"]["name"] == DORIC and not done["failed"]
    import pandas as pd
    table = pd.read_csv(out / {"ensemble": "members.csv",
                               "fragility": "fragility_runs.csv"}.get(name, "runs.csv"))
    three_d = table[table["column"].isin(["drums", "monolithic"])]
    assert len(three_d) and not three_d["simulated"].astype(bool).any()
    if name in ("ensemble", "slenderness", "friction", "records"):
        assert three_d["description"].str.startswith(DORIC).all()
    if name == "ensemble":
        assert json.loads((out / "ensemble_summary.json").read_text())["column_file"] == DORIC
    if name == "fragility":
        summary = json.loads((out / "fragility.json").read_text())
        assert summary["column_file"] == DORIC
        blocks = table[table["model"] == "2D"]
        assert (abs(blocks["height_m"] / 10.43 - 1) <= 0.01 + 1e-9).all()
