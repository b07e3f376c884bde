"""A command that refuses its input: exit 2, one line naming the problem, nothing written."""
from pipeline.cli import main


def refused(capsys, argv, words, out):
    """``main(argv)`` exits 2 with one line on stderr holding ``words`` and leaves no
    ``out``."""
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1, err
    assert not out.exists()
