"""The readers survival and invert take a user's files through (fragility.json, hazard
curves) against files that are wrong in one value: each refused in one line naming the
key and what it must be, exit code 2 and nothing written; and the pulse grids the
campaign writes with one row, and what P is above a grid, against closed forms."""
import copy
import json
import math
import os
import re

import numpy as np
import pytest
from scipy import stats

from pipeline.cli import main
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard import load_hazard
from pipeline.hazard.fragility import Lognormal, load_campaign_fragility
from pipeline.hazard.fragility.file import check_fragility

G = STANDARD_GRAVITY
BK = math.exp(-0.185774509051029)        # RotD50 / RotD100 of PGA, Boore & Kishida (2017)

COLUMN = {"records": ["R1", "R2"], "members": 4, "block2d": {"alpha_rad": 0.2, "p_per_s": 2.0},
          "columns": {"monolithic": {
              "description": "3D YADE monolithic column", "runs": 80, "toppled": 30,
              "PGA": {"median": 3.0, "beta": 0.4, "median_ci95": [2.4, 3.75],
                      "beta_ci95": [0.3, 0.55], "unit": "m/s^2", "n": 80, "toppled": 30,
                      "note": None},
              "logistic": {"coefficients": {"b0": 1.0, "b1": 3.0, "b2": 2.0},
                           "se": {"b0": 0.3, "b1": 0.2, "b2": 0.25},
                           "ci95": {"b0": [0.4, 1.6], "b1": [2.6, 3.4], "b2": [1.5, 2.5]},
                           "cov": [[0.09, 0.03, 0.05], [0.03, 0.04, 0.01],
                                   [0.05, 0.01, 0.0625]],
                           "n": 80, "toppled": 30, "note": None}}}}


def grid_document(pga_g=(0.1, 0.2, 0.4), ratios=(0.1, 0.2), p_of=lambda a, r: 0.5, n=20,
                  sets=2, logistic=(-2.0, 3.0, 0.5), uplift_g=0.05):
    """A pulse-grid fragility.json as campaign fragility --pulses writes it: cell
    fractions p_of(PGA g, PGV/PGA s) rounded to counts of n, each set's P the cell's."""
    cells = []
    for a in pga_g:
        for r in ratios:
            k = int(round(n * p_of(a, r)))
            lo, hi = stats.binomtest(k, n).proportion_ci(method="wilson")
            cells.append({"pga_g": a, "pgv_pga_s": r, "n": n, "overturned": k, "P": k / n,
                          "ci95": [float(lo), float(hi)], "P_per_set": [k / n] * sets,
                          "sets": list(range(sets))})
    model = {"cells": cells, "runs": n * len(cells),
             "overturned": sum(c["overturned"] for c in cells)}
    if logistic is not None:
        model["logistic"] = {"coefficients": dict(zip(("b0", "b1", "b2"), logistic)),
                             "se": {"b0": 0.1, "b1": 0.1, "b2": 0.1}, "cov": None}
    return {"mode": "pulses", "specimen": "test rock",
            "pulse_grid": {"pga_g": list(pga_g), "pgv_pga_s": list(ratios), "members": sets,
                           "models": {"monolithic": model},
                           "block2d": {"alpha_rad": math.atan(uplift_g), "uplift_g": uplift_g,
                                       "uplift_g_smallest": uplift_g}}}


def write(path, data):
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return path


def changed(document, change):
    data = copy.deepcopy(document)
    change(data)
    return data


def _mono(d):
    return d["columns"]["monolithic"]


def _cell(d, k=0):
    return d["pulse_grid"]["models"]["monolithic"]["cells"][k]


# ---------------------------------------------------------------- fragility.json
COLUMN_ROWS = [
    # a value of the wrong type where an object or a list is expected
    (lambda d: d["columns"].update(monolithic=[1, 2]), "columns.monolithic must be an object"),
    (lambda d: d["columns"].update(monolithic=5), "columns.monolithic must be an object"),
    (lambda d: _mono(d).update(logistic=[1, 2, 3]), "columns.monolithic.logistic must be an object"),
    (lambda d: _mono(d)["logistic"].update(se=[0.1, 0.2]), "logistic.se must be an object"),
    (lambda d: _mono(d)["logistic"].update(se=0.3), "logistic.se must be an object"),
    (lambda d: _mono(d)["logistic"]["se"].update(b1="0.2"), "logistic.se.b1 must be a finite"),
    (lambda d: d.update(records=3), "records must be a list"),
    (lambda d: d.update(records=[1, 2]), r"records\[0\] must be a record id"),
    (lambda d: _mono(d).update(PGA=[3.0, 0.4]), "columns.monolithic.PGA must be an object"),
    (lambda d: _mono(d)["logistic"].update(coefficients=[1, 3, 2]), "coefficients must be an obj"),
    # a covariance of the wrong shape, a scalar, strings, NaN, not positive semi-definite
    (lambda d: _mono(d)["logistic"].update(cov=[[0.09, 0.03], [0.03, 0.04]]),
     "logistic.cov must be a 3x3 list of numbers"),
    (lambda d: _mono(d)["logistic"].update(cov=0.09), "logistic.cov must be a 3x3 list of numbers"),
    (lambda d: _mono(d)["logistic"]["cov"][0].__setitem__(1, "x"), "cov must be a 3x3 list"),
    (lambda d: _mono(d)["logistic"]["cov"][0].__setitem__(0, float("nan")), "finite numbers"),
    (lambda d: _mono(d)["logistic"].update(cov=[[1, 2, 0], [2, 1, 0], [0, 0, 1]]),
     "not positive semi-definite"),
    (lambda d: _mono(d)["logistic"]["cov"][0].__setitem__(1, 0.5), "not symmetric"),
    # counts: bounded integers
    (lambda d: d.update(members=10 ** 9), "members must be 1 to 10000"),
    (lambda d: d.update(members=10 ** 400), "members must be 1 to 10000"),
    (lambda d: _mono(d).update(toppled=81), "toppled must be 0 to 80"),
    (lambda d: _mono(d)["PGA"].update(n=80.0), "PGA.n must be an integer"),
    # an interval that does not hold its estimate
    (lambda d: _mono(d)["PGA"].update(median_ci95=[3.2, 3.75]), "does not hold its estimate 3"),
    (lambda d: _mono(d)["logistic"]["ci95"].update(b1=[3.5, 4.0]), r"ci95.b1 \[3.5, 4\]"),
    (lambda d: d.update(columns={}), "no 'columns'"),
]


@pytest.mark.parametrize("change, message", COLUMN_ROWS)
def test_a_column_fragility_file_wrong_in_one_value_is_refused_in_one_line(
        tmp_path, capsys, change, message):
    path = write(tmp_path / "fragility.json", changed(COLUMN, change))
    with pytest.raises(InputError, match=message) as caught:
        load_campaign_fragility(path, None, "pga-pgv")
    assert "\n" not in str(caught.value) and str(path) in str(caught.value)
    _survival_refuses(tmp_path, capsys, ["--fragility", str(path)], message)


GRID_ROWS = [
    (lambda d: d["pulse_grid"].update(pga_g=0.3), "pulse_grid.pga_g must be a list"),
    (lambda d: d["pulse_grid"].update(models=[]), "pulse_grid.models must be an object"),
    (lambda d: d["pulse_grid"]["models"].update(monolithic="x"), "models.monolithic must be an"),
    (lambda d: _cell(d).update(n=10 ** 9), r"cells\[0\].n must be 0 to 10000000"),
    (lambda d: _cell(d).update(n=10 ** 30), r"cells\[0\].n must be 0 to 10000000"),
    (lambda d: _cell(d).update(n=20.0), r"cells\[0\].n must be an integer"),
    (lambda d: d["pulse_grid"].update(members=10 ** 9), "pulse_grid.members must be 1 to 10000"),
    (lambda d: d["pulse_grid"].update(members=True), "pulse_grid.members must be an integer"),
    (lambda d: _cell(d).update(overturned=-1), r"cells\[0\].overturned must be 0 to 20"),
    (lambda d: d["pulse_grid"]["models"]["monolithic"]["cells"].append(_cell(d, 1)),
     r"holds 7 values \(at most 6\)"),
    (lambda d: _cell(d, 5).update(pga_g=0.1, pgv_pga_s=0.1),
     r"cells\[5\] duplicates the cell at pga_g 0.1, pgv_pga_s 0.1"),
    (lambda d: _cell(d).update(sets=[0, -1]), r"cells\[0\].sets must be 0 to 1"),
    (lambda d: _cell(d).update(sets=[0, 0]), "names a parameter set twice"),
    (lambda d: _cell(d).update(P_per_set=[0.5, 1.5]), r"P_per_set\[1\] 1.5 outside"),
    (lambda d: _cell(d).update(P=0.9), r"cells\[0\].P 0.9 is not overturned / n = 10/20"),
    (lambda d: _cell(d).update(ci95=[0.6, 0.8]), "does not hold its estimate 0.5"),
    (lambda d: d["pulse_grid"].update(pga_g=[0.1, 0.3, 0.3000000000001]), "must increase"),
    (lambda d: _cell(d).update(pga_g=0.15), "a cell off the grid"),
    (lambda d: d["pulse_grid"]["block2d"].update(uplift_g="0.05"), "block2d.uplift_g must be a"),
    (lambda d: d.update(specimen=["x"]), "specimen must be a text"),
]


@pytest.mark.parametrize("change, message", GRID_ROWS)
def test_a_pulse_grid_file_wrong_in_one_value_is_refused_in_one_line(
        tmp_path, capsys, change, message):
    path = write(tmp_path / "fragility.json", changed(grid_document(), change))
    with pytest.raises(InputError, match=message) as caught:
        load_campaign_fragility(path)
    assert "\n" not in str(caught.value) and str(path) in str(caught.value)
    _survival_refuses(tmp_path, capsys, ["--fragility", str(path)], message)


def test_the_documents_above_are_valid_and_older_spellings_load(tmp_path):
    assert check_fragility(copy.deepcopy(COLUMN)) == COLUMN
    assert check_fragility(grid_document()) == grid_document()
    # an older file: a covariance written as nulls (singular), cells without sets, the 2D
    # block without uplift_g_smallest, the logistic surface without a covariance
    old = changed(COLUMN, lambda d: _mono(d)["logistic"].update(
        cov=[[None] * 3] * 3, ci95=None))
    surface = load_campaign_fragility(write(tmp_path / "old.json", old), None, "pga-pgv")
    assert surface.cov is None and "no covariance" in surface.note
    grid = grid_document()
    for cell in grid["pulse_grid"]["models"]["monolithic"]["cells"]:
        del cell["sets"]
    del grid["pulse_grid"]["block2d"]["uplift_g_smallest"]
    loaded = load_campaign_fragility(write(tmp_path / "old_grid.json", grid))
    assert loaded.uplift_m_s2 == pytest.approx(0.05 * G)


def _survival_refuses(tmp_path, capsys, argv, message):
    """survival with these arguments: exit 2, one line matching ``message``, nothing
    written."""
    out = tmp_path / "out"
    curve = _power_law_curve(tmp_path / "curve.csv", 0.05 * G, 3.0 * G)
    capsys.readouterr()
    assert main(["survival", "--hazard", str(curve), "--age-ka", "2", "--pgv-pga-median",
                 "0.1", "--pgv-pga-sigma", "0.3", "--draws", "10", "--out", str(out),
                 *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error:"), err
    assert re.search(message, err), err
    assert not out.exists()


def test_invert_site_fragility_with_a_column_entry_that_is_a_number(tmp_path, capsys):
    from pipeline.inversion import EXAMPLES_DIR
    path = write(tmp_path / "fragility.json", {"columns": {"monolithic": 5, "drums": 5}})
    out = tmp_path / "out"
    assert main(["invert", str(EXAMPLES_DIR / "two_sites.json"), "--out", str(out),
                 "--site-fragility", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "columns.monolithic must be an object, got a number 5" in err
    assert not out.exists()


def test_survival_refuses_the_same_fragility_twice(tmp_path, capsys):
    (tmp_path / "campaign").mkdir()
    path = write(tmp_path / "campaign" / "fragility.json", grid_document())
    link = tmp_path / "link.json"
    os.symlink(path, link)
    for other in (path, path.parent, link, tmp_path / "campaign" / ".." / "campaign"):
        _survival_refuses(tmp_path, capsys, ["--fragility", str(path), "--fragility",
                                             str(other)], "the same specimen twice")


# ---------------------------------------------------------------- hazard files
def _power_law_curve(path, low_m_s2, high_m_s2, k0=1e-4, k=2.5, n=60):
    """A plain hazard table of the rate k0 x^-k per year (x in m/s^2) at n PGA levels."""
    levels = np.geomspace(low_m_s2, high_m_s2, n)
    return write(path, "pga_m_s2,annual_rate_per_yr\n" + "".join(
        f"{float(x)!r},{float(k0 * x ** -k)!r}\n" for x in levels))


USGS_DOC = {"response": [{"metadata": {
    "imt": {"value": "PGA"}, "xlabel": "Ground Motion (g)",
    "ylabel": "Annual Frequency of Exceedence", "xvals": [0.01, 0.1, 0.5, 1.0],
    "latitude": 34.0, "longitude": -118.0, "edition": {"display": "NSHM"},
    "vs30": {"display": "760 m/s"}}, "data": [{"yvals": [0.1, 0.01, 1e-3, 1e-4]}]}]}


def _usgs_meta(d):
    return d["response"][0]["metadata"]


HAZARD_ROWS = [
    ("plain.csv", "pga_g,annual_rate_per_yr\n0.1,inf\n0.2,1e-3\n", "rate at 0.1 g is infinite"),
    ("plain.csv", "pga_g,annual_rate_per_yr\n0.1,1e-2\n1e308,1e-3\n", "at most 100 g"),
    ("plain.csv", "pga_g,annual_rate_per_yr\n0.1,1e-2\n0.2,nan\n", "is not a number"),
    ("usgs.json", changed(USGS_DOC, lambda d: d["response"][0]["data"][0]["yvals"]
                          .__setitem__(0, float("inf"))), "infinite"),
    ("usgs.json", changed(USGS_DOC, lambda d: _usgs_meta(d).update(edition="NSHM")),
     "metadata.edition must be an object"),
    ("usgs.json", changed(USGS_DOC, lambda d: d["response"][0].update(metadata=[1])),
     r"response\[0\].metadata must be an object"),
    ("usgs.json", changed(USGS_DOC, lambda d: _usgs_meta(d).update(vs30=760)),
     "metadata.vs30 must be an object"),
    ("usgs.json", changed(USGS_DOC, lambda d: _usgs_meta(d).update(imt="PGA")),
     "metadata.imt must be an object"),
    ("usgs.json", changed(USGS_DOC, lambda d: _usgs_meta(d)["imt"].update(value=["PGA"])),
     "imt.value must be a text"),
    ("usgs.json", changed(USGS_DOC, lambda d: _usgs_meta(d).update(latitude=float("nan"))),
     "latitude must be a number"),
    ("usgs.json", '{"response": ' + "[" * 100_000 + "]" * 100_000 + "}", "nested too deep"),
    ("oq.csv", "#,,,\"kind='mean', investigation_time=50.0, imt='PGA'\"\nlon,lat,poe-0.1,"
               "poe-0.2\nnan,10,0.1,0.01\n", "lon nan is not a coordinate"),
]


@pytest.mark.parametrize("name, content, message", HAZARD_ROWS)
def test_a_hazard_file_wrong_in_one_value_is_refused_in_one_line(tmp_path, capsys, name,
                                                                  content, message):
    path = write(tmp_path / name, content)
    with pytest.raises(InputError, match=message) as caught:
        load_hazard(path)
    assert "\n" not in str(caught.value) and str(path) in str(caught.value)
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(path), "--median-g", "0.3", "--beta", "0.4",
                 "--age-ka", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message.replace("\\", "") in err
    assert not out.exists()


def test_a_named_pipe_is_refused_before_it_is_read(tmp_path, capsys):
    fifo = tmp_path / "curve.csv"
    os.mkfifo(fifo)                    # no writer: reading it would wait for ever
    with pytest.raises(InputError, match="not a regular file"):
        load_hazard(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        load_campaign_fragility(fifo)
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(fifo), "--median-g", "0.3", "--beta", "0.4",
                 "--age-ka", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "not a regular file" in err and not out.exists()


# ---------------------------------------------------------------- one-row grids, above the top
def test_a_one_row_pulse_grid_meets_the_closed_form(tmp_path):
    # one PGV/PGA (pgv_pga_s=0.2:0.2:1): P lognormal in PGA, interpolated along PGA only;
    # under lambda = k0 x^-k the rate is k0 median^-k exp(k^2 beta^2 / 2) on the campaign's
    # PGA (--hazard-component rotd100)
    median, beta, k0, k = 3.0, 0.4, 1e-4, 2.5
    lognormal = Lognormal(median, beta)
    pga_g = list(np.geomspace(0.02, 5.0, 80))
    data = grid_document(pga_g, [0.2], lambda a, r: float(lognormal.probability(a * G)),
                         n=10 ** 6, logistic=None)
    path = write(tmp_path / "fragility.json", data)
    grid = load_campaign_fragility(path)
    a = np.array([0.05, 0.3, 1.1]) * G
    for ratio in (0.05, 0.2, 1.0):     # the same P at any PGV/PGA: the one row's
        assert grid.probability(a, np.full(3, ratio)) == pytest.approx(
            lognormal.probability(a), abs=2e-3)
    curve = _power_law_curve(tmp_path / "curve.csv", 0.01, 100.0, k0, k, 80)
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(curve), "--fragility", str(path),
                 "--pgv-pga-median", "0.2", "--pgv-pga-sigma", "0.3", "--age-ka", "2",
                 "--draws", "0", "--hazard-component", "rotd100", "--out", str(out)]) == 0
    summary = json.loads((out / "survival.json").read_text())
    closed = k0 * median ** -k * math.exp(0.5 * (k * beta) ** 2)
    assert summary["annual_overturning_rate_per_yr"] == pytest.approx(closed, rel=0.02)


def test_a_one_column_pulse_grid_is_linear_in_ln_pgv_pga(tmp_path):
    # one PGA: P linear in ln(PGV/PGA) between the cells is reproduced exactly
    def p_of(a, r):
        return 0.2 + 0.3 * math.log(r / 0.05) / math.log(4.0)
    data = grid_document([0.3], [0.05, 0.1, 0.2], p_of, n=10 ** 6)
    grid = load_campaign_fragility(write(tmp_path / "fragility.json", data))
    ratio = np.array([0.06, 0.13, 0.19])
    assert grid.probability(np.full(3, 0.3 * G), ratio) == pytest.approx(
        [p_of(0.3, r) for r in ratio], abs=1e-6)


def test_p_zero_at_the_grid_top_is_said_and_warned_under_a_hazard_far_beyond(tmp_path,
                                                                              capsys):
    # no run overturns anywhere on a grid up to 0.49 g, the hazard reaches 3.3 g: P = 0
    # carried above the grid gives survival 1; survival.json says how P is extended and
    # the rate with P = 1 above the grid: the curve's rate at the grid's top on the hazard's
    # RotD50, k0 (0.49 g BK)^-k (the power law is exact under log-log interpolation)
    k0, k = 1e-4, 2.5
    data = grid_document([0.1, 0.2, 0.3, 0.49], [0.1, 0.2], lambda a, r: 0.0, logistic=None)
    path = write(tmp_path / "fragility.json", data)
    curve = _power_law_curve(tmp_path / "curve.csv", 0.05 * G, 3.3 * G, k0, k, 40)
    out = tmp_path / "out"
    capsys.readouterr()
    assert main(["survival", "--hazard", str(curve), "--fragility", str(path),
                 "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3", "--age-ka", "2",
                 "--draws", "0", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / "survival.json").read_text())
    assert summary["survival_probability"] == 1.0
    outside = summary["outside_grid"]
    top = 0.49 * G * BK
    assert outside["pga_range_m_s2"][1] == pytest.approx(top)
    assert outside["hazard_reach_over_grid_top"] == pytest.approx(3.3 * G / top)
    assert outside["hazard_rate_above_grid_per_yr"] == pytest.approx(k0 * top ** -k, rel=1e-9)
    assert outside["rate_per_yr_one_above_grid"] == pytest.approx(k0 * top ** -k, rel=1e-9)
    above = summary["specimens"][0]["fragility"]["above_grid"]
    assert above["p_at_last_pga"]["P"] == [0.0, 0.0]
    assert "P stays 0 at every PGA above it" in above["note"]
    warning = [w for w in summary["warnings"] if "reaches" in w]
    assert len(warning) == 1 and "P = 0 at every PGA above" in warning[0]
    assert f"warning: {warning[0]}" in printed


def test_no_above_grid_warning_when_the_hazard_ends_inside_the_grid(tmp_path, capsys):
    data = grid_document(list(np.geomspace(0.05, 5.0, 20)), [0.1, 0.2],
                         lambda a, r: float(stats.norm.cdf(math.log(a / 0.5) / 0.4)),
                         n=10 ** 4)
    path = write(tmp_path / "fragility.json", data)
    curve = _power_law_curve(tmp_path / "curve.csv", 0.1 * G, 2.0 * G)
    out = tmp_path / "out"
    assert main(["survival", "--hazard", str(curve), "--fragility", str(path),
                 "--pgv-pga-median", "0.1", "--pgv-pga-sigma", "0.3", "--age-ka", "2",
                 "--draws", "0", "--out", str(out)]) == 0
    summary = json.loads((out / "survival.json").read_text())
    assert summary["outside_grid"]["hazard_rate_above_grid_per_yr"] == 0.0
    assert not [w for w in summary["warnings"] if "reaches" in w]
    assert summary["outside_grid"]["rate_per_yr_one_above_grid"] == pytest.approx(
        summary["annual_overturning_rate_per_yr"])


def test_every_cell_is_read_back_at_its_place(tmp_path):
    # P = overturned / n of every cell at its (PGA, PGV/PGA), whatever the cells' order
    def p_of(a, r):
        return min(1.0, a * r * 4.0)
    data = grid_document([0.1, 0.2, 0.4], [0.1, 0.2], p_of, n=100)
    data["pulse_grid"]["models"]["monolithic"]["cells"].reverse()
    grid = load_campaign_fragility(write(tmp_path / "fragility.json", data), below="logistic")
    for a in (0.1, 0.2, 0.4):
        for r in (0.1, 0.2):
            assert grid.probability(np.array([a * G]), np.array([r]))[0] == pytest.approx(
                round(100 * p_of(a, r)) / 100)


@pytest.mark.parametrize("depth, message", [(100_000, "nested too deep"),
                                            (40, "nested deeper than 32 levels")])
def test_a_fragility_file_nested_deep_is_refused_in_one_line(tmp_path, capsys, depth, message):
    text = '{"columns": {"monolithic": {"note": ' + "[" * depth + "]" * depth + "}}}"
    path = write(tmp_path / "fragility.json", text)
    with pytest.raises(InputError, match=message) as caught:
        load_campaign_fragility(path)
    assert "\n" not in str(caught.value)
    _survival_refuses(tmp_path, capsys, ["--fragility", str(path)], message)
