"""The documentation stays true: its links and the repository paths it names exist, and
every command example in it is one the command line accepts (parsed, not run)."""
import re
import shlex
from pathlib import Path

import pytest

from pipeline.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
         ROOT / "records" / "README.md", ROOT / "records" / "shake_table" / "README.md"]
LINK = re.compile(r"\]\(([^)\s]+)\)")
# a repository path in backticks: a file of the project's own folders
PATH = re.compile(r"`((?:docs|pipeline|records|tests|yade_scripts|bench)/[\w./-]+)`")
COMMAND = re.compile(r"(?:\.venv/bin/python|python) -m pipeline ((?:[^\n`\\]|\\\n)+)")


def _page_id(path):
    return str(path.relative_to(ROOT))


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_links_and_named_paths_exist(page):
    text = page.read_text()
    missing = []
    for target in LINK.findall(text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        if not (page.parent / target.split("#")[0]).exists():
            missing.append(target)
    for target in PATH.findall(text):
        target = target.rstrip(".")
        if any(c in target for c in "*<>") or "..." in target:
            continue
        if not ((ROOT / target).exists() or (page.parent / target).exists()):
            missing.append(target)
    assert not missing, f"{page.name} names what does not exist: {missing}"


def _examples():
    for page in PAGES:
        for match in COMMAND.finditer(page.read_text()):
            line = match.group(1).replace("\\\n", " ").split("#")[0].strip()
            if not line or any(c in line for c in "<>[]|$") or "..." in line:
                continue                                  # a placeholder, not an example
            yield pytest.param(line, id=f"{page.name}: {line[:60]}")


@pytest.mark.parametrize("line", list(_examples()))
def test_command_examples_parse(line):
    parser = build_parser()
    try:
        parser.parse_args(shlex.split(line))
    except SystemExit as exc:
        if exc.code:                                    # --help exits 0
            pytest.fail(f"the command line refuses the documented example: {line}")
