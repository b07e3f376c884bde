"""What ``survival`` and ``constrain`` are asked, declared as
:func:`~pipeline.scenario.parameters.param` fields (the commands build their flags from
them: :mod:`pipeline.cli._fields`), every one checked when the options are made, before
any work: the fragility and PGV/PGA options both share (:class:`SpecimenOptions`, read
by :meth:`SpecimenOptions.specimens` and :meth:`SpecimenOptions.ratio_model`), and each
command's own (:class:`SurvivalOptions`, :class:`ConstrainOptions`)."""
import math
from dataclasses import dataclass
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError, display_path
from pipeline.hazard.components import COMPONENTS
from pipeline.hazard.constrain import FLOOR
from pipeline.hazard.fragility import BELOW_GRID, GMM_MECHANISMS
from pipeline.hazard.fragility_kinds import BETA_RANGE, MEDIAN_G_RANGE
from pipeline.hazard.fragility_ratio import DEFAULT_VS30_M_S, PGA_PGV_CORRELATION
from pipeline.hazard.pga_pgv_correlation import BRADLEY_2012
from pipeline.scenario.parameters import check_fields, param
from pipeline.userfiles import number

COLUMNS = ("monolithic", "drums", "block2d", "block2d_worst")
SURVIVAL_OUT = RESULTS_DIR / "survival"
CONSTRAIN_OUT = RESULTS_DIR / "constrain"
MAX_SPECIMENS = 20


@dataclass(frozen=True)
class SpecimenOptions:
    """The fragilities of the specimens, the PGV/PGA at each PGA level and the draws of
    the survival interval (``--fragility`` ... ``--seed``)."""
    hazard_component: str = param(
        None, "", "the horizontal component of the hazard curve's PGA: rotd50 (NGA-West2 "
        "models, the USGS 2014 model; default) or rotd100 (the peak of the horizontal "
        "vector, campaign fragility's PGA); a campaign's fragility is put on it",
        flag="--hazard-component", choices=COMPONENTS)
    fragility: tuple[Path, ...] = param(
        (), "", "fragility.json of campaign fragility (or its directory); repeat for a set "
        "of specimens at the site", flag="--fragility", metavar="FILE")
    column: str = param(None, "", "which column entry of fragility.json (default: the first "
                        "3D one)", flag="--column", choices=COLUMNS)
    fragility_form: str = param(
        None, "", "from fragility.json: pga (its lognormal PGA fit), pga-pgv (its logistic "
        "surface in PGA and PGV/PGA; default for columns) or grid (a pulse grid's cells, "
        "bilinear in ln PGA and ln PGV/PGA, the logistic surface outside; default for a "
        "pulse grid)", flag="--fragility-form", choices=("pga", "pga-pgv", "grid"))
    below_grid: str = param(
        None, "", "a pulse grid's P below its first PGA: ramp (0 at the uplift acceleration "
        "g tan(alpha), rising linearly in ln PGA to the edge's P; default), zero, edge (the "
        "edge's P held down to the uplift acceleration) or logistic (the fitted surface)",
        flag="--below-grid", choices=BELOW_GRID)
    median_g: tuple[float, ...] = param(
        (), "", f"a stated lognormal fragility over PGA: median PGA (g), "
        f"{MEDIAN_G_RANGE[0]:g}-{MEDIAN_G_RANGE[1]:g} (as a file's PGA fit); repeat with "
        "--beta for a set", flag="--median-g", metavar="G")
    beta: tuple[float, ...] = param((), "", f"its dispersion (natural log), "
                                    f"{BETA_RANGE[0]:g}-{BETA_RANGE[1]:g}",
                                    flag="--beta", metavar="B")
    logistic: tuple[str, ...] = param(
        (), "", "a stated logistic surface logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 "
        "ln(PGV/PGA / 1 s) (b1 > 0); repeat for a set", flag="--logistic",
        metavar="B0,B1,B2")
    pgv_pga_median: float = param(None, "", "stated lognormal PGV/PGA: median (s), 0.001-10",
                                  flag="--pgv-pga-median", metavar="S")
    pgv_pga_sigma: float = param(None, "", "its sigma (natural log), 0-3",
                                 flag="--pgv-pga-sigma", metavar="LN")
    magnitude: float = param(None, "", "or from Boore et al. (2014) at this moment magnitude "
                             "(3-8.5), e.g. the mode of the hazard's disaggregation",
                             flag="--magnitude", metavar="M")
    distance_km: float = param(None, "", "and this Joyner-Boore distance (km, 0-300)",
                               flag="--distance-km", metavar="KM")
    vs30: float = param(None, "", f"Vs30 for the model (m/s, 150-1500); default "
                        f"{DEFAULT_VS30_M_S:g}", flag="--vs30", metavar="M_S")
    mechanism: str = param(None, "", "fault mechanism for the model (SS strike-slip, NS "
                           "normal, RS reverse); default SS", flag="--mechanism",
                           choices=GMM_MECHANISMS)
    pga_pgv_correlation: float = param(
        None, "", f"correlation of ln PGA and ln PGV residuals (0-0.99); default "
        f"{PGA_PGV_CORRELATION:g}, observed in the NGA-West2 residuals (Baker & Bradley "
        f"2017); {BRADLEY_2012.value:g} is Bradley's (2012) prediction",
        flag="--pga-pgv-correlation",
        metavar="RHO")
    draws: int = param(None, "", "fragility parameter draws for the survival interval "
                       "(0-20000; 0: none); default 400", flag="--draws", metavar="N")
    seed: int = param(None, "", "seed of the draws (>= 0); default 0", flag="--seed")

    FRAGILITY_FLAGS = ("hazard_component", "fragility", "column", "fragility_form",
                       "below_grid", "median_g", "beta", "logistic")
    RATIO_FLAGS = ("pgv_pga_median", "pgv_pga_sigma", "magnitude", "distance_km", "vs30",
                   "mechanism", "pga_pgv_correlation")
    RATIO_GROUP = "PGV/PGA at each PGA level (for a pga-pgv fragility)"
    DRAW_FLAGS = ("draws", "seed")

    def _fill(self, **defaults):
        """Fields left None take ``defaults`` (their defaults, stated in their help)."""
        check_fields(self)
        defaults = {"hazard_component": "rotd50", "below_grid": "ramp",
                    "vs30": DEFAULT_VS30_M_S, "mechanism": "SS", "draws": 400, "seed": 0,
                    **defaults}
        for name, value in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)

    def check_specimens(self):
        """The fragility, PGV/PGA and draw options range-checked (InputError, one line)."""
        for v in self.median_g:
            number(v, "--median-g", *MEDIAN_G_RANGE, "g")
        for v in self.beta:
            number(v, "--beta", *BETA_RANGE)
        if len(self.median_g) != len(self.beta):
            raise InputError(f"give one --beta per --median-g ({len(self.median_g)} medians, "
                             f"{len(self.beta)} betas)")
        for text in self.logistic:
            parse_logistic(text)
        if not self.median_g and not self.fragility and not self.logistic:
            raise InputError("no fragility: give --median-g and --beta, --logistic or "
                             "--fragility")
        _distinct_files(self.fragility, "--fragility", "specimen", "fragility.json")
        self._check_ratio()
        number(self.vs30, "--vs30", 150, 1500, "m/s")
        if self.pga_pgv_correlation is not None:
            number(self.pga_pgv_correlation, "--pga-pgv-correlation", 0, 0.99)
        if not 0 <= self.draws <= 20000:
            raise InputError(f"--draws must be 0 to 20000, got {self.draws}")
        if self.seed < 0:
            raise InputError(f"--seed must be 0 or more, got {self.seed}")

    def _check_ratio(self):
        stated = (self.pgv_pga_median, self.pgv_pga_sigma)
        modelled = (self.magnitude, self.distance_km)
        if any(v is not None for v in stated) and any(v is not None for v in modelled):
            raise InputError("PGV/PGA: give either --pgv-pga-median/--pgv-pga-sigma or "
                             "--magnitude/--distance-km, not both")
        if any(v is not None for v in stated):
            if None in stated:
                raise InputError("give both --pgv-pga-median and --pgv-pga-sigma")
            number(self.pgv_pga_median, "--pgv-pga-median", 0.001, 10, "s")
            number(self.pgv_pga_sigma, "--pgv-pga-sigma", 0, 3)
        if any(v is not None for v in modelled):
            if None in modelled:
                raise InputError("give both --magnitude and --distance-km")
            number(self.magnitude, "--magnitude", 3, 8.5)
            number(self.distance_km, "--distance-km", 0, 300, "km")
        elif self.pga_pgv_correlation is not None:
            raise InputError("--pga-pgv-correlation applies with --magnitude and "
                             "--distance-km")

    @property
    def specimen_count(self):
        return len(self.fragility) + len(self.median_g) + len(self.logistic)

    def campaign_fragility(self, path, column):
        """The fragility of ``column`` in the campaign's file ``path``, as the options
        ask for it (form, below the grid, the hazard's component)."""
        from pipeline.hazard.fragility import load_campaign_fragility
        from pipeline.records import rotd50_fraction
        return load_campaign_fragility(path, column, self.fragility_form, self.below_grid,
                                       self.hazard_component, self.magnitude,
                                       self.distance_km, rotd50_fraction)

    def specimens(self):
        """The fragilities of the options, in order: --fragility files, --median-g/--beta,
        --logistic."""
        from pipeline.hazard.fragility import Logistic, Lognormal
        specimens = [self.campaign_fragility(path, self.column) for path in self.fragility]
        if self.below_grid != "ramp" and all(f.grid_range() is None for f in specimens):
            raise InputError("--below-grid applies to a pulse-grid fragility (--fragility of "
                             "campaign fragility --pulses, --fragility-form grid)")
        specimens += [Lognormal(m * STANDARD_GRAVITY, b, label=f"stated lognormal: median "
                                f"{m:g} g, beta {b:g}")
                      for m, b in zip(self.median_g, self.beta)]
        specimens += [Logistic(parse_logistic(text), label=f"stated logistic surface {text}")
                      for text in self.logistic]
        return specimens

    def ratio_model(self, specimens):
        """The PGV/PGA model of the options, or None; InputError when a fragility needs
        one."""
        from pipeline.hazard.fragility import RatioFromGmm, RatioLognormal
        ratio = None
        if self.pgv_pga_median is not None:
            ratio = RatioLognormal(self.pgv_pga_median, self.pgv_pga_sigma)
        elif self.magnitude is not None:
            rho = PGA_PGV_CORRELATION if self.pga_pgv_correlation is None \
                else self.pga_pgv_correlation
            ratio = RatioFromGmm(self.magnitude, self.distance_km, self.vs30, self.mechanism,
                                 rho)
        if ratio is None and any(f.uses_ratio for f in specimens):
            raise InputError("the fragility is over PGA and PGV/PGA: give --pgv-pga-median "
                             "and --pgv-pga-sigma, or --magnitude and --distance-km (or "
                             "--fragility-form pga)")
        return ratio


@dataclass(frozen=True)
class SurvivalOptions(SpecimenOptions):
    """What ``survival`` is asked (see ``python -m pipeline survival --help``)."""
    hazard: tuple[Path, ...] = param(
        (), "", "hazard curve: OpenQuake hazard-curve CSV, USGS hazard web service JSON "
        "(static curves) or a plain table pga_<g|m_s2|cm_s2>,annual_rate_per_yr; repeat for "
        "several curves of the site (e.g. an engine's mean and quantile curves): the first "
        "gives the headline, survival.json's hazard_curves the result under each",
        flag="--hazard", metavar="FILE")
    site: int = param(None, "", "row (0-based) of an OpenQuake file with several sites",
                      flag="--site", metavar="N")
    age_ka: float = param(None, "", "the specimen's age in thousand years (above 0, at most "
                          "10000); needed with --hazard", flag="--age-ka", metavar="KA")
    age_sd_ka: float = param(None, "", "its standard deviation (ka; normal truncated at 0); "
                             "default 0", flag="--age-sd-ka", metavar="KA")
    observations: Path = param(
        None, "", "an observations file of invert (sites with fallen and standing columns): "
        "writes site_motion.json, the PGA range consistent with the site's outcome; "
        "fragility per column type from --fragility (a column fragility.json) or one stated "
        "--median-g/--beta or --logistic for all", flag="--observations", metavar="FILE")
    observation_site: str = param(None, "", "the site's name in --observations (default: its "
                                  "only site)", flag="--observation-site", metavar="NAME")
    at_pgv_pga: float = param(None, "", "the PGV/PGA (s, 0.001-10) at which the PGA range is "
                              "stated (for a fragility over PGA and PGV/PGA)",
                              flag="--at-pgv-pga", metavar="S")
    out: Path = param(None, "", f"output directory (default {display_path(SURVIVAL_OUT)})",
                      flag="--out", metavar="DIR")

    OBSERVATION_GROUP = "the motion at a site from its standing and fallen columns"

    def __post_init__(self):
        self._fill(age_sd_ka=0.0, out=SURVIVAL_OUT)
        if not self.hazard and self.observations is None:
            raise InputError("give --hazard (survival under a hazard curve) or --observations "
                             "(the motion at a site from its columns), or both")
        if self.hazard and self.age_ka is None:
            raise InputError("--hazard needs --age-ka (the specimen's age)")
        if not self.hazard and self.age_ka is not None:
            raise InputError("--age-ka applies with --hazard")
        self._check_observations()
        if self.age_ka is not None:
            number(self.age_ka, "--age-ka", 0, 10000, "ka", low_open=True)
        number(self.age_sd_ka, "--age-sd-ka", 0, 10000, "ka")
        self.check_specimens()
        _distinct_files(self.hazard, "--hazard", "curve")
        if self.observations is not None and self.column is not None:
            raise InputError("--column does not apply with --observations (each column's own "
                             "type is read from the file)")
        _check_column_site(self)
        _check_out(self.out)

    def _check_observations(self):
        if self.observations is None and (self.observation_site is not None
                                          or self.at_pgv_pga is not None):
            raise InputError("--observation-site and --at-pgv-pga apply with --observations")
        if self.at_pgv_pga is not None:
            number(self.at_pgv_pga, "--at-pgv-pga", 0.001, 10, "s")
        if self.observations is not None and self.specimen_count != 1:
            raise InputError("--observations: give one fragility (--fragility, one "
                             "--median-g/--beta or one --logistic), used by column type")


@dataclass(frozen=True)
class ConstrainOptions(SpecimenOptions):
    """What ``constrain`` is asked (see ``python -m pipeline constrain --help``)."""
    logic_tree: Path = param(
        None, "", "OpenQuake's export (the directory, or its realizations.csv, with one "
        "hazard_curve CSV per realisation) or a plain table branch,weight,"
        "pga_<g|m_s2|cm_s2>,annual_rate_per_yr (one row per branch and level)",
        metavar="PATH")
    site: int = param(None, "", "row (0-based) of OpenQuake curves with several sites",
                      flag="--site", metavar="N")
    age_ka: tuple[float, ...] = param(
        (), "", "a specimen's age in thousand years (above 0, at most 10000): one per "
        "specimen, in the order of the fragilities, or one for all", flag="--age-ka",
        metavar="KA")
    age_sd_ka: tuple[float, ...] = param(
        (), "", "its standard deviation (ka, 0-10000; normal truncated at 0): one per "
        "specimen or one for all; default 0", flag="--age-sd-ka", metavar="KA")
    rule: str = param(None, "", "the headline's rule: bayes (weights x survival probability; "
                      "default) or eliminate (branches of survival below --floor dropped); "
                      "both are written", flag="--rule", choices=("bayes", "eliminate"))
    floor: float = param(None, "", "survival probability below which elimination drops a "
                         f"branch (0-1, above 0 and below 1); default {FLOOR:g}", flag="--floor",
                         metavar="P")
    out: Path = param(None, "", f"output directory (default {display_path(CONSTRAIN_OUT)})",
                      flag="--out", metavar="DIR")

    def __post_init__(self):
        self._fill(rule="bayes", floor=FLOOR, out=CONSTRAIN_OUT)
        if self.logic_tree is None:
            raise InputError("give --logic-tree")
        self.check_specimens()
        n = self.specimen_count
        if n > MAX_SPECIMENS:
            raise InputError(f"{n} specimens (at most {MAX_SPECIMENS})")
        _check_column_site(self)
        if not self.age_ka:
            raise InputError("give --age-ka (one per specimen, or one for all)")
        ages, sds = self.ages()
        for a in ages:
            number(a, "--age-ka", 0, 10000, "ka", low_open=True)
        for s in sds:
            number(s, "--age-sd-ka", 0, 10000, "ka")
        number(self.floor, "--floor", 0, 1, low_open=True, high_open=True)
        _check_out(self.out)

    def ages(self):
        """The ages and their sds (ka), one per specimen."""
        n = self.specimen_count
        return (_per_specimen(self.age_ka, n, "--age-ka"),
                _per_specimen(self.age_sd_ka or (0.0,), n, "--age-sd-ka"))


def _check_column_site(options):
    if options.column is not None and not options.fragility:
        raise InputError("--column applies to --fragility files")
    if options.fragility_form is not None and not options.fragility:
        raise InputError("--fragility-form applies to --fragility files (a stated fragility "
                         "has its own form)")
    if options.below_grid != "ramp" and not options.fragility:
        raise InputError("--below-grid applies to a pulse-grid fragility (--fragility of "
                         "campaign fragility --pulses)")
    if options.site is not None and options.site < 0:
        raise InputError(f"--site must be 0 or more, got {options.site}")


def _check_out(out):
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} exists and is not a directory")


def _per_specimen(values, n, flag):
    if len(values) == 1:
        return list(values) * n
    if len(values) != n:
        raise InputError(f"give one {flag} per specimen ({n}) or one for all, got "
                         f"{len(values)}")
    return list(values)


def _distinct_files(paths: tuple[Path, ...], flag: str, what: str,
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


def parse_logistic(text):
    """'b0,b1,b2' -> (b0, b1, b2): finite numbers, b1 > 0 (P grows with PGA)."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError(f"--logistic {text!r}: expected three numbers B0,B1,B2")
    if not values[1] > 0:
        raise InputError(f"--logistic {text!r}: b1 must be positive (P grows with PGA)")
    return values
