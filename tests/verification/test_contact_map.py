"""The contact damping that gives a block a stated rocking restitution in YADE: the
damping found for one release honours the restitution at another release (a property of
the contact, not of one test), and a restitution the law cannot reach is refused."""
import pytest

from pipeline import paper
from pipeline.files import InputError
from pipeline.verification.contact_map import damping_for_restitution, rocking_restitution

H, B, D = (paper.MARBLE_BLOCK_M[k] for k in ("height", "width", "depth"))


@pytest.mark.yade
def test_stated_restitution_is_honoured_at_another_release():
    stated = 0.96                      # between Housner's 0.942 and the elastic ~0.98
    damping, measured, runs = damping_for_restitution(stated, H, B, D, log=lambda _: None)
    assert 0.0 < damping < 1.0 and abs(measured - stated) <= 5e-4 and runs <= 12
    # released from a quarter of alpha instead of a half: the impacts keep the restitution
    assert rocking_restitution(H, B, D, damping, release_ratio=0.25) == \
        pytest.approx(stated, abs=3e-3)


@pytest.mark.yade
def test_restitution_below_housner_refused():
    # Housner's perfectly inelastic impact, 1 - 1.5 / 26 = 0.942, is the lossiest
    with pytest.raises(InputError, match="reaches"):
        damping_for_restitution(0.90, H, B, D, log=lambda _: None)
