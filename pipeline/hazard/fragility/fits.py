"""The fits inside ``fragility.json``, each a type that checks itself on construction:
a lognormal fit of one intensity measure (:class:`LognormalFit`) and a logistic surface
in PGA and PGV/PGA (:class:`LogisticSurface`).  A refusal is one InputError naming the
value (``median must be ...``); read from a file,
:func:`~pipeline.hazard.fragility.checker.leaf` names the file and the key path before
it (``fragility.json: columns.monolithic.logistic.cov must be a 3x3 list of numbers``).
Keys a fit does not name are kept, in their order, in ``extra``."""
from dataclasses import dataclass

import numpy as np

from pipeline.hazard.fragility.checker import TOLERANCE, Checker, counts
from pipeline.hazard.fragility.keyed import Keyed
from pipeline.hazard.fragility.keyed import build as _build
from pipeline.hazard.fragility.keyed import join as _join
from pipeline.userfiles import show

B = ("b0", "b1", "b2")           # a logistic surface's coefficients: logit P = b0 + b1 ln PGA
                                 # + b2 ln PGV/PGA (PGA m/s^2, PGV/PGA s)


@dataclass(frozen=True)
class LognormalFit(Keyed):
    """A lognormal fragility of one intensity measure: ``median`` (in ``unit``) and
    ``beta`` (log standard deviation) with their 95 % intervals (each holding its
    estimate), ``n`` runs of which ``toppled`` toppled, a ``note``, ``bins`` (the observed
    fraction per IM bin, as :func:`pipeline.stats.fragility.binned_fractions` gives it);
    median None where not fitted (the note says why)."""
    median: float | None = None
    beta: float | None = None
    median_ci95: tuple | None = None
    beta_ci95: tuple | None = None
    unit: str | None = None
    note: str | None = None
    n: int | None = None
    toppled: int | None = None
    bins: tuple | None = None

    def __post_init__(self):
        """Any fit the campaign writes (a degenerate one too: a beta of 1e6, an interval
        open where it overflowed); the PGA fit survival reads is checked further by the
        file's reader (:func:`pipeline.hazard.fragility.check.check_fragility`)."""
        c = Checker("")
        c.text(self.unit, "unit")
        c.text(self.note, "note")
        median = c.num(self.median, "median", 0, None, True, True)
        beta = c.num(self.beta, "beta", 0, None, True, True)
        _open_pair(c, self.median_ci95, "median_ci95", median)
        _open_pair(c, self.beta_ci95, "beta_ci95", beta)
        counts(c, {"n": self.n, "toppled": self.toppled}, "", "n", "toppled")

    @classmethod
    def of(cls, data):
        """The fit of a dict as the campaign writes it."""
        return _build(cls, data, {"median_ci95": _tuple, "beta_ci95": _tuple, "bins": _tuple})

    def to_json(self):
        return _join(self, {"median_ci95": _list, "beta_ci95": _list, "bins": _list})


@dataclass(frozen=True)
class LogisticSurface(Keyed):
    """logit P = b0 + b1 ln PGA + b2 ln PGV/PGA (PGA m/s^2, PGV/PGA s), as
    :func:`pipeline.stats.fragility.logistic_surface` fits it: ``coefficients``, ``se``
    and ``ci95`` per coefficient (:data:`B`; an interval holding its coefficient), ``cov``
    (3 x 3: symmetric positive semi-definite, or nulls where the information matrix was
    singular), ``n`` runs of which ``toppled`` toppled, a ``note``; coefficients None
    where not fitted.  Read through :attr:`b`, :attr:`se_b` and :attr:`covariance`."""
    coefficients: dict | None = None
    se: dict | None = None
    ci95: dict | None = None
    cov: tuple | None = None
    n: int | None = None
    toppled: int | None = None
    note: str | None = None
    separated: bool | None = None
    dimensionless: dict | None = None

    def __post_init__(self):
        c = Checker("")
        c.text(self.note, "note")
        counts(c, {"n": self.n, "toppled": self.toppled}, "", "n", "toppled")
        b = dict.fromkeys(B)
        if self.coefficients is not None:
            c.obj(self.coefficients, "coefficients")
            b = {k: c.num(self.coefficients.get(k), f"coefficients.{k}") for k in B}
        if self.se is not None:
            c.obj(self.se, "se")
            for k in B:
                c.num(self.se.get(k), f"se.{k}", 0, None, optional=True)
        if self.ci95 is not None:
            c.obj(self.ci95, "ci95")
            for k in B:
                c.pair(_listed(self.ci95.get(k)), f"ci95.{k}", holds=b[k])
        _check_cov(c, self.cov)

    @property
    def b(self):
        """(b0, b1, b2) as floats, or None where not fitted."""
        return None if self.coefficients is None else \
            tuple(float(self.coefficients[k]) for k in B)

    @property
    def se_b(self):
        """The standard errors of (b0, b1, b2) (None each where not given), or None."""
        return None if not self.se else tuple(self.se.get(k) for k in B)

    @property
    def covariance(self):
        """The 3 x 3 covariance (tuples of floats), or None: not given, or written as
        nulls (a singular information matrix)."""
        if self.cov is None or any(v is None for row in self.cov for v in row):
            return None
        return tuple(tuple(float(v) for v in row) for row in self.cov)

    @classmethod
    def of(cls, data):
        """The surface of a dict as the campaign writes it."""
        return _build(cls, data, {"cov": lambda v: v if not _matrix(v) else
                                  tuple(tuple(row) for row in v)})

    def to_json(self):
        return _join(self, {"cov": lambda v: v if not isinstance(v, tuple) else
                            [list(row) for row in v]})


def _open_pair(c, pair, where, holds):
    """A 95 % interval (lo, hi) of positive numbers, either None where it overflowed,
    holding ``holds`` where both are given; or None."""
    if pair is None:
        return
    if not (isinstance(pair, tuple) and len(pair) == 2):
        c.fail(where, f"must be a pair [lo, hi], got {show(_listed(pair))}")
    if None not in pair:
        c.pair(list(pair), where, 0, None, holds, True)
    for v in pair:
        c.num(v, where, 0, None, True, True)


def _check_cov(c, cov):
    """A 3 x 3 covariance: null, a matrix holding nulls (not used), or numbers: finite,
    symmetric and positive semi-definite."""
    if cov is None:
        return
    if not (_matrix(cov) and len(cov) == 3 and all(len(row) == 3 for row in cov)
            and all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool))
                    for row in cov for v in row)):
        c.fail("cov", f"must be a 3x3 list of numbers, got {show(_listed(cov))}")
    if any(v is None for row in cov for v in row):
        return
    try:
        matrix = np.array(cov, float)
    except OverflowError:
        c.fail("cov", "holds a number beyond a float's range")
    if not np.isfinite(matrix).all():
        c.fail("cov", "must hold finite numbers")
    scale = max(float(np.abs(matrix).max()), 1e-300)
    if not np.allclose(matrix, matrix.T, rtol=0.0, atol=TOLERANCE * scale):
        c.fail("cov", "is not symmetric")
    if np.linalg.eigvalsh(matrix).min() < -TOLERANCE * scale:
        c.fail("cov", "is not positive semi-definite (a variance cannot be negative)")


def _matrix(value):
    return isinstance(value, (list, tuple)) and all(isinstance(r, (list, tuple)) for r in value)


def _listed(value):
    """A tuple (as a type holds it) as the list the file holds, for the checks."""
    if isinstance(value, tuple):
        return [_listed(v) for v in value]
    return value


def _tuple(value):
    return tuple(value) if isinstance(value, list) else value


def _list(value):
    return list(value) if isinstance(value, tuple) else value
