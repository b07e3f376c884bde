"""The rigid rocking frame: N identical free-standing columns capped with a rigid beam that
rests freely on their capitals and does not slide (Makris & Vassiliou 2013, "Planar rocking
response and stability analysis of an array of free-standing columns capped with a freely
supported rigid beam", EESD 42(3), doi:10.1002/eqe.2222).

The frame has one degree of freedom, the columns' common rotation theta (rad): every column
rocks about a base corner (half-width b, half-height h, R = sqrt(b^2 + h^2), alpha =
atan(b / h), mass m, I0 = its moment of inertia about that corner), and the beam, of mass
m_b = gamma N m, rides on the opposite top corners.  Its centre of mass is at R from the
pivot and the top corner at 2R along the same line, so the beam translates (it does not
rotate) with twice the velocity of the columns' centres of mass, 2 R theta'.  Per unit
column mass:

    kinetic energy    T / (N m) = (1/2) (I0 / m + 4 gamma R^2) theta'^2
    potential energy  V / (N m) = g R (1 + 2 gamma) cos(alpha sgn theta - theta)
    ground excitation Q / (N m) = -a_g R (1 + 2 gamma) cos(alpha sgn theta - theta)

Lagrange's equation is then Housner's equation of one column with the same alpha and

    p_frame^2 = g R (1 + 2 gamma) / (I0 / m + 4 gamma R^2)
              = (3 g / (4 R)) (1 + 2 gamma) / (1 + 3 gamma)     (rectangular columns),

so uplift starts at |a_g| = g tan(alpha) whatever the beam weighs, and the frame rocks as a
single column of the same slenderness enlarged by (p / p_frame)^2 = (1 + 3 gamma) / (1 + 2
gamma): the heavier the beam, the larger the equivalent column and the more stable the frame.

At an impact (theta = 0) the columns change pivot and the beam its supporting corners.  With
the impulses at the new pivots and at the new beam contacts only, the momentum of the whole
frame projected on its new motion is kept (for one column: angular momentum about the new
pivot), which gives the ratio of the angular velocities after and before

    eta_frame = (I0 / m - 2 R^2 sin^2 alpha + 4 gamma R^2 cos 2 alpha) / (I0 / m + 4 gamma R^2)
              = (1 - (3/2) sin^2 alpha + 3 gamma cos 2 alpha) / (1 + 3 gamma)   (rectangular),

Housner's 1 - (3/2) sin^2 alpha for gamma = 0, tending to cos 2 alpha for a heavy beam.
These are the forms Makris & Vassiliou give, derived again here from the frame's energy;
tests/test_rocking_frame.py checks them against the frame's kinematics and a Newton-Euler
impulse balance of columns and beam.  A cylindrical column rocking in a plane about a point
of its base rim has the same kinematics with its own I0 (``shape`` "cylinder").
"""
import math
from dataclasses import dataclass

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.rocking.housner import SHAPES, RockingBody

MAX_BEAM_MASS_RATIO = 1e3        # gamma: a beam a thousand times the columns' mass


def makris_vassiliou_p(p_column, gamma):
    """Frequency parameter (1/s) of a frame of rectangular columns of frequency parameter
    ``p_column`` (1/s) under a beam of mass ratio ``gamma`` = m_b / (N m)."""
    return p_column * math.sqrt((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma))


def makris_vassiliou_restitution(alpha, gamma):
    """Coefficient of restitution of the angular velocity of a frame of rectangular columns
    of critical angle ``alpha`` (rad) under a beam of mass ratio ``gamma``."""
    return (1.0 - 1.5 * math.sin(alpha) ** 2 + 3.0 * gamma * math.cos(2.0 * alpha)) / \
        (1.0 + 3.0 * gamma)


@dataclass(frozen=True)
class RockingFrame:
    """Identical columns of ``height`` and ``width`` (m, full sizes in the rocking plane;
    for ``shape`` "cylinder" the width is the diameter) under a rigid beam of ``gamma`` =
    beam mass / the columns' total mass (>= 0; 0: free-standing columns).  Gravity ``g``
    (m/s^2)."""
    height: float
    width: float
    gamma: float
    shape: str = "block"
    g: float = MODEL_GRAVITY

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise InputError(f"frame column shape must be one of {', '.join(SHAPES)}, got "
                             f"{self.shape!r}")
        if isinstance(self.gamma, bool) or not (isinstance(self.gamma, (int, float))
                                                and 0.0 <= self.gamma <= MAX_BEAM_MASS_RATIO):
            raise InputError(f"beam-to-columns mass ratio gamma must be a number in [0, "
                             f"{MAX_BEAM_MASS_RATIO:g}], got {self.gamma!r}")
        SHAPES[self.shape](self.height, self.width, self.g)      # sizes and g checked

    @classmethod
    def of_masses(cls, height, width, n_columns, column_mass, beam_mass, shape="block",
                  g=MODEL_GRAVITY):
        """The frame of ``n_columns`` columns of ``column_mass`` (kg) each under a beam of
        ``beam_mass`` (kg): gamma = beam_mass / (n_columns column_mass)."""
        if isinstance(n_columns, bool) or not isinstance(n_columns, int) or n_columns < 1:
            raise InputError(f"a frame needs a whole number of columns >= 1, got {n_columns!r}")
        if not (column_mass > 0 and beam_mass >= 0):
            raise InputError(f"column mass {column_mass} must be positive and beam mass "
                             f"{beam_mass} not negative (kg)")
        return cls(height, width, beam_mass / (n_columns * column_mass), shape, g)

    @property
    def column(self):
        """The column's constants (:func:`~pipeline.rocking.housner.block_constants` keys)."""
        return SHAPES[self.shape](self.height, self.width, self.g)

    @property
    def alpha(self):
        """Critical angle (rad), the column's."""
        return self.column["alpha"]

    @property
    def p(self):
        """Frequency parameter of the frame (1/s)."""
        c = self.column
        return math.sqrt(self.g * c["R"] * (1.0 + 2.0 * self.gamma) /
                         (c["I0_per_mass"] + 4.0 * self.gamma * c["R"] ** 2))

    @property
    def restitution(self):
        """Ratio of the angular velocities after and before an impact."""
        c = self.column
        r2, i0 = c["R"] ** 2, c["I0_per_mass"]
        return (i0 - 2.0 * r2 * math.sin(c["alpha"]) ** 2
                + 4.0 * self.gamma * r2 * math.cos(2.0 * c["alpha"])) / (i0 + 4.0 * self.gamma * r2)

    @property
    def uplift_acc(self):
        """Ground acceleration (m/s^2) that lifts the frame from rest: g tan(alpha)."""
        return self.g * math.tan(self.alpha)

    @property
    def size_factor(self):
        """(p_column / p_frame)^2: the single column enlarged by this factor (same alpha)
        has the frame's frequency parameter."""
        return (self.column["p"] / self.p) ** 2

    def body(self, restitution=None):
        """The frame as a :class:`~pipeline.rocking.housner.RockingBody` for the integrators
        (:func:`~pipeline.rocking.response.body_response`,
        :func:`~pipeline.rocking.pulse.body_sine_pulse_response`); its own restitution
        unless ``restitution`` is given."""
        return RockingBody(self.alpha, self.p, self.restitution, self.g).with_restitution(
            restitution)

    def energy_per_column_mass(self, theta, omega):
        """Mechanical energy of the frame over the columns' total mass (J/kg) at rotation
        ``theta`` (rad) and angular velocity ``omega`` (rad/s), scalars or arrays."""
        c = self.column
        kinetic = 0.5 * (c["I0_per_mass"] + 4.0 * self.gamma * c["R"] ** 2) * np.square(omega)
        return kinetic + self.g * c["R"] * (1.0 + 2.0 * self.gamma) * \
            np.cos(c["alpha"] - np.abs(theta))
