"""The contact damping ratio that gives a block a stated rocking restitution in YADE.

YADE's contact law (ViscElMat: a spring kn and a dashpot of damping ratio ``damping`` per
contact point) has no restitution of rocking of its own: a block's restitution (angular
velocity after / before an impact) comes out of the impacts of its corner springs.  It is
measured here by free rocking of the block in YADE (released from rest at half its
overturning angle, :func:`pipeline.verification.checks.run_block`; the restitution from its
successive amplitudes, :func:`pipeline.rocking.fit_free_rocking`), and the damping found
by bisection: the restitution falls monotonically with the damping, from an almost
elastic impact at 0 to Housner's perfectly inelastic value (1 - 1.5 sin^2 alpha) at 1.
A restitution outside that range is not reachable by this law and is refused.  Each
measured restitution is kept in a cache file (JSON, ``CACHE``) by block, density, kn,
damping and the model's code, so a block mapped once is not run again.
"""
import json
import math
import tempfile

from pipeline import RESULTS_DIR, paper, rocking
from pipeline.files import InputError, code_hash, write_json
from pipeline.verification.checks import MARBLE_CONTACT, run_block

RESTITUTION_TOLERANCE = 0.0005   # |measured - stated| restitution the bisection stops at
DAMPING_TOLERANCE = 0.002        # or the damping interval below this
RELEASE_RATIO = 0.5              # released from rest at this fraction of alpha
IMPACTS = 6
CACHE = RESULTS_DIR / "contact" / "restitution_map.json"


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
                            density=paper.MARBLE_DENSITY_KG_M3, log=print, cache=CACHE):
    """(damping, measured restitution, YADE runs made) for the stated ``restitution`` of
    this block at ``kn``: bisection on the damping ratio in [0, 1], each step one YADE
    free-rocking run unless ``cache`` (a JSON file, or None) holds it.  InputError (one line, naming the reachable range) when the restitution lies
    outside what damping 0-1 gives."""
    cached = json.loads(cache.read_text()) if cache is not None and cache.is_file() else {}
    model = code_hash("scenario", "verification", "yade_scripts")
    runs = 0

    def measured(damping):
        nonlocal runs
        key = f"{height:.6g},{width:.6g},{depth:.6g},{density:.6g},{kn:.6g},{damping:.6g},{model}"
        if key not in cached:
            cached[key] = rocking_restitution(height, width, depth, damping, kn, density)
            runs += 1
            if cache is not None:
                write_json(cache, cached)
        return cached[key]

    low, high = 0.0, 1.0
    r_low, r_high = measured(low), measured(high)
    if not r_high - RESTITUTION_TOLERANCE <= restitution <= r_low + RESTITUTION_TOLERANCE:
        raise InputError(f"restitution {restitution:.3f}: this block reaches "
                         f"{r_high:.3f}-{r_low:.3f} with contact damping 1-0 in YADE "
                         f"(kn {kn:g} N/m); a lower one needs a lossier contact than the "
                         "perfectly inelastic impact of Housner's")
    best = min(((abs(r_low - restitution), low, r_low), (abs(r_high - restitution), high, r_high)))
    while best[0] > RESTITUTION_TOLERANCE and high - low > DAMPING_TOLERANCE:
        middle = 0.5 * (low + high)
        r_middle = measured(middle)
        log(f"damping {middle:.4f}: restitution {r_middle:.4f}")
        best = min(best, (abs(r_middle - restitution), middle, r_middle))
        if r_middle > restitution:        # too elastic: more damping
            low = middle
        else:
            high = middle
    return best[1], best[2], runs
