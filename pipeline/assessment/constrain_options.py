"""What ``constrain`` is asked, declared as :func:`~pipeline.scenario.parameters.param`
fields beside the fragility and PGV/PGA options it shares with ``survival``
(:class:`~pipeline.assessment.options.SpecimenOptions`)."""
from dataclasses import dataclass
from pathlib import Path

from pipeline.assessment.age_options import (AGE_VALUES, StatedAge, age_kinds,
                                             check_age_kinds)
from pipeline.assessment.options import (AGE_FLAGS, CONSTRAIN_OUT, KA, MAX_AGE_KA,
                                         MAX_SPECIMENS, SpecimenOptions, _check_column_site, _check_out,
                                         _per_specimen, disaggregation_param)
from pipeline.files import InputError
from pipeline.hazard.ages import LowerBound, TruncatedNormal, UniformInterval, load_age_samples
from pipeline.hazard import branch_ratio
from pipeline.hazard.constrain import FLOOR
from pipeline.hazard.disaggregation import load_mag_dist
from pipeline.scenario.parameters import check_fields, param


@dataclass(frozen=True)
class ConstrainOptions(SpecimenOptions):
    """What ``constrain`` is asked (see ``python -m pipeline constrain --help``)."""
    logic_tree: Path = param(
        None, "", "OpenQuake's export (the directory, or its realizations.csv, with one "
        "hazard_curve CSV per realisation) or a plain table branch,weight,"
        "pga_<g|m_s2|cm_s2>,annual_rate_per_yr (one row per branch and level)",
        flag="--logic-tree", metavar="PATH", required=True)
    site: int = param(None, "", "the site of the curves (0-based: the row of OpenQuake "
                      "curves with several sites, or the site column of a plain table)", 0,
                      None, flag="--site", metavar="N",
                      optional="the curves' only site (--joint-hazard: its first)")
    specimen_site: tuple[int, ...] = param(
        (), "", "the site of each specimen (0-based: the row of OpenQuake curves with "
        "several sites, or the site column of a plain table), in the order of the "
        "fragilities, or one for all; sites taken as far apart (the set's survival the "
        "product over sites)", 0, None, flag="--specimen-site", metavar="N",
        optional="every specimen at --site")
    age_ka: tuple[float, ...] = param(
        (), "ka", "a specimen's age (a mean with --age-sd-ka): one per specimen, in the "
        "order of the fragilities, or one for all", 0, MAX_AGE_KA, low_open=True,
        flag="--age-ka", metavar="KA", optional=True)
    age_sd_ka: tuple[float, ...] = param(
        (0.0,), "ka", "its standard deviation (normal truncated at 0): one per specimen or "
        "one for all", 0, MAX_AGE_KA, flag="--age-sd-ka", metavar="KA")
    age_min_ka: tuple[float, ...] = param(
        (), "ka", "or a lower bound only on a specimen's age: one per specimen or one for "
        "all", 0, MAX_AGE_KA, low_open=True, flag="--age-min-ka", metavar="KA",
        optional=True)
    age_range_ka: tuple[tuple[float, float], ...] = param(
        (), "ka", "or an interval a specimen's age lies in, uniform over it: one per "
        "specimen or one for all", 0, MAX_AGE_KA, flag="--age-range-ka",
        metavar=("LO", "HI"), optional=True)
    age_samples: tuple[Path, ...] = param(
        (), "", "or samples of a specimen's age (ka) in a column of a CSV file (its only "
        "one, or --age-column): one file per specimen or one for all",
        flag="--age-samples", metavar="FILE", optional=True)
    age: tuple[str, ...] = param(
        (), "ka", "or each specimen's age of its own kind: lower_bound:MIN, interval:LO,HI "
        "(uniform), normal:MEAN[,SD] (truncated at 0) or samples:FILE (as --age-samples); "
        "one per specimen, in the order of the fragilities, or one for all; values up to "
        f"{MAX_AGE_KA:g}", flag="--age", metavar="KIND:VALUES", optional=True)
    age_column: str = param(None, "", "the column of --age-samples (and of --age "
                            "samples:FILE)", flag="--age-column", metavar="NAME",
                            optional="each file's only column")
    rule: str = param("bayes", "", "the headline's rule: bayes (weights x survival "
                      "probability) or eliminate (branches of survival below --floor "
                      "dropped); both are written", flag="--rule",
                      choices=("bayes", "eliminate"))
    floor: float = param(FLOOR, "", "survival probability below which elimination drops a "
                         "branch", 0, 1, low_open=True, high_open=True, flag="--floor",
                         metavar="P")
    joint_hazard: Path = param(
        None, "", "or PGV/PGA at each PGA level from the rate density mrd of PGA and PGV "
        "(an OpenQuake datastore or its extract) at --site, or at each specimen's site "
        "(--specimen-site, the file's site index): each branch K its realisation "
        "K's where the file holds one per realisation (mrd-rlzs), else the mean's for every "
        "branch (the engine writes the mean's only)", flag="--joint-hazard",
        metavar="FILE", optional=True)
    disaggregation: Path = disaggregation_param("at --site")
    disaggregation_column: str = param(
        None, "", "the column of --disaggregation for every branch: mean, or rlzK for "
        "realisation K", flag="--disaggregation-column", metavar="NAME",
        optional="each branch K its column rlzK where the file holds every branch's, "
        "else mean")
    out: Path = param(CONSTRAIN_OUT, "", "output directory", flag="--out", metavar="DIR")

    RATIO_FLAGS = (*SpecimenOptions.RATIO_FLAGS, "joint_hazard", "disaggregation",
                   "disaggregation_column")
    AGE_FLAGS = (*AGE_FLAGS[:-1], "age", AGE_FLAGS[-1])
    AGE_GROUP = "the specimens' ages, as they are dated (one kind for all: one of " \
        "--age-ka, --age-min-ka, --age-range-ka, --age-samples; or --age per specimen)"

    def __post_init__(self):
        check_fields(self)
        self.check_specimens()
        n = self.specimen_count
        if n > MAX_SPECIMENS:
            raise InputError(f"{n} specimens (at most {MAX_SPECIMENS})")
        _check_column_site(self)
        self._check_ages(n)
        self._check_route(self.specimen_sites())
        self.check_model_flags()
        _check_out(self.out)

    def _check_ages(self, n):
        """One kind of age for all (--age-ka, ...) or one --age per specimen."""
        given = age_kinds(self)
        if self.age:
            if given or self.age_sd_ka != (0.0,):
                other = given[0] if given else "--age-sd-ka"
                raise InputError(f"--age gives each specimen's age: not with {other}")
            stated = [StatedAge.parse(text, MAX_AGE_KA) for text in self.age]
            _per_specimen(stated, n, "--age")
            if self.age_column is not None and all(a.file is None for a in stated):
                raise InputError("--age-column applies with --age-samples or --age "
                                 "samples:FILE")
            return
        if not given:
            raise InputError("give the specimens' ages: --age-ka, --age-min-ka, "
                             "--age-range-ka or --age-samples (one per specimen, or one "
                             "for all), or --age KIND:VALUES per specimen")
        check_age_kinds(self, given, "; ages of several kinds: one --age KIND:VALUES per "
                        "specimen")
        flag, values = AGE_VALUES[given[0]](self)
        _per_specimen(values, n, flag)
        if self.age_ka:
            _per_specimen(self.age_sd_ka, n, "--age-sd-ka")

    def _check_route(self, sites):
        """One source of PGV/PGA; --disaggregation (one site's) for specimens at one."""
        given = [flag for flag, on in (
            ("--joint-hazard", self.joint_hazard is not None),
            ("--disaggregation", self.disaggregation is not None),
            ("--pgv-pga-median/--pgv-pga-sigma", self.pgv_pga_median is not None),
            ("--magnitude/--distance-km", self.magnitude is not None)) if on]
        if len(given) > 1:
            raise InputError(f"PGV/PGA: give {given[0]} or {given[1]}, one of them")
        if self.disaggregation_column is not None and self.disaggregation is None:
            raise InputError("--disaggregation-column applies with --disaggregation")
        if self.disaggregation is not None and sites is not None and len(set(sites)) > 1:
            raise InputError("--disaggregation is one site's: the specimens are at several "
                             "sites (--specimen-site)")

    def ratio_model(self, specimens, tree=None):
        """PGV/PGA per branch of ``tree`` (a :class:`~pipeline.hazard.branch_ratio.
        BranchRatios`) from --joint-hazard's rate density or --disaggregation at --site,
        or as :meth:`SpecimenOptions.ratio_model`."""
        if self.joint_hazard is not None:
            from pipeline.hazard.joint_hazard import load_joint_hazard  # noqa: PLC0415  (h5py: lazy)
            return branch_ratio.mrd_ratios(load_joint_hazard(self.joint_hazard),
                                           self.site or 0, tree)
        if self.disaggregation is not None:
            return branch_ratio.disaggregation_ratios(
                load_mag_dist(self.disaggregation), tree, self.disaggregation_column,
                self.vs30, self.mechanism, self.pga_pgv_correlation)
        return super().ratio_model(specimens)

    def site_ratio_models(self, trees):
        """{site: PGV/PGA per branch of its tree from --joint-hazard's rate density at that
        site} for ``trees`` ({site: LogicTree}, the specimens' sites), the file read once;
        {} without --joint-hazard (then one PGV/PGA for every site)."""
        if self.joint_hazard is None:
            return {}
        from pipeline.hazard.joint_hazard import load_joint_hazard  # noqa: PLC0415  (h5py: lazy)
        joint = load_joint_hazard(self.joint_hazard)
        return {site: branch_ratio.mrd_ratios(joint, site, tree) for site, tree in trees.items()}

    def specimen_sites(self):
        """The site of each specimen (--specimen-site), or None (all at --site)."""
        if not self.specimen_site:
            return None
        return _per_specimen(self.specimen_site, self.specimen_count, "--specimen-site")

    def ages(self):
        """The ages and their sds (ka), one per specimen (of --age-ka)."""
        n = self.specimen_count
        return (_per_specimen(self.age_ka, n, "--age-ka"),
                _per_specimen(self.age_sd_ka, n, "--age-sd-ka"))

    def age_models(self):
        """One :class:`~pipeline.hazard.ages.AgeModel` (years) per specimen (an
        --age-samples file read here, each once)."""
        n = self.specimen_count
        if self.age:
            stated = _per_specimen([StatedAge.parse(t, MAX_AGE_KA) for t in self.age], n,
                                   "--age")
            read = {a.file: a.model(self.age_column) for a in stated if a.file is not None}
            return [read[a.file] if a.file is not None else a.model() for a in stated]
        if self.age_ka:
            return [TruncatedNormal(a * KA, s * KA) for a, s in zip(*self.ages())]
        if self.age_min_ka:
            return [LowerBound(a * KA) for a in _per_specimen(self.age_min_ka, n, "")]
        if self.age_range_ka:
            return [UniformInterval(lo * KA, hi * KA)
                    for lo, hi in _per_specimen(self.age_range_ka, n, "")]
        read = {path: load_age_samples(path, self.age_column, KA)
                for path in dict.fromkeys(self.age_samples)}
        return [read[path] for path in _per_specimen(self.age_samples, n, "")]
