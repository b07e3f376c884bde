"""survival's and constrain's options as declared fields: made in code they are checked as
on the command line (the same one line), repeated flags are typed per value, and the
defaults the help states are the ones taken (the observed correlation, rock Vs30)."""
import argparse
import json
import math

import pytest

from pipeline import cli
from pipeline.cli import constrain as constrain_command
from pipeline.cli import survival as survival_command
from pipeline.cli._fields import from_args
from pipeline.files import InputError
from pipeline.assessment.constrain_options import ConstrainOptions
from pipeline.assessment.options import SurvivalOptions

HAZARD = "records/hazard/usgs_nshm2014r1_curves_-118_34_vs760.json"
TREE = "records/hazard/openquake_logictree_case_11"


def _parsed(command, argv):
    parser = argparse.ArgumentParser()
    command.setup(parser)
    return parser.parse_args(argv)


def test_options_made_in_code_are_refused_with_the_command_lines_words(capsys, tmp_path):
    argv = ["survival", "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3", "--beta",
            "4", "--out", str(tmp_path / "out")]
    assert cli.main(argv) == 2
    said = capsys.readouterr().err.strip().splitlines()[-1]
    with pytest.raises(InputError) as refused:
        SurvivalOptions(hazard=(HAZARD,), age_ka=15.0, median_g=(0.3,), beta=(4.0,),
                        out=tmp_path / "out")
    assert said == f"error: {refused.value}"
    assert not (tmp_path / "out").exists()


def test_repeated_flags_are_numbers_and_one_age_serves_every_specimen():
    args = _parsed(constrain_command, ["--logic-tree", TREE, "--median-g", "0.3", "--beta",
                                       "0.4", "--median-g", "0.5", "--beta", "0.3",
                                       "--age-ka", "2"])
    options = from_args(ConstrainOptions, args)
    assert options.median_g == (0.3, 0.5) and options.beta == (0.4, 0.3)
    assert options.ages() == ([2.0, 2.0], [0.0, 0.0])
    with pytest.raises(InputError, match="one --age-ka per specimen"):
        from_args(ConstrainOptions, _parsed(constrain_command, [
            "--logic-tree", TREE, "--median-g", "0.3", "--beta", "0.4", "--age-ka", "2",
            "--age-ka", "3"]))


def test_the_defaults_taken_are_those_the_help_states():
    options = from_args(SurvivalOptions, _parsed(survival_command, [
        "--hazard", HAZARD, "--age-ka", "15", "--median-g", "0.3", "--beta", "0.4",
        "--magnitude", "6.5", "--distance-km", "10"]))
    assert (options.vs30, options.mechanism, options.draws, options.seed,
            options.age_sd_ka, options.below_grid) == (760.0, "SS", 400, 0, 0.0, "ramp")
    ratio = options.ratio_model(options.specimens())
    assert ratio.correlation == 0.654            # Baker & Bradley (2017), observed
    assert ratio.vs30_m_s == 760.0


def _survival(tmp_path, capsys, *age):
    out = tmp_path / "out"
    argv = ["survival", "--hazard", HAZARD, "--median-g", "0.3", "--beta", "0.4",
            "--draws", "0", "--out", str(out), *age]
    code = cli.main(argv)
    said = capsys.readouterr().err.strip().splitlines()
    if code != 0:
        return code, said[-1]
    return code, json.loads((out / "survival.json").read_text())


def test_ages_as_dated_give_their_closed_forms(tmp_path, capsys):
    """A lower bound: exp(-r min); an interval: (exp(-r lo) - exp(-r hi)) / (r (hi -
    lo)); samples from a file: the mean of exp(-r t); the rate the same under each."""
    _, bound = _survival(tmp_path, capsys, "--age-min-ka", "15")
    rate = bound["annual_overturning_rate_per_yr"]
    assert bound["survival_probability"] == pytest.approx(math.exp(-rate * 15e3), rel=1e-12)
    assert bound["age"]["kind"] == "lower_bound" and bound["age_ka"] is None
    assert bound["rate_scale_bound_5pct"] == pytest.approx(-math.log(0.05) / (rate * 15e3))
    _, interval = _survival(tmp_path, capsys, "--age-range-ka", "13", "22")
    assert interval["annual_overturning_rate_per_yr"] == rate
    lo, hi = 13e3, 22e3
    assert interval["survival_probability"] == pytest.approx(
        (math.exp(-rate * lo) - math.exp(-rate * hi)) / (rate * (hi - lo)), rel=1e-9)
    ages = tmp_path / "ages.csv"
    ages.write_text("# exposure ages\nsample,age_ka\n1,12\n2,15\n3,21\n")
    _, sampled = _survival(tmp_path, capsys, "--age-samples", str(ages), "--age-column",
                           "age_ka")
    assert sampled["survival_probability"] == pytest.approx(
        sum(math.exp(-rate * t * 1e3) for t in (12, 15, 21)) / 3, rel=1e-12)


@pytest.mark.parametrize("age, words", [
    (("--age-range-ka", "22", "13"), "--age-range-ka 22 13: the interval is upside down"),
    (("--age-ka", "15", "--age-min-ka", "10"), "give one kind of age: --age-ka or "
     "--age-min-ka"),
    (("--age-min-ka", "15", "--age-sd-ka", "2"), "--age-sd-ka applies with --age-ka"),
    (("--age-min-ka", "0"), "--age-min-ka 0 outside the allowed range (0, 10000] ka"),
])
def test_an_age_badly_given_is_one_line_and_nothing_written(tmp_path, capsys, age, words):
    code, said = _survival(tmp_path, capsys, *age)
    assert code == 2 and said.startswith(f"error: {words}")
    assert not (tmp_path / "out").exists()


def test_age_samples_of_one_column_need_no_column_name(tmp_path, capsys):
    """A file of one column: that column, as when named; several and none named: one
    line naming them, nothing written."""
    one = tmp_path / "one.csv"
    one.write_text("# exposure ages\nage_ka\n12\n15\n21\n")
    _, taken = _survival(tmp_path, capsys, "--age-samples", str(one))
    _, named = _survival(tmp_path, capsys, "--age-samples", str(one), "--age-column",
                         "age_ka")
    assert taken["survival_probability"] == named["survival_probability"]
    assert taken["age"]["samples"] == 3
    two = tmp_path / "two.csv"
    two.write_text("sample,age_ka\n1,12\n")
    code, said = _survival(tmp_path / "refused", capsys, "--age-samples", str(two))
    assert code == 2 and said == (f"error: {two}: 2 columns ('sample', 'age_ka'): name the "
                                  "one holding the ages (--age-column)")
    assert not (tmp_path / "refused").exists()


def test_constrain_takes_an_interval_age_for_every_specimen():
    args = _parsed(constrain_command, ["--logic-tree", TREE, "--median-g", "0.3", "--beta",
                                       "0.4", "--median-g", "0.5", "--beta", "0.3",
                                       "--age-range-ka", "1", "3"])
    options = from_args(ConstrainOptions, args)
    assert [(a.lo_yr, a.hi_yr) for a in options.age_models()] == [(1e3, 3e3)] * 2
    with pytest.raises(InputError, match="one --age-range-ka per specimen"):
        from_args(ConstrainOptions, _parsed(constrain_command, [
            "--logic-tree", TREE, "--median-g", "0.3", "--beta", "0.4", "--age-range-ka",
            "1", "3", "--age-range-ka", "2", "4"]))


def test_each_default_and_range_is_declared_once_and_the_help_says_it():
    """The help states the declared default and range (from the field, not prose); an
    open end is refused at the end itself."""
    parser = argparse.ArgumentParser()
    constrain_command.setup(parser)
    text = " ".join(parser.format_help().split())
    assert "--floor P survival probability below which elimination drops a branch; " \
        "default 0.05; 0-1 (above 0 and below 1)" in text
    assert "--draws N fragility parameter draws for the survival interval (0: none); " \
        "default 400; 0-20000" in text
    with pytest.raises(InputError, match=r"--floor 1 outside the allowed range \(0, 1\)"):
        from_args(ConstrainOptions, _parsed(constrain_command, [
            "--logic-tree", TREE, "--median-g", "0.3", "--beta", "0.4", "--age-ka", "2",
            "--floor", "1"]))
    with pytest.raises(InputError, match=r"--median-g 20 outside the allowed range \[0.001, 10\] g"):
        from_args(ConstrainOptions, _parsed(constrain_command, [
            "--logic-tree", TREE, "--median-g", "0.3", "--beta", "0.4", "--median-g", "20",
            "--beta", "0.4", "--age-ka", "2"]))


def test_the_fragility_form_auto_is_declared_and_reads_a_columns_surface(tmp_path):
    """--fragility-form's default is declared (auto: the logistic surface of a column
    file; tests/hazard/test_pulse_grid_survival: a pulse grid's cells) and taken."""
    from dataclasses import replace
    from tests.hazard.test_survival import _fragility_json
    parser = argparse.ArgumentParser()
    survival_command.setup(parser)
    text = " ".join(parser.format_help().split())
    assert "auto: pga-pgv for columns, grid for a pulse grid; default auto" in text
    options = from_args(SurvivalOptions, _parsed(survival_command, [
        "--hazard", HAZARD, "--age-ka", "15", "--fragility",
        str(_fragility_json(tmp_path / "fragility.json")), "--magnitude", "6.5",
        "--distance-km", "10", "--draws", "0", "--out", str(tmp_path / "out")]))
    assert options.fragility_form == "auto"
    auto, = options.specimens()
    stated, = replace(options, fragility_form="pga-pgv").specimens()
    assert auto.inner.coefficients == stated.inner.coefficients == (1.0, 3.0, 2.0)  # the file's
    assert replace(options, fragility_form="pga").specimens()[0].inner.median_m_s2 == 3.0


def test_a_required_logic_tree_left_out_is_refused_before_any_work():
    with pytest.raises(InputError, match="^give --logic-tree$"):
        ConstrainOptions(median_g=(0.3,), beta=(0.4,), age_ka=(2.0,))
