"""constrain --age KIND:VALUES: each specimen's age of its own kind.  Each specimen gets
the survival its kind gives it alone; a lower bound and an interval against the average
of exp(-rate t) over the age computed here; the age chain of mixed kinds against its
closed form; bad ages refused in one line with nothing written."""
import json
import math
import re
import shlex
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

from pipeline import RECORDS_DIR
from pipeline.cli import main
from tests.refusal import refused

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = RECORDS_DIR / "hazard" / "two_site_example"
TREE = EXAMPLE / "logic_tree_two_sites.csv"
SAMPLES = EXAMPLE / "age_samples_synthetic.csv"
ROCKS = (("0.8", "0.4"), ("1", "0.3"), ("0.9", "0.3"))


def _run(tmp_path, capsys, name, *argv, tree=TREE):
    out = tmp_path / name
    code = main(["constrain", "--logic-tree", str(tree), "--draws", "0", "--out", str(out),
                 *map(str, argv)])
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    return json.loads((out / "constrain.json").read_text())


def _p(run):
    return np.array([b["survival_probability"] for b in run["branches"]])


def _rock(k):
    return ["--median-g", ROCKS[k][0], "--beta", ROCKS[k][1]]


def _three_sites(tmp_path):
    """The example's table with a third site, a copy of site 0."""
    lines = TREE.read_text().splitlines()
    third = [line[:-1] + "2" for line in lines if line.endswith(",0")]
    path = tmp_path / "three_sites.csv"
    path.write_text("\n".join(lines + third) + "\n")
    return path


def _rate(tmp_path, capsys, k, site, *more):
    """Each branch's annual rate of overturning of rock k (and ``more``) at ``site``:
    -ln P / t of a known age t."""
    rocks = [*_rock(k), *more]
    known = _run(tmp_path, capsys, f"known{k}{len(more)}", *rocks, "--age-ka", "1",
                 "--site", site)
    return -np.log(_p(known)) / 1e3


def test_each_specimen_gets_the_survival_of_its_own_kind(tmp_path, capsys):
    """Three rocks at three far sites, a lower bound, an interval and a normal age: the
    set's survival is the product of three runs of one rock and one kind of age, and the
    lowest specimen's survival that of the right rock."""
    tree = _three_sites(tmp_path)
    kinds = (["--age-min-ka", "10.5"], ["--age-range-ka", "13", "22"],
             ["--age-ka", "15", "--age-sd-ka", "3"])
    mixed = _run(tmp_path, capsys, "mixed", *_rock(0), *_rock(1), *_rock(2), "--age",
                 "lower_bound:10.5", "--age", "interval:13,22", "--age", "normal:15,3",
                 *[a for s in (0, 1, 2) for a in ("--specimen-site", s)], tree=tree)
    alone = [_p(_run(tmp_path, capsys, f"alone{k}", *_rock(k), *kinds[k], "--site", k,
                     tree=tree)) for k in range(3)]
    np.testing.assert_allclose(_p(mixed), np.prod(alone, axis=0), rtol=1e-12)
    assert [s["age"]["kind"] for s in mixed["specimens"]] == ["lower_bound", "interval",
                                                              "normal"]
    for row, *own in zip(mixed["branch_test"]["branches"], *alone):
        assert row["lowest_specimen"] == int(np.argmin(own))
        assert row["lowest_specimen_survival"] == pytest.approx(min(own), rel=1e-12)


def test_a_lower_bound_and_an_interval_against_the_average_over_the_age(tmp_path,
                                                                         capsys):
    """exp(-rate min) for a lower bound; the mean of exp(-rate t) over t uniform on
    [13, 22] ka by quadrature; the rate of each branch from a known age."""
    rate = _rate(tmp_path, capsys, 0, 0)
    for age, reference in (("lower_bound:10.5", np.exp(-rate * 10.5e3)),
                           ("interval:13,22", [integrate.quad(
                               lambda t, r=r: math.exp(-r * t), 13e3, 22e3)[0] / 9e3
                               for r in rate])):
        run = _run(tmp_path, capsys, age.split(":")[0], *_rock(0), "--age", age,
                   "--site", 0)
        np.testing.assert_allclose(_p(run), reference, rtol=1e-9)


def test_the_age_chain_of_mixed_kinds(tmp_path, capsys):
    """Two rocks at one site.  Known ages of two kinds: the chain of --age-ka exactly.  A
    lower bound a and an interval [lo, hi] (lo > a): both stand through a, the second
    alone through T - a, so P = exp(-rate_both a) E[exp(-rate_2 (T - a))], within the
    Monte Carlo's standard error."""
    two = [*_rock(0), *_rock(1), "--site", 0]
    mixed = _run(tmp_path, capsys, "known_mixed", *two, "--age", "lower_bound:10.5",
                 "--age", "normal:15")
    plain = _run(tmp_path, capsys, "known_plain", *two, "--age-ka", "10.5", "--age-ka", "15")
    assert mixed["age_model"] == plain["age_model"] == "known ages"
    np.testing.assert_array_equal(_p(mixed), _p(plain))
    both = _rate(tmp_path, capsys, 0, 0, *_rock(1))
    second = _rate(tmp_path, capsys, 1, 0)
    a, lo, hi = 10.5e3, 13e3, 22e3
    reference = np.exp(-both * a) * (np.exp(-second * (lo - a)) - np.exp(-second * (hi - a))) \
        / (second * (hi - lo))
    run = _run(tmp_path, capsys, "chain", *two, "--age", "lower_bound:10.5", "--age",
               "interval:13,22")
    assert run["age_model"].startswith("differing uncertain ages: Monte Carlo")
    se = np.array([b["survival_age_se_relative"] for b in run["branches"]])
    assert np.all(np.abs(_p(run) / reference - 1) < 4 * se + 1e-12)


def test_one_age_stated_for_all_and_a_samples_file(tmp_path, capsys):
    """One --age for every specimen; samples:FILE of one column without --age-column, as
    --age-samples with it."""
    two = [*_rock(0), *_rock(1), "--specimen-site", 0, "--specimen-site", 1]
    one = _run(tmp_path, capsys, "one", *two, "--age", "interval:13,22")
    each = _run(tmp_path, capsys, "each", *two, "--age-range-ka", "13", "22")
    np.testing.assert_array_equal(_p(one), _p(each))
    stated = _run(tmp_path, capsys, "stated", *two, "--age", f"samples:{SAMPLES}")
    column = _run(tmp_path, capsys, "column", *two, "--age-samples", SAMPLES,
                  "--age-column", "age_ka")
    np.testing.assert_array_equal(_p(stated), _p(column))


def _bad_samples(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("age_ka\n12\nabout 13\n")
    return path


def _two_columns(tmp_path):
    path = tmp_path / "two.csv"
    path.write_text("sample,age_ka\n1,12\n2,15\n")
    return path


@pytest.mark.parametrize("ages, words", [
    (("--age", "interval:22,13"), "--age interval:22,13: the interval is upside down"),
    (("--age", "weird:1"), "--age 'weird:1': expected KIND:VALUES, the kind one of"),
    (("--age", "15"), "--age '15': expected KIND:VALUES"),
    (("--age", "normal:1,2,3"), "--age normal:1,2,3: expected normal:MEAN[,SD] (ka)"),
    (("--age", "lower_bound:0"), "--age lower_bound:0: 0 ka outside (0, 10000] ka"),
    (("--age", "interval:0,0"), "--age interval:0,0: 0 ka outside (0, 10000] ka"),
    (("--age", "normal:2,-1"), "--age normal:2,-1: -1 ka outside [0, 10000] ka"),
    (("--age", "lower_bound:old"), "expected lower_bound:MIN, numbers in ka"),
    (("--age", "lower_bound:nan"), "--age lower_bound:nan: nan ka outside"),
    (("--age", "samples:"), "expected samples:FILE"),
    (("--age", "lower_bound:1", "--age", "lower_bound:2"),
     "give one --age per specimen (3) or one for all, got 2"),
    (("--age", "lower_bound:1", "--age-ka", "2"), "--age gives each specimen's age: not "
     "with --age-ka"),
    (("--age", "lower_bound:1", "--age-sd-ka", "2"), "not with --age-sd-ka"),
    (("--age", "lower_bound:1", "--age-column", "age_ka"), "--age-column applies with "
     "--age-samples or --age samples:FILE"),
    (("--age-ka", "2", "--age-min-ka", "1"), "give one kind of age: --age-ka or "
     "--age-min-ka, not both; ages of several kinds: one --age KIND:VALUES per specimen"),
    (("--age", "samples:{two}"), "two.csv: 2 columns ('sample', 'age_ka'): name the one "
     "holding the ages (--age-column)"),
    (("--age-samples", "{two}"), "two.csv: 2 columns"),
    (("--age", "samples:{bad}"), "bad.csv: data row 2, column age_ka: not a number"),
])
def test_an_age_badly_given_is_one_line_and_nothing_written(tmp_path, capsys, ages, words):
    files = {"two": _two_columns(tmp_path), "bad": _bad_samples(tmp_path)}
    out = tmp_path / "out"
    refused(capsys, ["constrain", "--logic-tree", TREE, *_rock(0), *_rock(1), *_rock(2),
                     "--specimen-site", 0, "--draws", 0, "--out", out,
                     *[a.format(**files) for a in ages]], words, out)


def _docs_examples():
    """The docs' commands that use the shipped example, as written."""
    for page in ("constrained-hazard.md", "survival.md"):
        text = (ROOT / "docs" / page).read_text()
        for line in re.findall(r"\.venv/bin/python -m pipeline (.*two_site_example.*)", text):
            yield pytest.param(shlex.split(line), id=f"{page}: {line[:50]}")


@pytest.mark.parametrize("argv", list(_docs_examples()))
def test_the_docs_examples_on_the_shipped_example_run(tmp_path, capsys, monkeypatch, argv):
    """Run from the repository root as the docs give them (the output elsewhere)."""
    monkeypatch.chdir(ROOT)
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    name = "constrain.json" if argv[0] == "constrain" else "survival.json"
    result = json.loads((out / name).read_text())
    if argv[0] == "constrain":
        assert [(s["site"], s["specimens"]) for s in result["sites"]] == [(0, [0]),
                                                                          (1, [1, 2])]
        assert [s["age"]["kind"] for s in result["specimens"]] == [
            "lower_bound", "interval", "samples"]
    else:
        assert result["age"]["samples"] == 200
