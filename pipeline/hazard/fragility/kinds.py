"""The declared fragility of survival and constrain (:class:`Fragility`: P(overturn |
PGA, PGV/PGA) and what is known of its uncertainty) and its two fitted kinds:
:class:`Lognormal` over PGA (a stated median and beta, or the PGA fit of ``campaign
fragility``) and :class:`Logistic`, the surface of ``campaign fragility``, logit P = b0 +
b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s) (Purvance et al. 2008).  Each can draw
parameter sets from the uncertainty of its estimate (``draws``): ln median and ln beta
normal with the spread of their 95 % intervals (independent: the campaign writes no
covariance between them), the logistic coefficients multivariate normal with their
covariance (each only its standard error when the file holds no covariance: ``note``
says so).  A column campaign's fragility is one of these two with its members' own fits
(``member_fits``); the other kinds are
:class:`~pipeline.hazard.fragility.grid.PulseGrid` (a pulse grid's cells) and
:class:`~pipeline.hazard.fragility.components.OnHazardMeasure` (any kind read on the hazard
curve's PGA).
"""
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import special, stats

from pipeline.constants import STANDARD_GRAVITY

Z95 = stats.norm.ppf(0.975)
MEDIAN_G_RANGE = (0.001, 10.0)   # a lognormal fragility's median PGA (g), stated or from a file
BETA_RANGE = (0.01, 3.0)         # its dispersion (natural log), stated or from a file


class Fragility(ABC):
    """P(overturn | PGA, PGV/PGA) of one specimen.  ``label`` (text) names it;
    ``uses_ratio`` (bool) says whether P depends on PGV/PGA.  PGA in m/s^2 on the
    fragility's own measure, PGV/PGA in s, P in 0-1."""
    label: str
    uses_ratio: bool

    @abstractmethod
    def probability(self, pga_m_s2, pgv_pga_s=None):
        """P(overturn) at PGA (m/s^2) and PGV/PGA (s; may be None when ``uses_ratio`` is
        False), an array of their broadcast shape."""

    @abstractmethod
    def draws(self, n, rng):
        """``n`` fragilities of the same kind drawn from the uncertainty of the estimate
        (``rng`` a numpy Generator), or None when it states none."""

    @abstractmethod
    def describe(self):
        """A JSON-ready dict saying what the fragility is (form, label, parameters)."""

    def members(self):
        """One fragility per parameter set (member) of the campaign, or None."""
        return None

    def stacks_with(self, other):
        """True when :meth:`probability_stack` takes ``other`` with this one (by default
        never: each is evaluated alone)."""
        return False

    def probability_stack(self, fragilities, pga_m_s2, pgv_pga_s=None):
        """P of each of ``fragilities`` (this one's kind, each :meth:`stacks_with` it) at
        the points: D x the points' shape."""
        return np.array([f.probability(pga_m_s2, pgv_pga_s) for f in fragilities])

    def grid_range(self):
        """(first, last) PGA (m/s^2) of the grid the fragility is read from, or None when
        it has no grid."""
        return None

    def variants(self):
        """{"zero": P = 0 below the grid, "edge": the edge's P held below it} (a lower and
        an upper bound on the rate), or None when it has no grid."""
        return None


@dataclass(frozen=True)
class _Fitted(Fragility):
    """A fitted form's ``note`` and the campaign's fits of its members (``member_fits``),
    keyword-only."""
    note: str | None = field(default=None, kw_only=True)
    member_fits: tuple | None = field(default=None, compare=False, kw_only=True)

    def members(self):
        """One fragility per member (parameter set) of the campaign, or None."""
        return None if not self.member_fits else list(self.member_fits)


@dataclass(frozen=True)
class Lognormal(_Fitted):
    """P(overturn | PGA) = Phi(ln(PGA / median) / beta): ``median_m_s2`` (m/s^2), ``beta``
    (natural log); optional 95 % intervals of each (same units) for :meth:`draws`."""
    median_m_s2: float
    beta: float
    median_ci95: tuple | None = None
    beta_ci95: tuple | None = None
    label: str = "lognormal"
    uses_ratio = False

    def probability(self, pga_m_s2, pgv_pga_s=None):
        """P(overturn) at PGA (m/s^2), the same at any PGV/PGA; shaped like both broadcast."""
        pga = np.asarray(pga_m_s2, float)
        if pgv_pga_s is not None:
            pga = np.broadcast_to(pga, np.broadcast_shapes(pga.shape, np.shape(pgv_pga_s)))
        return stats.norm.cdf(np.log(pga / self.median_m_s2) / self.beta)

    def draws(self, n, rng):
        """``n`` parameter sets drawn from the estimate's uncertainty; None without one."""
        if self.median_ci95 is None and self.beta_ci95 is None:
            return None
        ln_m = _ln_normal(self.median_m_s2, self.median_ci95, n, rng)
        ln_b = _ln_normal(self.beta, self.beta_ci95, n, rng)
        return [replace(self, median_m_s2=float(np.exp(m)), beta=float(np.exp(b)),
                        member_fits=None) for m, b in zip(ln_m, ln_b)]

    def describe(self):
        return {"form": "P = Phi(ln(PGA / median) / beta)", "label": self.label,
                "median_m_s2": self.median_m_s2, "median_g": self.median_m_s2 / STANDARD_GRAVITY,
                "beta": self.beta, "median_ci95_m_s2": self.median_ci95,
                "beta_ci95": self.beta_ci95, "note": self.note}


@dataclass(frozen=True)
class Logistic(_Fitted):
    """logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s): ``coefficients``
    (b0, b1, b2); ``cov`` (3 x 3) or ``se`` (3, None where fixed) for :meth:`draws`."""
    coefficients: tuple
    cov: tuple | None = None
    se: tuple | None = None
    label: str = "logistic surface"
    uses_ratio = True

    def probability(self, pga_m_s2, pgv_pga_s):
        b0, b1, b2 = self.coefficients
        eta = b0 + b1 * np.log(np.asarray(pga_m_s2, float)) + b2 * np.log(pgv_pga_s)
        return special.expit(eta)          # no overflow for any eta

    def draws(self, n, rng):
        b = np.array(self.coefficients, float)
        if self.cov is not None:
            # the reader checked cov positive semi-definite (within rounding): no warning
            # for an eigenvalue that rounding puts just below zero
            sample = rng.multivariate_normal(b, np.array(self.cov, float), n,
                                             check_valid="ignore")
        elif self.se is not None:
            se = np.array([0.0 if s is None else s for s in self.se], float)
            sample = b + rng.standard_normal((n, 3)) * se
        else:
            return None
        return [replace(self, coefficients=tuple(float(v) for v in row), member_fits=None)
                for row in sample]

    def describe(self):
        return {"form": "logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s)",
                "label": self.label, "coefficients": dict(zip(("b0", "b1", "b2"),
                                                              self.coefficients)),
                "covariance_used": self.cov is not None, "note": self.note}


def _ln_normal(value, ci95, n, rng):
    """n draws of ln(value) ~ N(ln value, s), s from a 95 % interval (0 without one)."""
    s = 0.0 if ci95 is None else math.log(ci95[1] / ci95[0]) / (2.0 * Z95)
    return math.log(value) + s * rng.standard_normal(n)

