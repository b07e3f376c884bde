"""The contact damping that gives a block a stated rocking restitution in YADE: the
damping found for one release honours the restitution at another release (a property of
the contact, not of one test), and a restitution the law cannot reach is refused."""
import pytest

from pipeline import paper
from pipeline.files import InputError
from pipeline.verification.contact_map import bisect_damping, block_measure, rocking_restitution

H, B, D = (paper.MARBLE_BLOCK_M[k] for k in ("height", "width", "depth"))


def damping_for(restitution, cache):
    """(damping, measured restitution, YADE runs made), as ``contact --damping-map`` finds
    them for the paper's marble block."""
    measured, runs = block_measure(H, B, D, paper.MARBLE_BLOCK_KN_N_M,
                                   paper.MARBLE_DENSITY_KG_M3, cache)
    damping, found = bisect_damping(restitution, measured, "this block", lambda _: None)
    return damping, found, runs()


@pytest.mark.yade
def test_stated_restitution_is_honoured_at_another_release(tmp_path):
    stated = 0.96                      # between Housner's 0.942 and the elastic ~0.98
    cache = tmp_path / "map.json"
    damping, measured, runs = damping_for(stated, cache)
    assert 0.0 < damping < 1.0 and abs(measured - stated) <= 5e-4 and 3 <= runs <= 12
    # mapped once: the same answer from the cache, no run
    assert damping_for(stated, cache) == (damping, measured, 0)
    # released from a quarter of alpha instead of a half: the impacts keep the restitution
    assert rocking_restitution(H, B, D, damping, release_ratio=0.25) == \
        pytest.approx(stated, abs=3e-3)


@pytest.mark.yade
def test_restitution_below_housner_refused():
    # Housner's perfectly inelastic impact, 1 - 1.5 / 26 = 0.942, is the lossiest
    with pytest.raises(InputError, match="reaches"):
        damping_for(0.90, None)


@pytest.mark.yade
def test_paper_marble_block_as_far_as_its_numbers_go():
    """Hinzen (2009), Figs. 2-4: the marble block (4267 g, h/b 5, 8 cm base) released at
    10 deg matched its numeric twin up to the 18th impact in the first 5 s, with kn
    1.2e7 N/m and damping 0.36; matching the amplitudes needed a kinetic-energy ratio
    1.4 % above Housner's.  Housner's restitution puts the 18th impact near 5 s, and
    YADE's contact at the paper's parameters gives a restitution between Housner's and
    the paper's 1.4 %-larger energy ratio (an impact that keeps slightly more motion)."""
    import math
    from pipeline.rocking.response import housner_free_rocking
    alpha = math.atan(B / H)
    housner = 1 - 1.5 * math.sin(alpha) ** 2
    free = housner_free_rocking(H, B, math.radians(10.0), n_impacts=20)
    assert free["impact_times"][17] == pytest.approx(5.0, abs=0.25)
    paper_eta = math.sqrt(1.014) * housner
    measured = rocking_restitution(H, B, D, paper.DAMPING_RATIO, kn=paper.MARBLE_BLOCK_KN_N_M)
    assert housner < measured < paper_eta + 1e-3


# ---------------------------------------------------------------- bisection, cache, interval
def _stand_in(calls):
    """A cheap monotone stand-in for a YADE restitution: 0.99 at damping 0 down to 0.94
    at 1, linear (its inverse is known: damping = (0.99 - r) / 0.05)."""
    def measure(damping):
        calls.append(damping)
        return 0.99 - 0.05 * damping
    return measure


def test_bisection_finds_the_stand_ins_inverse_and_caches(tmp_path):
    from pipeline.verification.contact_map import (RESTITUTION_TOLERANCE, bisect_damping,
                                                   cached_measure)
    calls, cache = [], tmp_path / "map.json"
    measured, runs = cached_measure(_stand_in(calls), "stand-in", cache)
    damping, found = bisect_damping(0.97, measured, "the stand-in", log=lambda _: None)
    assert abs(found - 0.97) <= RESTITUTION_TOLERANCE
    assert damping == pytest.approx(0.4, abs=RESTITUTION_TOLERANCE / 0.05)
    assert runs() == len(calls) == len(set(calls))
    again, runs_again = cached_measure(_stand_in(calls), "stand-in", cache)
    assert bisect_damping(0.97, again, "the stand-in", log=lambda _: None) == (damping, found)
    assert runs_again() == 0                       # all from the cache file
    with pytest.raises(InputError, match="the stand-in reaches 0.940-0.990"):
        bisect_damping(0.90, again, "the stand-in", log=lambda _: None)


def test_damping_interval_maps_the_standard_error_through_the_stand_in():
    from pipeline.verification.contact_map import damping_interval
    measure = _stand_in([])
    interval = damping_interval(0.97, 0.005, measure, "the stand-in", log=lambda _: None)
    # restitution 0.975 (more elastic) -> less damping 0.3; 0.965 -> 0.5
    assert interval["low"] == pytest.approx(0.3, abs=0.011)
    assert interval["high"] == pytest.approx(0.5, abs=0.011)
    assert interval["clipped"] == []
    # beyond the elastic end: the low end is the range's end, and said
    wide = damping_interval(0.985, 0.01, measure, "the stand-in", log=lambda _: None)
    assert wide["low"] == 0.0 and wide["clipped"] == ["low"]
    assert wide["high"] == pytest.approx(0.3, abs=0.011)
    assert damping_interval(0.97, None, measure, "the stand-in") is None


@pytest.mark.yade
def test_specimen_path_equals_the_block_path_on_the_marble_block():
    """Any specimen's free rocking (released by turning the scene about its footprint's
    support line; the restitution from its energy per swing, and from the centre of
    mass's successive rises) against the block's own path (released by its edge tilt;
    Housner's amplitude formula): for a rigid symmetric block the three are the same
    quantity, within 1e-3."""
    from pipeline.scenario import ColumnGeometry
    from pipeline.verification.checks import MARBLE_CONTACT
    from pipeline.verification.contact_map import specimen_rocking
    block = ColumnGeometry.block(H, B, D, paper.MARBLE_DENSITY_KG_M3)
    options = {k: v for k, v in MARBLE_CONTACT.items() if k not in ("kn", "damping")}
    found = specimen_rocking(block, paper.DAMPING_RATIO, paper.MARBLE_BLOCK_KN_N_M,
                             azimuth_deg=90.0, **options)
    import math
    assert found["critical_angle_deg"] == pytest.approx(math.degrees(math.atan(B / H)), abs=1e-6)
    assert found["impacts"] >= 5
    block_path = rocking_restitution(H, B, D, paper.DAMPING_RATIO)
    assert found["restitution"] == pytest.approx(block_path, abs=1e-3)
    assert found["restitution_from_rises"] == pytest.approx(block_path, abs=1e-3)
    # default azimuth: the weak side, across the block's depth (D < B)
    from pipeline.verification.contact_map import _scene, weakest_azimuth
    from pipeline.scenario import Contact, Numerics
    assert weakest_azimuth(_scene(block, Contact(), Numerics())[1]) % 180.0 == 0.0


def test_a_restitution_the_bisection_cannot_meet_is_said():
    """A measure with a step (as a rock's scattered restitution can have) leaves the
    stated value unmet: the nearest is returned and a warning line says so."""
    from pipeline.verification.contact_map import bisect_damping
    lines = []
    damping, found = bisect_damping(0.965, lambda d: 0.99 if d < 0.3 else 0.94, "a step",
                                     log=lines.append)
    assert found in (0.99, 0.94) and (damping < 0.3) == (found == 0.99)
    assert "not met" in lines[-1] and "a step" in lines[-1]
