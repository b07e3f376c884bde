"""The ``survival`` command's workflow: a standing specimen's survival under a site's
hazard curves written as ``survival.json`` and ``survival.png``, and the PGA range a
site's standing and fallen columns allow as ``site_motion.json`` (docs/survival.md).
The command reads its options; this reads the input files and writes the results
(:func:`survival_outputs`)."""
from dataclasses import replace

from pipeline.assessment.options import parse_logistic
from pipeline.assessment.state_options import parse_state_lognormal, state_fragility
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError, file_set, result_json_text, write_text
from pipeline.hazard.assess import assess
from pipeline.hazard.damage_states import COLLAPSE, StateFragility
from pipeline.hazard.fragility.components import OnHazardMeasure
from pipeline.hazard.fragility.load import load_state_fragilities
from pipeline.hazard.curves import load_hazard
from pipeline.hazard.fragility import Logistic, Lognormal
from pipeline.hazard.joint_assess import assess_joint
from pipeline.hazard.site_motion import site_motion
from pipeline.inversion.observations import load_observations

FELL_OR_STOOD = ((COLLAPSE, COLLAPSE), (0, COLLAPSE - 1))   # no damage state seen
FILES = ("survival.json", "survival.png", "site_motion.json")   # every file survival writes
SUMMARIES = ("survival.json", "site_motion.json")           # what says what the set holds


def site_motion_result(observations_path, site_name, fragility_for, at_pgv_pga, pga_measure):
    """site_motion.json's content: the PGA range consistent with one site's columns
    (``site_name`` None: the file's only site; ``fragility_for(column type, states)`` its
    fragility, ``states`` whether a column of that type was seen in a damage state, so
    that it needs the states below collapse; ``pga_measure``: what the PGA is, in
    words)."""
    observations = load_observations(observations_path)
    name = site_name
    if name is None:
        if len(observations.sites) != 1:
            raise InputError(f"{observations_path.name}: {len(observations.sites)} sites: "
                             "name one with --observation-site")
        name = observations.sites[0].name
    seen = {c.column for site in observations.sites if site.name == name
            for c in site.columns if tuple(c.state_range) not in FELL_OR_STOOD}
    result = site_motion(observations, name,
                         lambda column: fragility_for(column, column in seen), at_pgv_pga)
    result["pga_measure"] = pga_measure
    return result


def write_site_motion(out, result):
    """Write ``result`` as ``out``/site_motion.json (atomically; an earlier run's
    survival.json and survival.png removed: they are not of this run)."""
    text = result_json_text(result, "site_motion.json")
    with file_set(out, FILES, SUMMARIES) as stage:
        write_text(stage / "site_motion.json", text)


def survival_files(out, curves, specimens, ratio, age, draws, seed, hazard_component,
                   site_motion=None):
    """survival.json's content (:func:`pipeline.hazard.assess.assess` under ``curves``,
    the first the headline; ``age`` an :class:`~pipeline.hazard.ages.AgeModel`), written
    with survival.png to ``out`` as one set (with site_motion.json when ``site_motion`` is
    given; an earlier run's left out removed)."""
    summary, data = assess(curves[0], specimens, ratio, age, draws, seed, curves[1:])
    return _write(out, summary, data, hazard_component, site_motion)


def joint_survival_files(out, joint, specimens, age, draws, seed, hazard_component):
    """survival.json's content under the joint hazard ``joint`` of one site
    (:func:`pipeline.hazard.joint_assess.assess_joint`), written with survival.png to
    ``out`` as one set."""
    summary, data = assess_joint(joint, specimens, age, draws, seed)
    return _write(out, summary, data, hazard_component, None)


def _write(out, summary, data, hazard_component, site_motion):
    """survival.json (a :class:`~pipeline.hazard.results.SurvivalResult`; and
    site_motion.json) checked, then written with survival.png; returns survival.json."""
    from pipeline.figures.survival import plot_survival  # lazy: matplotlib, only when a figure is drawn
    summary = replace(summary, hazard_component=hazard_component, figure="survival.png",
                      **({} if site_motion is None else {"site_motion": site_motion}))
    texts = {"survival.json": summary.text()}   # before any file
    if site_motion is not None:
        texts["site_motion.json"] = result_json_text(site_motion, "site_motion.json")
    with file_set(out, FILES, SUMMARIES) as stage:
        plot_survival(data, stage / "survival.png")
        for name, text in texts.items():
            write_text(stage / name, text)
    return summary


def survival_outputs(o):
    """What ``survival`` writes for the options ``o``
    (:class:`~pipeline.assessment.options.SurvivalOptions`): (survival.json as a
    :class:`~pipeline.hazard.results.SurvivalResult` or None, site_motion.json's or None, the age model or None), the files written to
    ``o.out``."""
    site_motion = None if o.observations is None else _site_motion(o)
    if not o.hazard and o.joint_hazard is None:
        write_site_motion(o.out, site_motion)
        return None, site_motion, None
    age = o.age_model()
    specimens = o.specimens()
    if o.joint_hazard is not None:
        return joint_survival_files(o.out, _joint_site(o), specimens, age, o.draws, o.seed,
                                    o.hazard_component), None, age
    curves = [load_hazard(path, o.site) for path in o.hazard]
    ratio = o.ratio_model(specimens) if o.disaggregation is None \
        else o.disaggregation_ratio(curves[0])
    return survival_files(o.out, curves, specimens, ratio, age, o.draws, o.seed,
                          o.hazard_component, site_motion), site_motion, age


def _joint_site(o):
    """The joint hazard of --joint-hazard at --site (unset: the file's only site)."""
    from pipeline.hazard.joint_hazard import load_joint_hazard  # lazy: h5py, only for --joint-hazard
    joint = load_joint_hazard(o.joint_hazard)
    if o.site is None and len(joint.sites) != 1:
        raise InputError(f"{o.joint_hazard}: {len(joint.sites)} sites: name one with --site")
    return joint.site(0 if o.site is None else o.site)


def _site_motion(o):
    """site_motion.json's content: the PGA range consistent with one site's columns, each
    column type's fragility from the options ``o``: of toppling, with the lower damage
    states' of --state-lognormal, or else of --fragility's damage-state fits for that
    column type (:func:`_file_states`)."""
    lower = parse_state_lognormal(o.state_lognormal)
    if o.fragility:
        def toppling(column):
            return o.campaign_fragility(o.fragility[0], column)
        if not lower:
            return _site_motion_of(o, lambda column, states: _file_states(
                o, toppling(column), column) if states else
                StateFragility.toppling(toppling(column)))
    elif o.median_g:
        stated = Lognormal(o.median_g[0] * STANDARD_GRAVITY, o.beta[0],
                           label=f"stated lognormal: median {o.median_g[0]:g} g, "
                           f"beta {o.beta[0]:g} (every column)")
        def toppling(column):
            return stated
    else:
        stated = Logistic(parse_logistic(o.logistic[0]),
                          label=f"stated logistic surface {o.logistic[0]} (every column)")
        def toppling(column):
            return stated

    return _site_motion_of(o, lambda column, states: state_fragility(toppling(column), lower))


def _file_states(o, collapse, column):
    """The :class:`~pipeline.hazard.damage_states.StateFragility` of ``column``: its
    toppling fragility ``collapse`` (of --fragility, on the PGA of --hazard-component),
    the states below it from the same file's damage-state fits, put on that PGA as
    ``collapse`` is."""
    lower, source = load_state_fragilities(o.fragility[0], column)
    if isinstance(collapse, OnHazardMeasure) and any(f is not None for f in lower):
        lower = tuple(None if f is None else replace(collapse, inner=f) for f in lower)
        source += f", put on its PGA as the toppling fit ({o.hazard_component})"
    return StateFragility(lower + (collapse,), source)


def _site_motion_of(o, fragility_for):
    """:func:`site_motion_result` of the options ``o`` with ``fragility_for(column,
    states)``."""
    return site_motion_result(
        o.observations, o.observation_site, fragility_for, o.at_pgv_pga,
        f"{o.hazard_component}: a campaign's fragility put on it "
        "(fragilities.*.pga_measure)" if o.fragility else
        "the stated fragility's own PGA")
