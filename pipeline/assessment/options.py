"""What ``survival`` and ``constrain`` are asked, declared as
:func:`~pipeline.scenario.parameters.param` fields (name, type, default, range, unit, help;
the commands build their flags from them: :mod:`pipeline.cli._fields`), every one checked
when the options are made, before any work: the fragility and PGV/PGA options both share
(:class:`SpecimenOptions`, read by :meth:`SpecimenOptions.specimens` and
:meth:`SpecimenOptions.ratio_model`), and each command's own (:class:`SurvivalOptions`,
:class:`~pipeline.assessment.constrain_options.ConstrainOptions`), the ages among them as :mod:`pipeline.hazard.ages` models."""
import math
from dataclasses import dataclass
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.assessment.age_options import KA, age_kinds, check_age_kinds
from pipeline.assessment.distinct_files import distinct_files
from pipeline.assessment.state_options import parse_state_lognormal
from pipeline.hazard.ages import LowerBound, TruncatedNormal, UniformInterval, load_age_samples
from pipeline.hazard.fragility.components import COMPONENTS
from pipeline.hazard.disagg_ratio import ratio_mixture
from pipeline.hazard.disaggregation import load_mag_dist
from pipeline.hazard.fragility import (BELOW_GRID, GMM_MECHANISMS, Logistic, Lognormal,
                                      RatioFromGmm, RatioLognormal, load_campaign_fragility)
from pipeline.hazard.fragility.kinds import BETA_RANGE, MEDIAN_G_RANGE
from pipeline.hazard.fragility.load import FRAGILITY_FORMS
from pipeline.hazard.fragility.ratio import DEFAULT_VS30_M_S, PGA_PGV_CORRELATION
from pipeline.hazard.pga_pgv_correlation import BRADLEY_2012
from pipeline.hazard.same_place import check_same_place
from pipeline.hazard.site_motion import PGV_PGA_RANGE_S
from pipeline.records import rotd50_fraction
from pipeline.scenario.parameters import check_fields, param

COLUMNS = ("monolithic", "drums", "block2d", "block2d_worst")
SURVIVAL_OUT = RESULTS_DIR / "survival"
CONSTRAIN_OUT = RESULTS_DIR / "constrain"
MAX_SPECIMENS = 20
MAX_AGE_KA = 10000.0
MODEL_FLAGS = (("--vs30", "vs30"), ("--mechanism", "mechanism"),
               ("--pga-pgv-correlation", "pga_pgv_correlation"))   # the model's inputs
AGE_FLAGS = ("age_ka", "age_sd_ka", "age_min_ka", "age_range_ka", "age_samples",
             "age_column")


def disaggregation_param(of):
    """The ``--disaggregation`` field: the disaggregation ``of`` what (in words)."""
    return param(None, "", "or PGV/PGA at each PGA level a mixture over OpenQuake's "
                 f"magnitude-distance disaggregation {of} (its Mag_Dist CSV export): the "
                 "ground-motion model at each bin, weighted by the bin's share of the events "
                 "near that level (with --vs30, --mechanism, --pga-pgv-correlation)",
                 flag="--disaggregation", metavar="FILE", optional=True)


@dataclass(frozen=True)
class SpecimenOptions:
    """The fragilities of the specimens, the PGV/PGA at each PGA level and the draws of
    the survival interval (``--fragility`` ... ``--seed``)."""
    hazard_component: str = param(
        "rotd50", "", "the horizontal component of the hazard curve's PGA: rotd50 (NGA-West2 "
        "models, the USGS 2014 model) or rotd100 (the peak of the horizontal vector, "
        "campaign fragility's PGA); a campaign's fragility is put on it",
        flag="--hazard-component", choices=COMPONENTS)
    fragility: tuple[Path, ...] = param(
        (), "", "fragility.json of campaign fragility (or its directory); repeat for a set "
        "of specimens at the site", flag="--fragility", metavar="FILE",
        optional="stated fragilities only")
    column: str = param(None, "", "which column entry of fragility.json", flag="--column",
                        choices=COLUMNS, optional="the first 3D one")
    fragility_form: str = param(
        "auto", "", "from fragility.json: pga (its lognormal PGA fit), pga-pgv (its logistic "
        "surface in PGA and PGV/PGA) or grid (a pulse grid's cells, bilinear in ln PGA and "
        "ln PGV/PGA, the logistic surface outside); auto: pga-pgv for columns, grid for a "
        "pulse grid", flag="--fragility-form", choices=FRAGILITY_FORMS)
    below_grid: str = param(
        "ramp", "", "a pulse grid's P below its first PGA: ramp (0 at the uplift acceleration "
        "g tan(alpha), rising linearly in ln PGA to the edge's P), zero, edge (the "
        "edge's P held down to the uplift acceleration) or logistic (the fitted surface)",
        flag="--below-grid", choices=BELOW_GRID)
    median_g: tuple[float, ...] = param(
        (), "g", "a stated lognormal fragility over PGA: median PGA (as a file's PGA fit); "
        "repeat with --beta for a set", *MEDIAN_G_RANGE, flag="--median-g", metavar="G",
        optional=True)
    beta: tuple[float, ...] = param((), "", "its dispersion (natural log)", *BETA_RANGE,
                                    flag="--beta", metavar="B", optional=True)
    logistic: tuple[str, ...] = param(
        (), "", "a stated logistic surface logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 "
        "ln(PGV/PGA / 1 s) (b1 > 0); repeat for a set", flag="--logistic",
        metavar="B0,B1,B2", optional=True)
    pgv_pga_median: float = param(None, "s", "stated lognormal PGV/PGA: median", 0.001, 10,
                                  flag="--pgv-pga-median", metavar="S", optional=True)
    pgv_pga_sigma: float = param(None, "", "its sigma (natural log)", 0, 3,
                                 flag="--pgv-pga-sigma", metavar="LN", optional=True)
    magnitude: float = param(None, "", "or from Boore et al. (2014) at this moment "
                             "magnitude, e.g. the mode of the hazard's disaggregation", 3, 8.5,
                             flag="--magnitude", metavar="M", optional=True)
    distance_km: float = param(None, "km", "and this Joyner-Boore distance", 0, 300,
                               flag="--distance-km", metavar="KM", optional=True)
    vs30: float = param(DEFAULT_VS30_M_S, "m/s", "Vs30 for the model", 150, 1500,
                        flag="--vs30", metavar="M_S")
    mechanism: str = param("SS", "", "fault mechanism for the model (SS strike-slip, NS "
                           "normal, RS reverse)", flag="--mechanism", choices=GMM_MECHANISMS)
    pga_pgv_correlation: float = param(
        PGA_PGV_CORRELATION, "", "correlation of ln PGA and ln PGV residuals; the default is "
        "observed in the NGA-West2 residuals (Baker & Bradley 2017), "
        f"{BRADLEY_2012.value:g} is Bradley's (2012) prediction", 0, 0.99,
        flag="--pga-pgv-correlation", metavar="RHO")
    draws: int = param(400, "", "fragility parameter draws for the survival interval "
                       "(0: none)", 0, 20000, flag="--draws", metavar="N")
    seed: int = param(0, "", "seed of the draws", 0, None, flag="--seed")

    FRAGILITY_FLAGS = ("hazard_component", "fragility", "column", "fragility_form",
                       "below_grid", "median_g", "beta", "logistic")
    RATIO_FLAGS = ("pgv_pga_median", "pgv_pga_sigma", "magnitude", "distance_km", "vs30",
                   "mechanism", "pga_pgv_correlation")
    RATIO_GROUP = "PGV/PGA at each PGA level (for a pga-pgv fragility)"
    DRAW_FLAGS = ("draws", "seed")
    AGE_GROUP = "the specimens' age, as it is dated (one of --age-ka, --age-min-ka, " \
        "--age-range-ka, --age-samples)"

    def check_specimens(self):
        """The fragility and PGV/PGA options checked together (InputError, one line; each
        alone by :func:`~pipeline.scenario.parameters.check_fields`)."""
        if len(self.median_g) != len(self.beta):
            raise InputError(f"give one --beta per --median-g ({len(self.median_g)} medians, "
                             f"{len(self.beta)} betas)")
        for text in self.logistic:
            parse_logistic(text)
        if not self.median_g and not self.fragility and not self.logistic:
            raise InputError("no fragility: give --median-g and --beta, --logistic or "
                             "--fragility")
        distinct_files(self.fragility, "--fragility", "specimen", "fragility.json")
        self._check_ratio()

    def _check_ratio(self):
        stated = (self.pgv_pga_median, self.pgv_pga_sigma)
        modelled = (self.magnitude, self.distance_km)
        if any(v is not None for v in stated) and any(v is not None for v in modelled):
            raise InputError("PGV/PGA: give either --pgv-pga-median/--pgv-pga-sigma or "
                             "--magnitude/--distance-km, not both")
        if any(v is not None for v in stated) and None in stated:
            raise InputError("give both --pgv-pga-median and --pgv-pga-sigma")
        if any(v is not None for v in modelled) and None in modelled:
            raise InputError("give both --magnitude and --distance-km")

    def check_model_flags(self):
        """--vs30, --mechanism and --pga-pgv-correlation refused where no ground-motion
        model gives PGV/PGA (only --magnitude/--distance-km and --disaggregation use one)."""
        if self.magnitude is not None or getattr(self, "disaggregation", None) is not None:
            return
        for flag, name in MODEL_FLAGS:
            if getattr(self, name) != _default(name):
                raise InputError(f"{flag} applies with --magnitude/--distance-km or "
                                 "--disaggregation (the ground-motion model's PGV/PGA)")

    @property
    def specimen_count(self):
        return len(self.fragility) + len(self.median_g) + len(self.logistic)

    def campaign_fragility(self, path, column):
        """The fragility of ``column`` in the campaign's file ``path``, as the options
        ask for it (form, below the grid, the hazard's component)."""
        return load_campaign_fragility(path, column, self.fragility_form, self.below_grid,
                                       self.hazard_component, self.magnitude,
                                       self.distance_km, rotd50_fraction)

    def specimens(self):
        """The fragilities of the options, in order: --fragility files, --median-g/--beta,
        --logistic."""
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
        ratio = None
        if self.pgv_pga_median is not None:
            ratio = RatioLognormal(self.pgv_pga_median, self.pgv_pga_sigma)
        elif self.magnitude is not None:
            ratio = RatioFromGmm(self.magnitude, self.distance_km, self.vs30, self.mechanism,
                                 self.pga_pgv_correlation)
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
        flag="--hazard", metavar="FILE", optional=True)
    joint_hazard: Path = param(
        None, "", "or the joint hazard of PGA and PGV: an OpenQuake datastore (or its "
        "extract) holding the mean rate density mrd of PGA and PGV; PGV/PGA then comes "
        "from each event (no --pgv-pga-median, --magnitude)", flag="--joint-hazard",
        metavar="FILE", optional=True)
    site: int = param(None, "", "row (0-based) of an OpenQuake file with several sites", 0,
                      None, flag="--site", metavar="N", optional="the file's only site")
    age_ka: float = param(None, "ka", "the specimen's age (a mean with --age-sd-ka)", 0,
                          MAX_AGE_KA, low_open=True, flag="--age-ka", metavar="KA",
                          optional=True)
    age_sd_ka: float = param(0.0, "ka", "its standard deviation (normal truncated at 0)", 0,
                             MAX_AGE_KA, flag="--age-sd-ka", metavar="KA")
    age_min_ka: float = param(None, "ka", "or the age known as a lower bound only (survival "
                              "exp(-rate min) is then an upper bound)", 0, MAX_AGE_KA,
                              low_open=True, flag="--age-min-ka", metavar="KA",
                              optional=True)
    age_range_ka: tuple[float, float] = param(
        None, "ka", "or an interval the age lies in, uniform over it (e.g. from "
        "deglaciation)", 0, MAX_AGE_KA, flag="--age-range-ka", metavar=("LO", "HI"),
        optional=True)
    age_samples: Path = param(None, "", "or samples of the age's distribution: a CSV file "
                              "(a header line; # comments) with the ages in ka in a column "
                              "(its only one, or --age-column)", flag="--age-samples",
                              metavar="FILE", optional=True)
    age_column: str = param(None, "", "the column of --age-samples", flag="--age-column",
                            metavar="NAME", optional="the file's only column")
    observations: Path = param(
        None, "", "an observations file of invert (sites with fallen and standing columns): "
        "writes site_motion.json, the PGA range consistent with the site's outcome; "
        "fragility per column type from --fragility (a column fragility.json) or one stated "
        "--median-g/--beta or --logistic for all", flag="--observations", metavar="FILE",
        optional=True)
    observation_site: str = param(None, "", "the site's name in --observations",
                                  flag="--observation-site", metavar="NAME",
                                  optional="its only site")
    state_lognormal: tuple[str, ...] = param(
        (), "", "a stated lognormal fragility of a damage state below collapse, "
        "P(DS >= STATE) over PGA, for columns of --observations seen in a damage state "
        "(slight, moderate or severe; collapse is the toppling fragility); repeat per state",
        flag="--state-lognormal", metavar="STATE,MEDIAN_G,BETA",
        optional="with --fragility, the lognormal PGA fits of its damage_states")
    at_pgv_pga: float = param(None, "s", "the PGV/PGA at which the PGA range is stated (for "
                              "a fragility over PGA and PGV/PGA)", *PGV_PGA_RANGE_S,
                              flag="--at-pgv-pga", metavar="S", optional=True)
    disaggregation: Path = disaggregation_param("of the first --hazard curve")
    disaggregation_column: str = param(
        "mean", "", "the column of --disaggregation: mean, or rlzK for realisation K (that "
        "of the first --hazard curve)", flag="--disaggregation-column", metavar="NAME")
    out: Path = param(SURVIVAL_OUT, "", "output directory", flag="--out", metavar="DIR")

    RATIO_FLAGS = (*SpecimenOptions.RATIO_FLAGS, "disaggregation", "disaggregation_column")
    OBSERVATION_GROUP = "the motion at a site from its standing and fallen columns"

    def __post_init__(self):
        check_fields(self)
        if not self.hazard and self.joint_hazard is None and self.observations is None:
            raise InputError("give --hazard (survival under a hazard curve) or --observations "
                             "(the motion at a site from its columns), or both")
        self._check_joint()
        self._check_disaggregation()
        given = age_kinds(self)
        hazard = "--hazard" if self.hazard else "--joint-hazard" if self.joint_hazard else None
        if hazard is not None and not given:
            raise InputError(f"{hazard} needs the specimen's age: --age-ka, --age-min-ka, "
                             "--age-range-ka or --age-samples")
        if hazard is None and given:
            raise InputError(f"{given[0]} applies with --hazard")
        check_age_kinds(self, given)
        self._check_observations()
        self.check_specimens()
        distinct_files(self.hazard, "--hazard", "curve")
        if self.observations is not None and self.column is not None:
            raise InputError("--column does not apply with --observations (each column's own "
                             "type is read from the file)")
        _check_column_site(self)
        self.check_model_flags()
        _check_out(self.out)

    def _check_joint(self):
        """--joint-hazard: alone as the hazard, its PGV/PGA its own."""
        if self.joint_hazard is None:
            return
        if self.hazard:
            raise InputError("give --hazard or --joint-hazard, not both")
        ratio = [flag for flag, given in (
            ("--pgv-pga-median", self.pgv_pga_median is not None),
            ("--pgv-pga-sigma", self.pgv_pga_sigma is not None),
            ("--magnitude", self.magnitude is not None),
            ("--distance-km", self.distance_km is not None),
            ("--vs30", self.vs30 != _default("vs30")),
            ("--mechanism", self.mechanism != _default("mechanism"))) if given]
        if ratio:
            raise InputError(f"{ratio[0]} does not apply with --joint-hazard (its events "
                             "hold their PGV/PGA)")
        if self.observations is not None:
            raise InputError("--observations applies with --hazard or alone")
        if self.disaggregation is not None:
            raise InputError("--disaggregation does not apply with --joint-hazard (its "
                             "events hold their PGV/PGA)")

    def _check_disaggregation(self):
        """--disaggregation: the one source of PGV/PGA, with a hazard curve."""
        if self.disaggregation is None:
            if self.disaggregation_column != _default_of(SurvivalOptions,
                                                        "disaggregation_column"):
                raise InputError("--disaggregation-column applies with --disaggregation")
            return
        if self.pgv_pga_median is not None or self.magnitude is not None:
            raise InputError("PGV/PGA: give --disaggregation, --pgv-pga-median/"
                             "--pgv-pga-sigma or --magnitude/--distance-km, one of them")
        if not self.hazard:
            raise InputError("--disaggregation needs --hazard (the curve it disaggregates)")

    def disaggregation_ratio(self, curve):
        """PGV/PGA as a mixture over --disaggregation's bins
        (:class:`~pipeline.hazard.disagg_ratio.RatioMixture`), its bins first checked to
        add up to ``curve``'s rate at each level."""
        disaggregation = load_mag_dist(self.disaggregation)
        check_same_place(str(self.disaggregation), disaggregation.site, curve.source,
                         "the hazard curve")
        disaggregation.check_curve(self.disaggregation_column, curve)
        return ratio_mixture(disaggregation, self.disaggregation_column, self.vs30,
                             self.mechanism, self.pga_pgv_correlation)

    def _check_observations(self):
        if self.observations is None and (self.observation_site is not None
                                          or self.at_pgv_pga is not None):
            raise InputError("--observation-site and --at-pgv-pga apply with --observations")
        if self.state_lognormal and self.observations is None:
            raise InputError("--state-lognormal applies with --observations")
        parse_state_lognormal(self.state_lognormal)
        if self.observations is not None and self.specimen_count != 1:
            raise InputError("--observations: give one fragility (--fragility, one "
                             "--median-g/--beta or one --logistic), used by column type")

    def age_model(self):
        """The specimen's age (:class:`~pipeline.hazard.ages.AgeModel`, years) as the
        options date it (an --age-samples file read here)."""
        if self.age_ka is not None:
            return TruncatedNormal(self.age_ka * KA, self.age_sd_ka * KA)
        if self.age_min_ka is not None:
            return LowerBound(self.age_min_ka * KA)
        if self.age_range_ka is not None:
            return UniformInterval(self.age_range_ka[0] * KA, self.age_range_ka[1] * KA)
        return load_age_samples(self.age_samples, self.age_column, KA)


def _default(name):
    """The declared default of the field ``name`` of :class:`SpecimenOptions`."""
    return _default_of(SpecimenOptions, name)


def _default_of(cls, name):
    """The declared default of the field ``name`` of the options class ``cls``."""
    return cls.__dataclass_fields__[name].default


def _check_column_site(options):
    if options.column is not None and not options.fragility:
        raise InputError("--column applies to --fragility files")
    if options.fragility_form != _default("fragility_form") and not options.fragility:
        raise InputError("--fragility-form applies to --fragility files (a stated fragility "
                         "has its own form)")
    if options.below_grid != "ramp" and not options.fragility:
        raise InputError("--below-grid applies to a pulse-grid fragility (--fragility of "
                         "campaign fragility --pulses)")


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
