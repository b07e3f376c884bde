"""Housner's rigid body rocking in a plane: its constants and closed forms.

Theory after Housner (1963) and Augusti & Sinopoli (1992), as summarised in Hinzen
(2009), eqs 1-8.

Block: width b (m, in the rocking plane), height h (m), homogeneous.
alpha = atan(b/h) (rad), R = half-diagonal (m), p = sqrt(3 g / (4 R)) (1/s),
I0 = (4/3) m R^2 about a base corner.

Coefficient of restitution: Housner's exact rectangular-block value
eta = 1 - 1.5 sin^2(alpha) (angular momentum conserved about the new corner),
with the kinetic-energy ratio r = eta^2 (paper eq 4).  The paper's eq 5 is the
slender-block form eta ~ 1 - 1.5 (b/h)^2 ~ 1 - 1.5 alpha^2; we use the exact
sin^2(alpha) form everywhere (for alpha = 0.25: 0.9082 vs 0.9063).
"""
import math
from dataclasses import dataclass, replace

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError


def block_constants(height, width, g=MODEL_GRAVITY):
    """Geometry and Housner constants of a rectangular block (h, b in m).

    Returns dict: alpha (rad), R (m, half-diagonal), p (1/s), I0_per_mass
    (m^2, (4/3) R^2), restitution (Housner eta = 1 - 1.5 sin^2 alpha, for the
    angular velocity), energy_ratio (r = eta^2), uplift_acc (m/s^2, g tan alpha).
    """
    if not (height > 0 and width > 0 and g > 0):
        raise InputError(f"block height {height}, width {width} and g {g} must be positive")
    alpha = math.atan(width / height)
    R = 0.5 * math.hypot(height, width)
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2
    return dict(alpha=alpha, R=R, p=math.sqrt(3.0 * g / (4.0 * R)),
                I0_per_mass=4.0 / 3.0 * R ** 2, restitution=eta,
                energy_ratio=eta ** 2, uplift_acc=g * math.tan(alpha))


def cylinder_constants(height, diameter, g=MODEL_GRAVITY):
    """Housner's constants of a homogeneous solid cylinder (h, d in m) rocking in a plane
    about a point of its base rim: the block's equation with alpha = atan(d / h), R the
    distance from that point to the centre of mass, I0 = m (d^2 / 16 + h^2 / 12) + m R^2
    about it, p = sqrt(g R / (I0 / m)) (1/s) and the restitution of a perfectly inelastic
    impact on the opposite rim point, eta = 1 - 2 R^2 sin^2(alpha) / (I0 / m) (angular
    momentum conserved about it).  Same keys as :func:`block_constants`."""
    if not (height > 0 and diameter > 0 and g > 0):
        raise InputError(f"cylinder height {height}, diameter {diameter} and g {g} must be "
                         "positive")
    alpha = math.atan(diameter / height)
    R = 0.5 * math.hypot(height, diameter)
    i0 = diameter ** 2 / 16.0 + height ** 2 / 12.0 + R ** 2
    eta = 1.0 - 2.0 * R ** 2 * math.sin(alpha) ** 2 / i0
    return dict(alpha=alpha, R=R, p=math.sqrt(g * R / i0), I0_per_mass=i0, restitution=eta,
                energy_ratio=eta ** 2, uplift_acc=g * math.tan(alpha))


SHAPES = {"block": block_constants, "cylinder": cylinder_constants}


@dataclass(frozen=True)
class RockingBody:
    """What Housner's equation theta'' = -p^2 [sin(alpha sgn theta - theta) + a_g / g
    cos(alpha sgn theta - theta)] needs of a body rocking in a plane: the critical angle
    ``alpha`` (rad, in (0, pi/2)), the frequency parameter ``p`` (1/s), the coefficient of
    restitution of the angular velocity at an impact ``restitution`` (in [0, 1]) and
    gravity ``g`` (m/s^2).  A block or a cylinder (:meth:`of_shape`), or a rocking frame
    of columns under a beam (:mod:`pipeline.rocking.frame`)."""
    alpha: float
    p: float
    restitution: float
    g: float = MODEL_GRAVITY

    def __post_init__(self):
        if not 0.0 < self.alpha < 0.5 * math.pi:
            raise InputError(f"critical angle alpha must lie in (0, pi/2) rad, got {self.alpha}")
        if not (self.p > 0 and self.g > 0 and math.isfinite(self.p) and math.isfinite(self.g)):
            raise InputError(f"frequency parameter p {self.p} and g {self.g} must be positive")
        if not 0.0 <= self.restitution <= 1.0:
            raise InputError("coefficient of restitution must lie in [0, 1], got "
                             f"{self.restitution}")

    @classmethod
    def of_shape(cls, height, width, shape="block", g=MODEL_GRAVITY, restitution=None):
        """A homogeneous block or cylinder (``shape``, a key of :data:`SHAPES`) of height and
        width (diameter) in m, with its own restitution unless ``restitution`` is given."""
        if shape not in SHAPES:
            raise InputError(f"rocking shape must be one of {', '.join(SHAPES)}, got {shape!r}")
        c = SHAPES[shape](height, width, g)
        return cls(c["alpha"], c["p"], c["restitution"], g).with_restitution(restitution)

    def with_restitution(self, restitution):
        """This body with another restitution (None: unchanged)."""
        return self if restitution is None else replace(self, restitution=float(restitution))

    @property
    def uplift_acc(self):
        """Ground acceleration (m/s^2) that lifts the body from rest: g tan(alpha)."""
        return self.g * math.tan(self.alpha)


def housner_closed_form(theta0_ratio, r, n):
    """Paper eq 6 (Housner 1963, linearised block): amplitudes theta_k / alpha.

    theta_k / alpha = 1 - sqrt(1 - r^k (1 - (1 - theta0/alpha)^2)) for
    k = 0..n, k = number of impacts so far; r = kinetic-energy ratio per impact.
    """
    k = np.arange(n + 1)
    return 1.0 - np.sqrt(1.0 - r ** k * (1.0 - (1.0 - theta0_ratio) ** 2))


def augusti_sinopoli_mu_min(width, height):
    """Paper eq 8 (Augusti & Sinopoli 1992): static friction needed for pure rocking.

    mu_s > 3 (b/h) / (4 + (b/h)^2) = 3 sin(alpha) cos(alpha) / (4 - 3 sin^2 alpha).
    This is, for a rigid block rocking about a corner at theta = 0, both the
    ratio of base friction to normal force when rocking starts from rest
    (omega = 0; demand falls as the release angle grows) and the ratio of
    horizontal to vertical base impulse of a Housner impact (see
    impact_friction_demand).  Dimensionless.
    """
    ratio = width / height
    return 3.0 * ratio / (4.0 + ratio ** 2)


def impact_friction_demand(width, height, restitution=None):
    """Horizontal / vertical base impulse of a rigid-block impact (dimensionless).

    Linear momentum of the centre of mass before and after an impact with
    angular velocity ratio eta gives |P_x| / P_z = (1 - eta) / ((1 + eta) tan alpha).
    With Housner's eta = 1 - 1.5 sin^2 alpha this equals eq 8; a lossier impact
    (smaller eta) demands more friction: the friction needed to avoid sliding
    at impact in a model whose impacts dissipate more than Housner's.
    """
    c = block_constants(height, width)
    eta = c["restitution"] if restitution is None else restitution
    return (1.0 - eta) / ((1.0 + eta) * math.tan(c["alpha"]))
