"""Provenance of results: the versions of the software that made them, YADE's included."""
import functools
import importlib.metadata
from pathlib import Path
from pipeline import __version__

YADE_PY_PATH = "/usr/lib/x86_64-linux-gnu/yade-double/py"   # Debian 12's package


@functools.lru_cache(maxsize=1)
def yade_version():
    """YADE's version string (from its config module), or None when not installed."""
    config = Path(YADE_PY_PATH) / "yade" / "config.py"
    if not config.is_file():
        return None
    for line in config.read_text(errors="replace").splitlines():
        if line.startswith("version="):
            return line.split("=", 1)[1].strip().strip("'\"")
    return None


def software_versions():
    """Versions (dict) of the package, obspy, numpy, scipy and YADE, for provenance."""
    versions = {"toppling-columns": __version__}
    for dist in ("obspy", "numpy", "scipy"):
        try:
            versions[dist] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            versions[dist] = None
    versions["yade"] = yade_version()
    return versions
