"""An OpenQuake job (``job.ini``) rewritten for the constrained hazard: the specimens'
sites, PGA and PGV at the same number of levels, the curves of every realisation and the
contexts the joint rate density needs (a classical job), and the disaggregation of PGA by
magnitude and distance (a disaggregation job).  Text only: the engine runs elsewhere
(:mod:`pipeline.assessment.hazard_job`).

The job's source and ground-motion logic trees, its site parameters (``site_model_file``
or the ``reference_*`` values) and its other settings are kept; file names become
relative to the directory the rewritten job is written to (the engine refuses absolute
ones)."""
import configparser
import os
from dataclasses import dataclass
from pathlib import Path

from pipeline.files import InputError

# the levels of the shipped QA case (records/hazard/openquake_postproc_case_mrd): PGA in
# g, PGV in cm/s, as many of each (the engine's rate density of two measures needs it)
PGA_LEVELS = "logscale(0.0001, 4, 40)"
PGV_LEVELS = "logscale(0.0001, 1000, 40)"
# the disaggregation: probabilities of exceedance in the investigation time, bins
POES_DISAGG = "0.01 0.001 0.0001"
MAG_BIN_WIDTH = "0.5"
DISTANCE_BIN_WIDTH_KM = "20"
MAX_JOB_BYTES = 1_000_000
# the site settings a given site list replaces
_SITE_KEYS = ("sites", "sites_csv", "region", "region_grid_spacing")
# the outputs and post-processing the rewritten jobs set themselves
_OUTPUT_KEYS = ("intensity_measure_types_and_levels", "intensity_measure_types",
                "postproc_func", "postproc_args", "individual_rlzs", "hazard_maps",
                "uniform_hazard_spectra", "poes", "calculation_mode", "poes_disagg",
                "iml_disagg", "disagg_outputs", "num_rlzs_disagg", "mag_bin_width",
                "distance_bin_width", "coordinate_bin_width", "num_epsilon_bins",
                "disagg_by_src", "description")


@dataclass(frozen=True)
class OqJob:
    """A job file read: its directory and its settings (section -> key -> text)."""
    path: Path
    sections: tuple[tuple[str, tuple[tuple[str, str], ...]], ...]

    def __post_init__(self):
        keys = {k for _, items in self.sections for k, _ in items}
        for need in ("source_model_logic_tree_file", "gsim_logic_tree_file",
                     "investigation_time"):
            if need not in keys:
                raise InputError(f"OpenQuake job {self.path}: no {need} (a classical "
                                 "job with source and ground-motion logic trees expected)")


def load_job(path):
    """The :class:`OqJob` of a ``job.ini`` (one loader)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"OpenQuake job {path}: no such file")
    if path.stat().st_size > MAX_JOB_BYTES:
        raise InputError(f"OpenQuake job {path}: larger than {MAX_JOB_BYTES} bytes")
    parser = configparser.ConfigParser(interpolation=None)
    try:
        parser.read_string(path.read_text(encoding="utf-8"), source=str(path))
    except (configparser.Error, UnicodeDecodeError) as err:
        first = str(err).splitlines()[0] if str(err) else type(err).__name__
        raise InputError(f"OpenQuake job {path}: not an ini file ({first})") from None
    sections = tuple((s, tuple(parser.items(s, raw=True))) for s in parser.sections())
    return OqJob(path.resolve(), sections)


def _relative(job, key, value, directory):
    if not (key.endswith("_file") or key.endswith("_csv")):
        return value
    return " ".join(os.path.relpath((job.path.parent / token).resolve(), directory)
                    for token in value.split())


def _text(job, directory, sites, extra):
    """The job's text to be written in ``directory``: its settings (file names relative to
    ``directory``) without the replaced ones, the sites (``(lon, lat)`` degrees) when given,
    then ``extra`` (key, value) pairs."""
    directory = Path(directory).resolve()
    drop = set(_OUTPUT_KEYS) | (set(_SITE_KEYS) if sites else set())
    lines = []
    for section, items in job.sections:
        lines.append(f"[{section}]")
        lines += [f"{k} = {_relative(job, k, v, directory)}" for k, v in items if k not in drop]
        lines.append("")
    lines.append("[constrained_hazard]")
    if sites:
        lines.append("sites = " + ", ".join(f"{lon:.6f} {lat:.6f}" for lon, lat in sites))
    lines += [f"{k} = {v}" for k, v in extra]
    return "\n".join(lines) + "\n"


def classical_text(job, directory, sites=()):
    """The classical job: PGA and PGV curves of every realisation and the ruptures'
    contexts kept (``postproc_func = dummy.main``) for the joint rate density."""
    return _text(job, directory, sites, (
        ("description", "'constrained hazard: PGA and PGV of every realisation'"),
        ("calculation_mode", "classical"),
        ("intensity_measure_types_and_levels",
         f'{{"PGA": {PGA_LEVELS}, "PGV": {PGV_LEVELS}}}'),
        ("postproc_func", "dummy.main"), ("individual_rlzs", "true")))


def disaggregation_text(job, directory, sites=()):
    """The disaggregation job: PGA by magnitude and distance (``Mag_Dist``), every
    realisation, at :data:`POES_DISAGG`."""
    return _text(job, directory, sites, (
        ("description", "'constrained hazard: PGA by magnitude and distance'"),
        ("calculation_mode", "disaggregation"),
        ("intensity_measure_types_and_levels", f'{{"PGA": {PGA_LEVELS}}}'),
        ("poes_disagg", POES_DISAGG), ("mag_bin_width", MAG_BIN_WIDTH),
        ("distance_bin_width", DISTANCE_BIN_WIDTH_KM), ("coordinate_bin_width", "1.0"),
        ("num_epsilon_bins", "1"), ("disagg_outputs", "Mag_Dist"),
        ("num_rlzs_disagg", "0"), ("individual_rlzs", "true")))
