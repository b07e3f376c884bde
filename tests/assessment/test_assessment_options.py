"""survival's and constrain's options as declared fields: made in code they are checked as
on the command line (the same one line), repeated flags are typed per value, and the
defaults the help states are the ones taken (the observed correlation, rock Vs30)."""
import argparse

import pytest

from pipeline import cli
from pipeline.cli import constrain as constrain_command
from pipeline.cli import survival as survival_command
from pipeline.cli._fields import from_args
from pipeline.files import InputError
from pipeline.assessment.options import ConstrainOptions, SurvivalOptions

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
