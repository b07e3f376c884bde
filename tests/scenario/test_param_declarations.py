"""Every option declared once: a field whose default is None or () says what unset means
(``optional``) or that it must be given (``required``); ``param`` refuses any other, and
every options class of the package keeps to it."""
import argparse
import dataclasses
import importlib
import inspect
import pkgutil
import sys

import pytest

import pipeline
from pipeline.cli._fields import add_arguments
from pipeline.files import InputError
from pipeline.scenario.parameters import param


def _option_classes():
    """Every dataclass of the package with fields declared by ``param`` (each module
    imported: a class is found wherever it lives)."""
    for info in pkgutil.walk_packages(pipeline.__path__, "pipeline."):
        importlib.import_module(info.name)
    found = {}
    for name, module in list(sys.modules.items()):
        if not name.startswith("pipeline"):
            continue
        for obj in vars(module).values():
            if inspect.isclass(obj) and dataclasses.is_dataclass(obj) and \
                    obj.__module__ == name and any(
                        "unit" in f.metadata and "help" in f.metadata
                        for f in dataclasses.fields(obj)):
                found[f"{name}.{obj.__qualname__}"] = obj
    return found


CLASSES = _option_classes()


def test_the_walk_finds_the_options_classes():
    names = {name.rsplit(".", 1)[1] for name in CLASSES}
    assert {"SurvivalOptions", "ConstrainOptions", "HazardJobOptions", "ContactOptions",
            "InversionOptions", "ShakeTableOptions", "FragilityOptions", "EnsembleOptions",
            "Numerics", "Contact"} <= names


@pytest.mark.parametrize("default", [None, ()])
def test_param_refuses_an_unset_default_not_declared(default):
    with pytest.raises(TypeError, match="optional"):
        param(default, "", "a value", flag="--x")
    assert param(default, "", "a value", optional="none").metadata["optional"] == "none"
    assert param(default, "", "a value", required=True).metadata["required"]


def test_param_refuses_optional_beside_a_default():
    with pytest.raises(TypeError, match="only a default of None"):
        param(400, "", "draws", optional="none")


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_every_unset_default_is_declared(name):
    """No field of None or () that does not say what unset means (or that it is
    required): a real default lives in the declaration, nowhere else."""
    undeclared = [f.name for f in dataclasses.fields(CLASSES[name])
                  if "help" in f.metadata and f.default in (None, ())
                  and not (f.metadata.get("optional") or f.metadata.get("required"))]
    assert undeclared == []


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_the_help_says_what_unset_means(name):
    """A field's ``optional`` phrase is its flag's help ("unset: ..."), its one home."""
    cls = CLASSES[name]
    parser = argparse.ArgumentParser()
    add_arguments(parser, cls)
    helps = {a.dest: a.help for a in parser._actions}
    for f in dataclasses.fields(cls):
        phrase = f.metadata.get("optional")
        if f.metadata.get("flag") and isinstance(phrase, str):
            assert f"unset: {phrase}".replace("%", "%%") in helps[f.name]


def test_a_required_option_left_out_is_refused():
    from pipeline.assessment.hazard_job import HazardJobOptions
    with pytest.raises(InputError, match="^give --oq-job$"):
        HazardJobOptions()


def test_the_shake_table_specimen_is_its_declared_default(capsys):
    """The shake-table campaign's specimen, once stated in its help and substituted in
    two readers, is the field's default: the help says it and the runs take it."""
    from pipeline import cli
    from pipeline.campaign.shake_table import ShakeTableOptions
    from pipeline.campaign.shake_table_experiments import SPECIMEN
    with pytest.raises(SystemExit):
        cli.main(["campaign", "shake-table", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "the scanned rock SP1); default records/shake_table/sp1.json" in text
    options = ShakeTableOptions()
    assert options.column_file == SPECIMEN and options.kwargs()["specimen"] == SPECIMEN


def test_an_integer_default_and_bounds_read_as_integers():
    """A seed of 20091000 reads "default 20091000" in the help, not 2.0091e+07; a float
    stays in the short form."""
    @dataclasses.dataclass(frozen=True)
    class Toy:
        seed: int = param(20091000, "", "the seed", low=0, high=2 ** 63, flag="--seed")
        width: float = param(1.5e-3, "m", "the width", low=1e-4, high=0.25, flag="--width")
    parser = argparse.ArgumentParser()
    add_arguments(parser, Toy)
    helps = {a.dest: a.help for a in parser._actions}
    assert "default 20091000" in helps["seed"] and f"0-{2 ** 63}" in helps["seed"]
    assert "default 0.0015" in helps["width"] and "0.0001-0.25" in helps["width"]
