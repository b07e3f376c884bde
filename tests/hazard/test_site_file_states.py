"""``survival --observations`` with damage states takes each state's lognormal from the
``damage_states`` fits of ``--fragility`` when ``--state-lognormal`` is not given: the same
bound as the stated lognormals when the file's fits equal them, the closed form of the
likelihood, the states put on the hazard's PGA as the toppling fit is, and a file without
damage-state fits refused in one line where a column's state needs them."""
import json

import numpy as np
import pytest
from scipy import stats

from pipeline.cli import main

G = 9.80665
# the file's fits (m/s^2): slight, moderate, severe per state; collapse the toppling fit
MEDIANS_G = {"slight": 0.1, "moderate": 0.2, "severe": 0.4, "collapse": 0.8}
BETAS = {"slight": 0.5, "moderate": 0.45, "severe": 0.4, "collapse": 0.4}
COLUMNS = [{"column": "drums", "state": "standing", "damage_state": "moderate"},
           {"column": "drums", "state": "standing", "residual_slide_m": 0.03,
            "base_width_m": 1.0},                        # 0.03 D: moderate or worse
           {"column": "drums", "state": "fallen", "downfall_azimuth_deg": 10.0}]


def _fit(state, n=100, reached=50):
    return {"median": MEDIANS_G[state] * G, "beta": BETAS[state], "unit": "m/s^2",
            "n": n, "toppled": reached}


def _fragility(path, states=True):
    reached = {"slight": 90, "moderate": 70, "severe": 60, "collapse": 50}
    data = {"records": ["R1"], "members": 1,
            "columns": {"drums": {"model": "3D", "description": "drums", "runs": 100,
                                  "toppled": 50, "PGA": _fit("collapse")}}}
    if states:
        data["damage_states"] = {"drums": {"description": "drums", "runs": 100, "states": {
            s: {"runs": 100, "reached": k, "PGA": _fit(s, reached=k)}
            for s, k in reached.items()}}}
    path.mkdir()
    (path / "fragility.json").write_text(json.dumps(data))
    return path / "fragility.json"


def _observations(path, columns=COLUMNS):
    path.write_text(json.dumps({"sites": [{"name": "A", "east_km": 0, "north_km": 0,
                                           "columns": columns}]}))
    return path


def _run(tmp_path, name, fragility, extra=(), columns=COLUMNS):
    out = tmp_path / name
    argv = ["survival", "--observations", str(_observations(tmp_path / f"{name}.json",
                                                             columns)),
            "--fragility", str(fragility), "--fragility-form", "pga", "--out", str(out),
            *extra]
    assert main(argv) == 0
    return json.loads((out / "site_motion.json").read_text())


def _closed_form_ml_g(scale=1.0):
    """The maximum of L = (Phi(z2) - Phi(z3)) (Phi(z2) - Phi(z4)) Phi(z4), z_k = ln(a /
    m_k) / beta_k, found on a fine grid (g)."""
    a = np.geomspace(0.02, 5.0, 400001)
    z = {s: np.log(a / (MEDIANS_G[s] * scale)) / BETAS[s] for s in MEDIANS_G}
    phi = {s: stats.norm.cdf(v) for s, v in z.items()}
    ll = np.log(phi["moderate"] - phi["severe"]) + \
        np.log(phi["moderate"] - phi["collapse"]) + np.log(phi["collapse"])
    return a[np.argmax(ll)]


def test_the_files_fits_give_the_stated_lognormals_bound(tmp_path):
    fragility = _fragility(tmp_path / "campaign")
    on = ["--hazard-component", "rotd100"]           # the file's PGA: no conversion
    from_file = _run(tmp_path, "file", fragility, on)
    stated = _run(tmp_path, "stated", fragility, on + [
        a for s in ("slight", "moderate", "severe")
        for a in ("--state-lognormal", f"{s},{MEDIANS_G[s]:g},{BETAS[s]:g}")])
    assert from_file["pga_ml_m_s2"] == pytest.approx(stated["pga_ml_m_s2"], rel=1e-9)
    for a, b in zip(from_file["pga_interval95_m_s2"], stated["pga_interval95_m_s2"]):
        assert a == pytest.approx(b, rel=1e-9)
    assert from_file["pga_ml_g"] == pytest.approx(_closed_form_ml_g(), rel=1e-4)
    assert from_file["column_states"] == stated["column_states"]
    source = from_file["state_fragilities_from"]["drums"]
    assert str(fragility) in source and "damage_states.drums" in source
    assert stated["state_fragilities_from"] == {"drums": "stated (--state-lognormal)"}
    moderate = from_file["state_fragilities"]["drums"]["moderate"]
    assert moderate["median_m_s2"] == pytest.approx(MEDIANS_G["moderate"] * G)


def test_the_states_are_put_on_the_hazards_pga_as_the_toppling_fit(tmp_path):
    result = _run(tmp_path, "rotd50", _fragility(tmp_path / "campaign"))
    fraction = result["fragilities"]["drums"]["pga_measure"]["fraction"]
    assert 0.6 < fraction < 1.0
    for state in ("slight", "moderate", "severe"):
        measure = result["state_fragilities"]["drums"][state]["pga_measure"]
        assert measure["fraction"] == fraction
    # every median moved by the one fraction: P_hazard(x) = P(x / f)
    assert result["pga_ml_g"] == pytest.approx(_closed_form_ml_g(fraction), rel=1e-4)


def test_a_file_without_damage_state_fits_is_refused_in_one_line(tmp_path, capsys):
    fragility = _fragility(tmp_path / "campaign", states=False)
    out = tmp_path / "out"
    argv = ["survival", "--observations", str(_observations(tmp_path / "obs.json")),
            "--fragility", str(fragility), "--fragility-form", "pga", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "holds no damage-state fits" in err
    assert "observed moderate" in err and str(fragility) in err and "put on" not in err
    assert not out.exists()


def test_fell_and_stood_alone_need_no_damage_state_fits(tmp_path):
    fragility = _fragility(tmp_path / "campaign", states=False)
    columns = [{"column": "drums", "state": "standing"},
               {"column": "drums", "state": "fallen", "downfall_azimuth_deg": 10.0}]
    result = _run(tmp_path, "plain", fragility, ["--hazard-component", "rotd100"],
                  columns)
    # one of two identical lognormal columns fell: the maximum at the median
    assert result["pga_ml_g"] == pytest.approx(MEDIANS_G["collapse"], rel=1e-6)
    assert "state_fragilities" not in result and "state_fragilities_from" not in result
