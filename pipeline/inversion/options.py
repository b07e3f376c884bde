"""The ``invert`` command's options, declared as :func:`~pipeline.scenario.parameters.param`
fields (the command builds their flags from them): the workflows' and the site motion's
(the grids' in :mod:`pipeline.inversion.grid_options`); checked on creation, before any
work.  Light: the command imports it at start-up, the workflows
(:mod:`pipeline.inversion.workflows`) only when it runs."""
from dataclasses import dataclass
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.files import LONG_RUN_S, InputError, check_jobs
from pipeline.hazard.site_motion import PGV_PGA_RANGE_S
from pipeline.inversion.likelihood import DEFAULT_FLOOR, DEFAULT_KERNEL_DEG, DEFAULT_LIKELIHOOD, \
    LIKELIHOODS, check_model_options
from pipeline.scenario.parameters import check_fields, param

DEFAULT_FORWARD_DIR = RESULTS_DIR / "inversion-forward"   # the forward runs' campaign
DEMO_TRIALS = 20           # --trials of --demo
STUDY_TRIALS = 200         # --trials of --member-study: Wilson intervals of about +-0.03 at 0.95


@dataclass(frozen=True)
class InversionOptions:
    """What the workflows take from the command line (see ``toppling invert --help``),
    declared as :func:`~pipeline.scenario.parameters.param` fields (the command builds
    their flags); checked on creation, before any work."""
    out: Path = param(None, "", "output directory", flag="--out", metavar="DIR",
                      optional="results/inversion/<file stem>; --demo: results/inversion")
    scheduler: str = param(None, "", "run the forward campaign on an existing Dask cluster",
                           flag="--scheduler", metavar="ADDRESS",
                           optional="on this machine")
    jobs: int = param(None, "", "parallel YADE runs / pyprop8 processes", flag="--jobs",
                      optional="all cores")
    allow_long: bool = param(False, "", f"start a forward table estimated to take over "
                             f"{LONG_RUN_S / 3600:g} h on this machine (refused otherwise; "
                             "the estimate is printed before any run)", flag="--allow-long")
    table: Path = param(None, "", "use this forward table file (tables/forward_table_<key>.npz) "
                        "as it is: no pyprop8, no YADE (its code version is reported, not "
                        "checked)", flag="--table", metavar="FILE",
                        optional="the table of the forward runs, run or reused")
    extend_table: Path = param(None, "", "a computed forward table of the same grid but for "
                               "fewer rings: only the missing rings are run, then joined to it "
                               "(the joined table is written to the forward directory's "
                               "tables/)", flag="--extend-table", metavar="FILE",
                               optional="no table extended")
    forward_dir: Path = param(DEFAULT_FORWARD_DIR, "", "campaign directory of the forward runs",
                              flag="--forward-dir", metavar="DIR")
    kernel_deg: float = param(DEFAULT_KERNEL_DEG, "deg", "width of the von Mises kernel on "
                              "ensemble falls", 0.0, 90.0, "--kernel-deg", low_open=True)
    floor: float = param(DEFAULT_FLOOR, "", "fraction of uniform density mixed into every "
                         "direction density (below 1)", 0.0, 1.0, "--floor", low_open=True)
    likelihood: str = param(DEFAULT_LIKELIHOOD, "", "predictive: columns of one site share "
                            "its motion and the ensemble is finite (Polya urn: a site's own "
                            "falls inform its next column; calibrated in the member study); "
                            "independent: the product over columns (too sure when a site has "
                            "several columns)", flag="--likelihood", choices=LIKELIHOODS)
    trials: int = param(None, "", "trials per configuration", 1, 1000, "--trials",
                        optional=f"{DEMO_TRIALS} with --demo, {STUDY_TRIALS} with "
                        "--member-study")

    def __post_init__(self):
        check_fields(self)
        check_model_options(self.kernel_deg, self.floor, self.likelihood)
        check_jobs(self.jobs)
        if self.table is not None and self.extend_table is not None:
            raise InputError("give --table (a table used as it is) or --extend-table (a "
                             "table to extend by rings), not both")


@dataclass(frozen=True)
class SiteMotionOptions:
    """The PGA range each site's standing and fallen columns allow (site_motion.json beside
    the posterior): the fragility it is read from, checked on creation, before any work."""
    site_fragility: Path = param(
        None, "", "a column fragility.json of campaign fragility (or its directory), one "
        "entry per column type of the observations: writes site_motion.json beside the "
        "posterior, the PGA range (RotD50) each site's outcome allows (docs/survival.md)",
        flag="--site-fragility", metavar="FILE", optional=True)
    site_fragility_form: str = param(
        "pga", "", "its lognormal PGA fit (pga) or its logistic surface in PGA and PGV/PGA "
        "(pga-pgv, with --at-pgv-pga)", flag="--site-fragility-form", choices=("pga", "pga-pgv"))
    at_pgv_pga: float = param(None, "s", "the PGV/PGA at which the PGA range is stated for "
                              "--site-fragility-form pga-pgv", *PGV_PGA_RANGE_S,
                              flag="--at-pgv-pga", metavar="S", optional=True)

    def __post_init__(self):
        surface = self.site_fragility_form == "pga-pgv"
        if self.site_fragility is None and (self.at_pgv_pga is not None or surface):
            raise InputError("--site-fragility-form and --at-pgv-pga go with --site-fragility")
        check_fields(self)
        if surface and self.at_pgv_pga is None:
            raise InputError("--site-fragility-form pga-pgv needs --at-pgv-pga (the PGV/PGA "
                             "at which the PGA range is stated)")
        if not surface and self.at_pgv_pga is not None:
            raise InputError("--at-pgv-pga goes with --site-fragility-form pga-pgv")

