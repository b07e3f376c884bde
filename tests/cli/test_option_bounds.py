"""Options bounded before any work: the long-run gate counts a campaign's runs from its
options before any run spec is built (a pulse grid of 2,500 cells, 10,000 members, an
ensemble sized up to 10,000 members), options that would be ignored are refused in
combination, and the free-rocking fit reads a noisy decay and refuses one that does not
decay.  Each refusal is one `error:` line, exit 2, and writes nothing."""
import math

import numpy as np
import pytest

from pipeline import cli, paper
from pipeline.rocking.decay import fit_free_rocking, slowest_rocking_hz
from pipeline.rocking.response import housner_free_rocking
from pipeline.files import InputError

SP1 = "records/shake_table/sp1.json"


def refused(capsys, argv):
    """The one error line of a refused command (exit 2)."""
    code = cli.main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: ") and "Traceback" not in err, err
    return last


def no_specs(monkeypatch):
    """Building any of the fragility campaign's run specs fails the test: the gate must
    come first (every campaign module imported first, so none keeps the stand-in)."""
    from pipeline import campaign
    from pipeline.campaign import fragility
    campaign.discover()

    def built(*args, **kwargs):
        pytest.fail("run specs built before the long-run gate")
    monkeypatch.setattr(fragility, "column_specs", built)
    monkeypatch.setattr(fragility, "_pulse_specs", built)


# ---------------------------------------------------------------- the gate from the options
@pytest.mark.parametrize("options, runs, hours", [
    # 50 x 50 cells x 4 members x 4 headings; a run's cost 0.3 + 0.2 (2 pi r + 4) core-s
    (["--pulses", "pga_g=0.1:1:50;pgv_pga_s=0.1:1:50"], 40000,
     40000 * (0.3 + 0.2 * (2 * math.pi * 0.55 + 4.0)) / 2 / 3600),
    # the mesh specimen's default grid vsr (10 x 10 cells, PGV/PGA 0.1-1.0 s) x 10,000 x 4
    (["--members", "10000"], 4_000_000,
     4_000_000 * (0.3 + 0.2 * (2 * math.pi * 0.55 + 4.0)) / 2 / 3600),
])
@pytest.mark.parametrize("adaptive", [False, True])
def test_a_fragility_grid_of_hours_is_refused_before_any_spec(tmp_path, capsys, monkeypatch,
                                                              options, runs, hours, adaptive):
    no_specs(monkeypatch)
    out = tmp_path / "out"
    err = refused(capsys, ["campaign", "fragility", "--column-file", SP1, "--jobs", "2",
                           "--out", str(out), *options] + (["--adaptive"] if adaptive else []))
    assert f"({runs} runs," in err and "--allow-long" in err
    said = float(err.split("would take about ")[1].split()[0])
    unit = err.split("would take about ")[1].split()[1]
    assert said == pytest.approx(hours if unit == "h" else hours / 24, abs=0.051)
    assert not out.exists()


def test_past_the_gate_the_specs_are_built(tmp_path, capsys, monkeypatch):
    """With --allow-long the campaign goes on to its specs (stood in for), after one
    warning naming the count."""
    from pipeline.campaign import fragility

    def built(*args, **kwargs):
        raise InputError("specs")
    monkeypatch.setattr(fragility, "_pulse_specs", built)
    code = cli.main(["campaign", "fragility", "--column-file", SP1, "--jobs", "2", "--out",
                     str(tmp_path / "out"), "--allow-long",
                     "--pulses", "pga_g=0.1:1:50;pgv_pga_s=0.1:1:50"])
    captured = capsys.readouterr()
    assert code == 2 and captured.err.strip().splitlines()[-1] == "error: specs"
    assert captured.out.count("warning: campaign fragility (40000 runs") == 1


def test_a_sized_ensemble_is_gated_on_the_members_it_may_reach(tmp_path, capsys, monkeypatch):
    """--members 1 --max-members 10000: 10,000 members and the nominal run may be reached:
    refused before the first batch; with --allow-long the first batch starts."""
    from pipeline import campaign
    out = tmp_path / "out"
    for members in ([], ["--members", "1"]):
        monkeypatch.setattr(campaign, "run_campaign",
                            lambda *a, **k: pytest.fail("a batch ran before the gate"))
        err = refused(capsys, ["campaign", "ensemble", "--record", "GM20", *members,
                               "--max-members", "10000", "--precision", "0.001", "--jobs",
                               "2", "--out", str(out)])
        assert "up to 10000 members" in err and "(10001 runs, 9 core-s each)" in err
        assert "12.5 h" in err and "--allow-long" in err            # 10001 x 9 / 2 s
        assert not out.exists()

    def started(name, **kwargs):
        raise InputError(f"started {kwargs['options']['record_members']}")
    monkeypatch.setattr(campaign, "run_campaign", started)
    err = refused(capsys, ["campaign", "ensemble", "--record", "GM20", "--members", "1",
                           "--max-members", "10000", "--precision", "0.001", "--jobs", "2",
                           "--out", str(out), "--allow-long"])
    assert err == "error: started {'GM20': 1}"


# ---------------------------------------------------------------- options refused
@pytest.mark.parametrize("argv, words", [
    (["campaign", "shake-table", "--tests", ",,,"], "names no test"),
    (["campaign", "ensemble", "--record", "GM20", "--precision", "0"],
     "--precision 0 outside the allowed range (0, 0.5]"),
    (["campaign", "ensemble", "--record", "GM20", "--arc-deg", "0"],
     "--arc-deg 0 outside the allowed range (0, 360] deg"),
    (["campaign", "fragility", "--pulses", "vsr", "--azimuth", "90", "--headings", "4"],
     "--azimuth fixes the direction: --headings 4"),
    (["campaign", "fragility", "--pulses", "vsr", "--levels", "1,2"],
     "--levels scales records"),
    (["campaign", "fragility", "--column-file", SP1, "--levels", "1,2"],
     "--levels scales records"),              # a mesh specimen: the pulse grid by default
    (["campaign", "fragility", "--pulses", "pga_g=0.3:0.3000000001:2;pgv_pga_s=0.2:0.2:1"],
     "--pulses pga_g: its 2 values are only 1 distinct"),
    (["campaign", "slenderness", "--stiffness", "paper"],
     "--stiffness sets a described column's kn: add --column-file"),
    (["campaign", "ensemble", "--record", "GM20", "--stiffness", "matched"],
     "--stiffness sets a described column's kn"),
])
def test_options_refused_before_any_work(tmp_path, capsys, monkeypatch, argv, words):
    from pipeline import campaign
    monkeypatch.setattr(campaign, "run_campaign", lambda *a, **k: pytest.fail("ran"))
    out = tmp_path / "out"
    err = refused(capsys, argv + ["--out", str(out)])
    assert words in err
    assert not out.exists()


@pytest.mark.parametrize("rings, words", [
    ("1e9", "1e+09 km: the generator takes rings of 0.05-100 km"),
    ("0.01", "0.01 km: the generator takes rings of 0.05-100 km"),
    ("5,nan", "the generator takes rings of 0.05-100 km"),
    ("5,5", "a ring given twice"),
])
def test_synthetics_rings_are_refused_by_the_generators_range(tmp_path, capsys, monkeypatch,
                                                               rings, words):
    from pipeline.motion.synthetics import compute, sites
    monkeypatch.setattr(sites, "DEFAULT_OUT_DIR", tmp_path / "synthetics")
    monkeypatch.setattr(compute, "_point_source_task", lambda *a: pytest.fail("computed"))
    err = refused(capsys, ["synthetics", "--rings", rings, "--jobs", "1"])
    assert words in err
    assert not (tmp_path / "synthetics").exists()


@pytest.mark.parametrize("name, extra", [
    ("ensemble", ["--record", "GM20", "--column-file", "doric-peristyle"]),
    ("fragility", ["--column-file", "doric-peristyle"]),
    ("slenderness", ["--column-file", "doric-peristyle"]),
    ("columns", []),
])
def test_stiffness_beside_a_contact_files_kn_is_refused(tmp_path, capsys, name, extra):
    """The contact file's kn goes over --stiffness: both given, one is ignored: refused;
    a file without kn leaves --stiffness its column's kn."""
    contact = tmp_path / "contact.json"
    contact.write_text('{"kn": 1e8, "damping": 0.1}')
    out = tmp_path / "out"
    err = refused(capsys, ["campaign", name, *extra, "--stiffness", "paper", "--contact-file",
                           str(contact), "--out", str(out), "--jobs", "1"])
    assert "--contact-file sets kn, which --stiffness sets too" in err
    assert not out.exists()


def test_a_one_row_pulse_grid_is_allowed():
    from pipeline.campaign.fragility import FragilityOptions, parse_grid
    grid = parse_grid("pga_g=0.3:0.5:3;pgv_pga_s=0.2:0.2:1")
    assert list(grid["pgv_pga_s"]) == [0.2] and list(grid["pga_g"]) == [0.3, 0.4, 0.5]
    FragilityOptions(pulses="pga_g=0.3:0.5:3;pgv_pga_s=0.2:0.2:1")


def test_azimuth_alone_shakes_one_heading_and_headings_alone_keep_theirs():
    from pipeline.campaign.fragility import DEFAULT_HEADINGS, FragilityOptions
    assert FragilityOptions(pulses="vsr", azimuth=90.0).kwargs()["headings"] == 1
    assert FragilityOptions(pulses="vsr", azimuth=90.0, headings=1).kwargs()["headings"] == 1
    assert FragilityOptions(pulses="vsr").kwargs()["headings"] == DEFAULT_HEADINGS
    assert FragilityOptions(pulses="vsr", headings=6).kwargs()["headings"] == 6


# ---------------------------------------------------------------- records
def test_a_finely_sampled_table_is_refused_before_processing_allocates(tmp_path, capsys,
                                                                      monkeypatch):
    """2,000 rows every 10 us: the filter's 2 x 120 s of margins would make 24 million
    samples a component (0.6 GB an array): refused before any array of that size."""
    from pipeline.records import processing
    path = tmp_path / "lab.txt"
    t = 1e-5 * np.arange(2000)
    path.write_text("# lab-table: fine\n# units: g\n# axes: 90\n" + "".join(
        f"{a:.7f} {0.1 * math.sin(2 * math.pi * 200 * a):.6f}\n" for a in t))
    monkeypatch.setattr(processing, "Work", lambda *a, **k: pytest.fail("processed"))
    out = tmp_path / "out"
    err = refused(capsys, ["records", str(path), "--out", str(out), "--no-figures"])
    held = 2000 + 2 * math.ceil(120.0 / 1e-5)
    assert f"make {held:,} samples" in err and "lab.txt" in err
    assert not out.exists()


# ---------------------------------------------------------------- contact
H, B = paper.MARBLE_BLOCK_M["height"], paper.MARBLE_BLOCK_M["width"]


def test_a_block_too_small_for_the_frequency_is_one_line(tmp_path, capsys):
    """A 0.01 x 0.005 m block: p = sqrt(3 g / (4 R)), R its half-diagonal; below 0.99
    alpha Housner's linearised period T = 4 / p acosh(1 / (1 - 0.99)) is its slowest."""
    out = tmp_path / "contact.json"
    err = refused(capsys, ["contact", "--block", "0.01,0.005", "--frequency-hz", "0.01",
                           "--amplitude-ratio", "0.5", "--out", str(out)])
    p = math.sqrt(3 * 9.81 / (4 * 0.5 * math.hypot(0.01, 0.005)))
    slowest = p / (4 * math.acosh(100.0))
    assert "no block of that size rocks at that frequency" in err
    assert f"{slowest:.3g} Hz" in err
    assert not out.exists()
    assert slowest_rocking_hz(0.01, 0.005) == pytest.approx(slowest, rel=1e-3)


def decay(restitution, noise_rad, seed, tail_s=1.0, dt=0.002):
    """A rigid block's decay (Housner's equation, ``restitution``) released at half its
    overturning angle, sampled every ``dt`` s, at rest ``tail_s`` s after its last
    peak, with white noise of ``noise_rad``."""
    out = housner_free_rocking(H, B, 0.5 * math.atan(B / H), n_impacts=8,
                                       restitution=restitution)
    t = np.arange(0.0, out["t"][-1] + tail_s, dt)
    theta = np.interp(t, out["t"], out["theta"], right=0.0)
    return t, theta + np.random.default_rng(seed).normal(0.0, noise_rad, t.size)


@pytest.mark.parametrize("restitution", [0.85, 0.93])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_noisy_decay_gives_its_restitution_within_its_error(restitution, seed):
    """Noise of 1 mrad on amplitudes of 0.1 rad down to the noise, and a second at rest:
    its zero crossings are no swings; the restitution within 4 standard errors and
    0.01 of the true one (the former mean over impacts read 2.0 here and refused it)."""
    t, theta = decay(restitution, 1e-3, seed)
    fit = fit_free_rocking(H, B, t=t, theta=theta)
    assert fit["restitution_se"] is not None and fit["restitution_se"] < 0.005
    assert abs(fit["restitution"] - restitution) < max(4 * fit["restitution_se"], 1e-3)
    assert abs(fit["restitution"] - restitution) < 0.01
    assert 4 <= fit["impacts"] <= 8


@pytest.mark.parametrize("noise_rad", [0.0, 1e-3])
def test_a_constant_amplitude_is_refused(tmp_path, capsys, noise_rad):
    t = np.arange(0.0, 10.0, 0.002)
    theta = 0.05 * np.sin(2 * math.pi * 1.3 * t)
    theta += np.random.default_rng(0).normal(0.0, noise_rad, t.size)
    with pytest.raises(InputError, match="do not decay"):
        fit_free_rocking(H, B, t=t, theta=theta)
    record = tmp_path / "decay.csv"
    record.write_text("time_s,tilt_rad\n" + "".join(f"{a:.4f},{b:.7f}\n"
                                                    for a, b in zip(t, theta)))
    out = tmp_path / "contact.json"
    err = refused(capsys, ["contact", "--free-rocking", str(record), "--block", f"{H},{B}",
                           "--out", str(out)])
    assert "do not decay" in err and not out.exists()


@pytest.mark.parametrize("argv, flag", [
    (["survival", "--median-g", "0.3", "--beta", "0.4", "--age-ka", "1", "--age-ka", "2"],
     "--age-ka"),
    (["campaign", "ensemble", "--record", "GM20", "--precision", "0.1", "--precision", "0.2"],
     "--precision"),
    (["survival", "--median-g", "0.3", "--beta", "0.4", "--draws", "10", "--draws", "10"],
     "--draws"),
])
def test_a_one_value_flag_given_twice_is_refused(tmp_path, capsys, argv, flag):
    """A later value would replace the first unseen: refused, naming the flag."""
    out = tmp_path / "out"
    err = refused(capsys, argv + ["--out", str(out)])
    assert flag in err and "given more than once" in err
    assert not out.exists()
