"""One file named twice where a set needs distinct ones (``--fragility``, ``--hazard``):
refused in one line."""
from pathlib import Path

from pipeline.files import InputError


def distinct_files(paths: tuple[Path, ...], flag: str, what: str,
                   inside: str | None = None) -> None:
    """Refuse one file named twice by ``flag`` (as a file or, with ``inside``, its
    directory; by another path or a link): one ``what`` is not two."""
    seen = {}
    for path in paths:
        file = path / inside if inside is not None and path.is_dir() else path
        try:
            stat = file.stat()
            key = (stat.st_dev, stat.st_ino)
        except OSError:
            key = file.resolve()
        if key in seen:
            raise InputError(f"{flag} {path} and {seen[key]} are one file: the same {what} "
                             "twice (a set needs distinct ones)")
        seen[key] = path
