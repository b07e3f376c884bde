"""Contact parameters from a free-rocking test: the restitution of synthetic decays of a
rigid block (Housner's equation integrated with a known restitution) is recovered, from a
tilt record and from the rocking frequency with the amplitude ratio; the command writes
the contact file and refuses bad input in one line."""
import json
import math
import re

import numpy as np
import pytest

from pipeline import cli, paper
from pipeline.rocking.decay import fit_free_rocking
from pipeline.rocking.response import housner_free_rocking
from pipeline.files import InputError

BLOCK = paper.MARBLE_BLOCK_M          # the paper's marble block: 0.40 x 0.08 m, h/b 5
H, B = BLOCK["height"], BLOCK["width"]


def recorded_decay(restitution, dt=0.002, impacts=8):
    """A decay as an instrument records it: uniform samples of the rigid block's tilt,
    released from rest at half its overturning angle."""
    out = housner_free_rocking(H, B, 0.5 * math.atan(B / H), n_impacts=impacts,
                                       restitution=restitution)
    t = np.arange(0.0, out["t"][-1], dt)
    return out, t, np.interp(t, out["t"], out["theta"])


@pytest.mark.parametrize("restitution", [0.75, 0.85, 0.93, None])
def test_restitution_recovered_from_a_tilt_record(restitution):
    out, t, theta = recorded_decay(restitution)
    fit = fit_free_rocking(H, B, t=t, theta=theta)
    assert fit["restitution"] == pytest.approx(out["restitution"], abs=2e-3)
    assert fit["restitution_sd"] < 2e-3          # a rigid block: every impact alike
    assert fit["impacts"] >= 6
    # the paper's block: Housner's 1 - 1.5 sin^2(atan(1/5)) = 1 - 1.5 / 26
    assert fit["housner_restitution"] == pytest.approx(1 - 1.5 / 26, rel=1e-12)


def test_tilt_in_degrees_and_noise():
    out, t, theta = recorded_decay(0.85)
    noisy = theta + np.random.default_rng(1).normal(0.0, 2e-4, theta.size)
    fit = fit_free_rocking(H, B, t=t, theta=noisy)
    # noise of 2e-4 rad on amplitudes of ~0.05 rad: restitution within 0.01, scatter said
    assert fit["restitution"] == pytest.approx(0.85, abs=0.01)
    assert fit["restitution_sd"] > 0 and fit["restitution_se"] < fit["restitution_sd"]


@pytest.mark.parametrize("restitution", [0.8, 0.9])
def test_restitution_from_frequency_and_amplitude_ratio(restitution):
    out = housner_free_rocking(H, B, 0.5 * math.atan(B / H), n_impacts=6,
                                       restitution=restitution)
    impacts, peaks = out["impact_times"], np.abs(out["peak_theta"])
    # the swing between impacts 2 and 3 has the amplitude after 3 impacts: half a cycle
    frequency = 1.0 / (2.0 * (impacts[3] - impacts[2]))
    fit = fit_free_rocking(H, B, frequency_hz=frequency,
                                   amplitude_ratios=[peaks[4] / peaks[3]])
    # the amplitude from the linearised period (eq 7): slender block, within 0.005
    assert fit["restitution"] == pytest.approx(restitution, abs=5e-3)
    assert fit["restitution_sd"] is None


def test_amplitude_beyond_alpha_refused():
    out, t, theta = recorded_decay(0.85)
    with pytest.raises(InputError, match="overturning angle"):
        fit_free_rocking(H, B, t=t, theta=theta * 57.3)


def test_command_writes_the_contact_file(tmp_path, capsys):
    out, t, theta = recorded_decay(0.85)
    decay = tmp_path / "decay.csv"
    decay.write_text("time_s,tilt_deg\n" + "".join(
        f"{a:.4f},{math.degrees(b):.6f}\n" for a, b in zip(t, theta)))
    target = tmp_path / "contact.json"
    assert cli.main(["contact", "--free-rocking", str(decay), "--block", f"{H},{B}",
                     "--out", str(target)]) == 0
    written = json.loads(target.read_text())
    assert written["restitution"] == pytest.approx(0.85, abs=3e-3)
    assert written["block"] == {"height_m": H, "width_m": B}


@pytest.mark.parametrize("argv, message", [
    (["--block", "0.4"], "2 numbers"),
    (["--block", "0.4,0.08"], "either --free-rocking"),
    (["--block", "0.4,0.08", "--frequency-hz", "2"], "needs --amplitude-ratio"),
    (["--block", "0.4,0.08", "--frequency-hz", "2", "--amplitude-ratio", "1.2"], "in \\(0, 1\\)"),
    (["--block", "0.4,0.08", "--frequency-hz", "-2", "--amplitude-ratio", "0.5"],
     "frequency-hz"),
    (["--block", "50,0.08", "--frequency-hz", "2", "--amplitude-ratio", "0.5"], "--block"),
    (["--block", "0.4,0.08", "--free-rocking", "missing.csv"], "not found"),
    (["--block", "0.4,0.08", "--frequency-hz", "2", "--amplitude-ratio", "0.5", "--kn", "1e8"],
     "go\\(es\\) with --damping-map"),
    (["--block", "0.4,0.08", "--frequency-hz", "2", "--amplitude-ratio", "0.5", "--damping-map",
      "--density", "5"], "density"),
    (["--frequency-hz", "2", "--amplitude-ratio", "0.5"], "either --block"),
    (["--block", "0.4,0.08", "--column-file", "doric-peristyle", "--frequency-hz", "2",
      "--amplitude-ratio", "0.5"], "either --block"),
    (["--block", "0.4,0.08", "--azimuth", "90", "--frequency-hz", "2",
      "--amplitude-ratio", "0.5"], "--azimuth goes with --column-file"),
    (["--column-file", "doric-peristyle", "--azimuth", "360", "--frequency-hz", "2",
      "--amplitude-ratio", "0.5"], "--azimuth must be in"),
    (["--column-file", "doric-peristyle", "--depth", "0.1", "--frequency-hz", "2",
      "--amplitude-ratio", "0.5"], "go\\(es\\) with --block"),
])
def test_command_refuses_bad_input(tmp_path, capsys, argv, message):
    target = tmp_path / "contact.json"
    code = cli.main(["contact", *argv, "--out", str(target)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    assert re.search(message, err)
    assert not target.exists()


def test_decay_file_without_tilt_column_refused(tmp_path, capsys):
    decay = tmp_path / "decay.csv"
    decay.write_text("time,angle\n0,0.01\n0.01,0.02\n")
    code = cli.main(["contact", "--free-rocking", str(decay), "--block", "0.4,0.08",
                     "--out", str(tmp_path / "c.json")])
    assert code == 2 and "tilt_rad" in capsys.readouterr().err


@pytest.mark.parametrize("text, message", [
    ('{"restitution": 0.95}', "no kn and damping"),
    ('{"kn": 1.2e7, "damping": 0.1, "stiffnes": 1}', "unknown key"),
    ('[1, 2]', "JSON object"),
    ('{"kn": 1.2e7,', "not readable JSON"),
    ('{"kn": true, "damping": 0.1}', "'kn' must be a finite number"),
])
def test_run_refuses_a_bad_contact_file(tmp_path, capsys, text, message):
    contact = tmp_path / "contact.json"
    contact.write_text(text)
    out = tmp_path / "run"
    code = cli.main(["run", "--record", "GM20", "--contact-file", str(contact),
                     "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and message in err
    assert not out.exists()


def test_contact_file_values_are_range_checked_and_not_doubled(tmp_path, capsys):
    contact = tmp_path / "contact.json"
    contact.write_text('{"kn": 1e3, "damping": 0.1}')
    assert cli.main(["run", "--record", "GM20", "--contact-file", str(contact),
                     "--out", str(tmp_path / "a")]) == 2
    assert "--contact-file contact.json: 'kn' 1000 outside" in capsys.readouterr().err
    contact.write_text('{"kn": 1.2e8, "damping": 0.1}')
    assert cli.main(["run", "--record", "GM20", "--contact-file", str(contact), "--damping",
                     "0.2", "--out", str(tmp_path / "b")]) == 2
    assert "not both" in capsys.readouterr().err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_column_file_is_read_as_its_equivalent_block(tmp_path, capsys):
    """A column description's decay is read with the block of its critical angle toward
    the azimuth: a box column's equivalent block is the box itself (Housner's value of
    its width over height)."""
    box = tmp_path / "box.json"
    box.write_text(json.dumps({"name": "box", "density": 2700, "blocks": [
        {"shape": "box", "height": H, "width": B, "depth": 0.2}]}))
    target = tmp_path / "contact.json"
    assert cli.main(["contact", "--frequency-hz", "2.4", "--amplitude-ratio", "0.74,0.73",
                     "--column-file", str(box), "--azimuth", "90", "--out", str(target)]) == 0
    written = json.loads(target.read_text())
    alpha = math.atan(B / H)
    assert written["specimen"]["critical_angle_deg"] == pytest.approx(math.degrees(alpha),
                                                                       abs=1e-6)
    assert written["housner_restitution"] == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2)
    by_block = tmp_path / "block.json"
    assert cli.main(["contact", "--frequency-hz", "2.4", "--amplitude-ratio", "0.74,0.73",
                     "--block", f"{H},{B}", "--out", str(by_block)]) == 0
    assert written["restitution"] == pytest.approx(
        json.loads(by_block.read_text())["restitution"], abs=1e-9)


def test_noise_recorded_at_rest_is_cut_from_the_decay_and_said(tmp_path, capsys):
    """A decay (restitution 0.85) that comes to rest and then records smooth noise of
    3 mrad for 4 s: the noise's swings, each above the noise the second differences
    measure, do not decay; read as swings they pull the restitution to ~0.99.  They are
    left out from where the block is at rest, and the command says so."""
    out = housner_free_rocking(H, B, 0.5 * math.atan(B / H), n_impacts=8, restitution=0.85)
    t = np.arange(0.0, out["t"][-1] + 4.0, 0.002)
    theta = np.interp(t, out["t"], out["theta"], right=0.0)
    noise = np.convolve(np.random.default_rng(0).normal(0.0, 1.0, t.size), np.ones(25) / 25,
                        mode="same")
    at_rest = t > out["t"][-1]
    theta[at_rest] += 3e-3 * noise[at_rest] / noise.std()
    fit = fit_free_rocking(H, B, t=t, theta=theta)
    assert fit["restitution"] == pytest.approx(0.85, abs=2e-3)
    assert fit["rest"] is not None and fit["rest"]["swings"] > 10
    assert fit["rest"]["from_s"] <= out["t"][-1]
    decay = tmp_path / "decay.csv"
    decay.write_text("time_s,tilt_rad\n" + "".join(f"{a:.4f},{b:.7f}\n"
                                                  for a, b in zip(t, theta)))
    target = tmp_path / "contact.json"
    assert cli.main(["contact", "--free-rocking", str(decay), "--block", f"{H},{B}",
                     "--out", str(target)]) == 0
    said = capsys.readouterr().out
    assert "note: the block is at rest from" in said and "left out of the fit" in said
    written = json.loads(target.read_text())
    assert written["restitution"] == pytest.approx(0.85, abs=3e-3)
    assert written["source"]["swings_at_rest"] == fit["rest"]["swings"]


def test_a_clean_decay_has_nothing_at_rest():
    out, t, theta = recorded_decay(0.85)
    assert fit_free_rocking(H, B, t=t, theta=theta)["rest"] is None
