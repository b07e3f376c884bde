"""The time step of a scene (s): the stability limit of the explicit contact law at a
contact's damping ratio, the factor a scene uses, the step of its lightest body on its
rim springs, and the wall-time cost (s) that step gives a scene.
"""
import logging
import math

from pipeline.files import InputError

log = logging.getLogger(__name__)

# An explicit step of a spring-dashpot of damping ratio zeta is stable for
# dt omega <= 2 (sqrt(1 + zeta^2) - zeta).  The scene's fastest mode is not one body on
# its rim springs (omega_n = sqrt(kn x rim points / m), the time step's unit) but the
# drums of a stack rocking on each other: measured on the still twin model over 5 s
# (make bench, section 9), the first factors that turn a body by degrees fit a mode of
# MODE_FREQUENCY_RATIO omega_n with MODE_DAMPING_RATIO times the contact's damping ratio
# (failures at zeta 0.2, 0.36, 0.5, 0.7, 1.0 from factors 0.45, 0.306, 0.24, 0.208, 0.166).
# The allowed factor is STABLE_DT_FRACTION of that mode's bound: at least 1.28x below
# every failure measured.
MODE_FREQUENCY_RATIO = 3.0
MODE_DAMPING_RATIO = 2.3
STABLE_DT_FRACTION = 0.75
CONVERGED_DT_FACTOR = 0.3     # outcomes converged up to this factor (make bench, section 5)


def largest_stable_dt_factor(damping):
    """Largest time-step factor that keeps contacts of this damping ratio stable."""
    zeta = MODE_DAMPING_RATIO * damping
    return STABLE_DT_FRACTION * 2.0 * (math.sqrt(1 + zeta ** 2) - zeta) / MODE_FREQUENCY_RATIO


def dt_factor_for(contact, numerics):
    """The time-step factor a scene uses: the given one, else the largest stable at the
    contact damping, at most CONVERGED_DT_FACTOR."""
    if numerics.dt_factor is not None:
        return numerics.dt_factor
    return min(CONVERGED_DT_FACTOR, largest_stable_dt_factor(contact.damping))


US_PER_BODY_STEP = 8.0   # wall us per body and time step: twin model 4.5 (8 bodies, ~36 us
#                          a step), a stack of 60 thin drums over 6.7 (it hit its wall limit)


def time_step_s(columns, contact, rim_points, dt_factor):
    """The scene's time step (s): ``dt_factor`` sqrt(m / (kn x base points)) of its
    lightest body on its base rim (at least ``rim_points`` points: a box on its four
    corners steps as finely as a drum on its rim); the scene takes it from the scene
    file."""
    stiffness = []
    for column in columns:
        for body in column["bodies"]:
            base = next(r for r in body["rims"] if r["role"] == "base")
            n_base = rim_points if base["kind"] == "circle" else len(base["points"])
            stiffness.append((body["mass"], contact.kn * max(n_base, rim_points)))
    return dt_factor * math.sqrt(min(m / k for m, k in stiffness))


def check_cost(params, wall_limit_s):
    """InputError when the scene file ``params`` would need more wall time for its t_max than
    ``wall_limit_s`` (the run's wall-clock limit would end it): say so before starting;
    a note on stdout when it takes over 5 minutes.  Returns the estimate (s): t_max /
    time step x bodies x US_PER_BODY_STEP."""
    bodies = sum(len(c["bodies"]) for c in params.columns)
    estimate = params.t_max / params.time_step_s * bodies * US_PER_BODY_STEP * 1e-6
    what = (f"{bodies} bodies stepping {params.time_step_s:.2g} s for "
            f"{params.t_max:.0f} s simulated: about {estimate / 60:.0f} min")
    if estimate > wall_limit_s:
        raise InputError(f"{what}, beyond the run's wall-clock limit ({wall_limit_s / 60:.0f} "
                         "min): use fewer or heavier blocks, a stiffer contact or a shorter "
                         "--window")
    if estimate > 300.0:
        log.info(f"note: {what} at most (quiet parts are skipped)")
    return estimate


def check_time_step(contact, numerics):
    """InputError when the time-step factor is too coarse for the contact damping."""
    limit = largest_stable_dt_factor(contact.damping)
    if numerics.dt_factor is not None and numerics.dt_factor > limit:
        raise InputError(f"--dt-factor {numerics.dt_factor:g} with --damping "
                         f"{contact.damping:g} is unstable (a still column rocks or falls): "
                         f"at this damping use --dt-factor <= {math.floor(limit * 1e3) / 1e3:g}")

