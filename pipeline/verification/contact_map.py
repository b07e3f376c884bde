"""The contact damping ratio that gives a block a stated rocking restitution in YADE.

YADE's contact law (ViscElMat: a spring kn and a dashpot of damping ratio ``damping`` per
contact point) has no restitution of rocking of its own: a block's restitution (angular
velocity after / before an impact) comes out of the impacts of its corner springs.  It is
measured here by free rocking of the block in YADE (released from rest at half its
overturning angle, :func:`pipeline.verification.checks.run_block`; the restitution from its
successive amplitudes, :func:`pipeline.rocking.fit_free_rocking`), and the damping found
by bisection: the restitution falls monotonically with the damping, from an almost
elastic impact at 0 to Housner's perfectly inelastic value (1 - 1.5 sin^2 alpha) at 1.
A restitution outside that range is not reachable by this law and is refused.
"""
import math
import tempfile

from pipeline import paper, rocking
from pipeline.files import InputError
from pipeline.verification.checks import MARBLE_CONTACT, run_block

RESTITUTION_TOLERANCE = 0.0005   # |measured - stated| restitution the bisection stops at
DAMPING_TOLERANCE = 0.002        # or the damping interval below this
RELEASE_RATIO = 0.5              # released from rest at this fraction of alpha
IMPACTS = 6


def rocking_restitution(height, width, depth, damping, kn=paper.MARBLE_BLOCK_KN_N_M,
                        density=paper.MARBLE_DENSITY_KG_M3, release_ratio=RELEASE_RATIO):
    """The restitution (mean over its first impacts) of the block rocking freely in YADE
    at contact damping ratio ``damping`` and stiffness ``kn`` (N/m per point), released
    from rest at ``release_ratio`` of its overturning angle."""
    alpha = math.atan(width / height)
    reference = rocking.housner_free_rocking(height, width, release_ratio * alpha,
                                             n_impacts=IMPACTS)
    duration = float(reference["peak_times"][IMPACTS]) + 0.05
    with tempfile.TemporaryDirectory(prefix="toppling-contact-") as run_dir:
        t, theta, _ = run_block(run_dir, height, width, depth, release_ratio * alpha,
                                duration=duration, density=density,
                                **{**MARBLE_CONTACT, "kn": kn, "damping": damping})
    return rocking.fit_free_rocking(height, width, t=t, theta=theta)["restitution"]


def damping_for_restitution(restitution, height, width, depth, kn=paper.MARBLE_BLOCK_KN_N_M,
                            density=paper.MARBLE_DENSITY_KG_M3, log=print):
    """(damping, measured restitution, runs) for the stated ``restitution`` of this block
    at ``kn``: bisection on the damping ratio in [0, 1], each step one YADE free-rocking
    run.  InputError (one line, naming the reachable range) when the restitution lies
    outside what damping 0-1 gives."""
    low, high = 0.0, 1.0
    r_low = rocking_restitution(height, width, depth, low, kn, density)
    r_high = rocking_restitution(height, width, depth, high, kn, density)
    runs = 2
    if not r_high - RESTITUTION_TOLERANCE <= restitution <= r_low + RESTITUTION_TOLERANCE:
        raise InputError(f"restitution {restitution:.3f}: this block reaches "
                         f"{r_high:.3f}-{r_low:.3f} with contact damping 1-0 in YADE "
                         f"(kn {kn:g} N/m); a lower one needs a lossier contact than the "
                         "perfectly inelastic impact of Housner's")
    best = min(((abs(r_low - restitution), low, r_low), (abs(r_high - restitution), high, r_high)))
    while best[0] > RESTITUTION_TOLERANCE and high - low > DAMPING_TOLERANCE:
        middle = 0.5 * (low + high)
        r_middle = rocking_restitution(height, width, depth, middle, kn, density)
        runs += 1
        log(f"damping {middle:.4f}: restitution {r_middle:.4f}")
        best = min(best, (abs(r_middle - restitution), middle, r_middle))
        if r_middle > restitution:        # too elastic: more damping
            low = middle
        else:
            high = middle
    return best[1], best[2], runs
