"""``hazard-job``: an OpenQuake job run at the specimens' sites by the engine's own command
line (in its own environment, one process, no server), its exports kept, then the
``constrain`` workflow on the per-realisation PGA curves (PGV/PGA from the run's rate
density unless the options give another source).

The engine writes into a temporary directory; only when every step succeeded does its
export move to ``<out>/openquake`` (the logic tree ``constrain`` reads; the PGA-PGV rate
density ``mrd_pga_pgv.hdf5`` and ``disaggregation/Mag_Dist-*.csv`` for ``survival
--joint-hazard`` and ``--disaggregation``), removed again if ``constrain`` then fails."""
import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

from pipeline.assessment.constrain import constrain_files
from pipeline.files import InputError, ToolError
from pipeline.hazard.oq_job import classical_text, disaggregation_text, load_job
from pipeline.scenario.parameters import check_fields, param

ROOT = Path(__file__).resolve().parents[2]
OQ_PYTHON = Path(".venv-oq/bin/python")
INSTALL = ("make oq-case-mrd installs it in .venv-oq (or: python3 -m venv .venv-oq && "
           ".venv-oq/bin/pip install -r records/tools/oq_engine_requirements.txt && "
           ".venv-oq/bin/pip install --no-deps openquake-engine==3.26.2)")
MRD_TOOL = ROOT / "records" / "tools" / "oq_mrd_extract.py"
EXPORT = "openquake"
MAX_SITES = 100
ENGINE_HANG_S = 24 * 3600.0        # a generous bound on one engine step


@dataclass(frozen=True)
class HazardJobOptions:
    """The engine side of ``hazard-job`` (the rest: ``constrain``'s options)."""
    oq_job: Path = param(None, "", "an OpenQuake job.ini with source and ground-motion "
                         "logic trees", flag="--oq-job", metavar="JOB_INI", required=True)
    oq_python: Path = param(OQ_PYTHON, "", "the Python of the environment holding the "
                            "OpenQuake engine", flag="--oq-python", metavar="PATH")
    oq_site: tuple[tuple[float, float], ...] = param(
        (), "degrees", "a site (longitude, latitude) the engine computes, in the order "
        "--site and --specimen-site count them", flag="--oq-site", metavar=("LON", "LAT"),
        optional="the job's own sites")

    def __post_init__(self):
        check_fields(self)
        if len(self.oq_site) > MAX_SITES:
            raise InputError(f"{len(self.oq_site)} --oq-site (at most {MAX_SITES})")
        for lon, lat in self.oq_site:
            if not (-180 <= lon <= 180 and -90 <= lat <= 90):
                raise InputError(f"--oq-site {lon:g} {lat:g}: longitude must lie in "
                                 "[-180, 180] and latitude in [-90, 90] degrees")


def check_engine(python):
    """Raise a one-line :class:`InputError` saying how to install the engine when
    ``python`` cannot import it."""
    python = Path(python)
    if not (python.is_file() and os.access(python, os.X_OK)):
        raise InputError(f"no OpenQuake engine: {python} is not a Python; {INSTALL}")
    done = subprocess.run([str(python), "-c", "import openquake.engine"],
                          capture_output=True, timeout=600)
    if done.returncode != 0:
        raise InputError(f"no OpenQuake engine in {python}; {INSTALL}")


def hazard_job(job_options, constrain_options):
    """Run the job's engine steps and ``constrain``; returns (constrain's summary,
    {step: engine wall time s})."""
    job = load_job(job_options.oq_job)
    _check_sites(job_options, constrain_options)
    # absolute, its symlinks kept (a venv's python is one): the engine runs in a temporary
    # directory
    python = Path(os.path.abspath(job_options.oq_python))
    check_engine(python)
    out = constrain_options.out
    times = {}
    with tempfile.TemporaryDirectory(prefix="oq-job-") as tmp:
        tmp = Path(tmp)
        export = tmp / EXPORT
        (export / "disaggregation").mkdir(parents=True)
        env = dict(os.environ, OQ_DATADIR=str(tmp / "oqdata"), OQ_DISTRIBUTE="no",
                   OQ_DATABASE="127.0.0.1")
        sites = job_options.oq_site
        calc = {}
        for name, text in (("classical", classical_text(job, tmp, sites)),
                           ("disaggregation", disaggregation_text(job, tmp, sites))):
            (tmp / f"{name}.ini").write_text(text, encoding="utf-8")
            calc[name], times[name] = _engine(python, tmp, name, env)
        for f in (tmp / "out_classical").glob("*.csv"):
            if f.name.startswith(("hazard_curve-", "realizations_")):
                shutil.copy(f, export / f.name)
        _per_realisation(python, tmp, calc["disaggregation"], env)
        for f in (tmp / "out_disaggregation").glob("Mag_Dist-*.csv"):
            shutil.copy(f, export / "disaggregation" / f.name)
        start = time.monotonic()
        _run([str(python), str(MRD_TOOL),
              str(tmp / "oqdata" / f"calc_{calc['classical']}.hdf5"),
              str(export / "mrd_pga_pgv.hdf5")], tmp, env, "the PGA-PGV rate density")
        times["mrd"] = time.monotonic() - start
        target, created = out / EXPORT, not out.exists()
        if target.exists():
            shutil.rmtree(target)
        out.mkdir(parents=True, exist_ok=True)
        shutil.move(str(export), str(target))
    try:            # constrain.json names the export where it stays
        summary = constrain_files(_with_export(constrain_options, target))
    except BaseException:
        shutil.rmtree(out if created else target, ignore_errors=True)
        raise
    return summary, times


def _with_export(o, export):
    """``constrain``'s options on the export: its logic tree, and PGV/PGA from its rate
    density when no other source of PGV/PGA is given."""
    own = o.joint_hazard is not None or o.pgv_pga_median is not None or \
        o.magnitude is not None or o.disaggregation is not None
    return replace(o, logic_tree=export, **({} if own else {
        "joint_hazard": export / "mrd_pga_pgv.hdf5"}))


def _check_sites(job_options, constrain_options):
    """--site and --specimen-site within the --oq-site given (before the engine runs)."""
    count = len(job_options.oq_site)
    if count == 0:
        return
    named = [("--site", constrain_options.site)] + [
        ("--specimen-site", s) for s in constrain_options.specimen_site]
    for flag, site in named:
        if site is not None and site >= count:
            raise InputError(f"{flag} {site}: beyond the {count} --oq-site given "
                             "(counted from 0)")


def _run(cmd, cwd, env, what):
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=ENGINE_HANG_S)
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines() or ["no message"]
        raise ToolError(f"OpenQuake engine, {what}: {lines[-1]}")
    return done.stdout + done.stderr


def _engine(python, tmp, name, env):
    """(calculation id, wall time s) of ``oq engine --run`` on ``<tmp>/<name>.ini``."""
    start = time.monotonic()
    log = _run([str(python), "-m", "openquake.commands", "engine", "--run",
                f"{name}.ini", "-e", "csv", "-p", f"export_dir={tmp / ('out_' + name)}"],
               tmp, env, f"the {name} job")
    wall = time.monotonic() - start
    found = re.findall(r"calc_(\d+)\.hdf5", log)
    if not found:
        raise ToolError(f"OpenQuake engine, the {name} job: no calculation id in its log")
    return found[-1], wall


def _per_realisation(python, tmp, calc_id, env):
    """Export the disaggregation of every realisation (``--eo`` of its output)."""
    oq = [str(python), "-m", "openquake.commands", "engine"]
    listing = _run(oq + ["--lo", calc_id], tmp, env, "the list of outputs")
    ids = [line.split()[0] for line in listing.splitlines() if "Per Realization" in line]
    if not ids:
        raise ToolError("OpenQuake engine: no disaggregation per realisation written")
    _run(oq + ["--eo", ids[0], str(tmp / "out_disaggregation")], tmp, env,
         "the disaggregation export")
