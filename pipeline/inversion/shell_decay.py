"""How P falls beyond the forward table's last ring: the shell's unknown decay.

The shell of the sources beyond the reach (:mod:`pipeline.inversion.beyond`) reads the
table past its last ring R.  Log-odds P is carried on linearly in ln(r / R) from the last
ring's P (l = logit P(R)) with a slope s that the table cannot measure:

- P never rises with distance (s <= 0), and the slope between the last two rings, never
  rising, is the slowest decay the table supports: where the rings before the last are
  near saturation (P capped at (n + 1/2) / (n + 1) for n members) their slope understates
  how fast P falls, and the ground motion's decay with distance steepens away from the
  source (the finite fault's near field saturates, spreading and attenuation do not), so
  P falls at least as fast beyond the last ring as between the last two;
- how much faster it cannot say: the steepest decay it cannot exclude leaves nothing
  falling at the shell's outer edge (``SHELL_FACTOR`` R), log-odds P there that of a node
  where none of its n members falls, logit((1/2) / (n + 1)).

So the shell's likelihood is marginalised over the slope, uniform between these two
(``steepness`` t in [0, 1]: s = (1 - t) s_slow + t s_fast, per slice, node azimuth and
column type), by Gauss-Legendre quadrature (``DECAY_NODES``).  One slope holds for every
column and site of a source (the decay is the source's and the ground's), so the mixture
is of the shell's whole likelihoods, not of each column's P.
"""
import numpy as np
from scipy import special

SHELL_FACTOR = 2.0          # the shell reaches this many times the table's last ring
DECAY_NODES = 8             # Gauss-Legendre nodes of the marginal over the slope


def decay_nodes(nodes=DECAY_NODES):
    """(steepness t in (0, 1), weights summing to 1): the quadrature of the uniform slope."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    return (x + 1.0) / 2.0, w / 2.0


def decay_factor(p_last, p_before, ring_ratio, p_none, beyond, steepness):
    """P at ln(r / R) = ``beyond`` (ne,) over the last ring's P ``p_last`` (ns, nv), for a
    slope at ``steepness`` t (0: the last two rings' slope, 1: nothing falling at the
    shell's outer edge, P ``p_none`` there): (ns, ne, nv).  ``p_before``: P at the ring
    before (None: one ring, slope 0 at t = 0); ``ring_ratio``: last ring over the one
    before."""
    last = special.logit(p_last)
    slow = np.zeros(last.shape) if p_before is None else np.minimum(
        (last - special.logit(p_before)) / np.log(ring_ratio), 0.0)
    fast = np.minimum((special.logit(p_none) - last) / np.log(SHELL_FACTOR), slow)
    slope = (1.0 - steepness) * slow + steepness * fast
    far = special.expit(last[:, None, :] + slope[:, None, :] * beyond[None, :, None])
    return far / p_last[:, None, :]
