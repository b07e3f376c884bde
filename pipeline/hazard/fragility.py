"""Fragility as survival needs it: P(overturn | PGA, PGV/PGA), and the PGV/PGA that goes
with each PGA level.

A fragility is either a :class:`Lognormal` over PGA (a stated median and beta, or the
PGA fit of ``campaign fragility``) or the :class:`Logistic` surface of ``campaign
fragility``, logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s) (Purvance et al.
2008).  Each can draw parameter sets from the uncertainty of its estimate (``draws``):
ln median and ln beta normal with the spread of their 95 % intervals (independent: the
campaign writes no covariance between them), the logistic coefficients multivariate
normal with their covariance (each only its standard error when the file holds no
covariance: ``note`` says so).

PGV/PGA (s) at a PGA level is lognormal: :class:`RatioLognormal` (a median and sigma the
user states, the same at every level) or :class:`RatioFromGmm` (the median and sigma of
PGV and PGA from Boore et al. 2014 (pygmm) at a magnitude and distance, for example the
mode of the hazard's disaggregation; ln PGV given ln PGA by their correlation).
"""
import importlib.metadata
import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import stats

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.hazard.fragility_file import MAX_MEMBERS, read_fragility_file
from pipeline.hazard.pulse_cells import interpolate
from pipeline.userfiles import DATA_FILE_BYTES, Unreadable, number, read_text, show

Z95 = stats.norm.ppf(0.975)
RATIO_NODES = 24                  # Gauss-Hermite nodes over ln(PGV/PGA)
BELOW_GRID = ("ramp", "zero", "edge", "logistic")   # P below a pulse grid: see PulseGrid
PGA_PGV_CORRELATION = 0.733       # ln PGA, ln PGV residuals: Bradley (2012), Earthq. Spectra 28(1)
GMM_MECHANISMS = ("SS", "NS", "RS")


@dataclass(frozen=True)
class Lognormal:
    """P(overturn | PGA) = Phi(ln(PGA / median) / beta): ``median_m_s2`` (m/s^2), ``beta``
    (natural log); optional 95 % intervals of each (same units) for :meth:`draws`."""
    median_m_s2: float
    beta: float
    median_ci95: tuple | None = None
    beta_ci95: tuple | None = None
    label: str = "lognormal"
    note: str | None = None
    member_fits: tuple | None = field(default=None, compare=False)
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

    def members(self):
        """One fragility per member (parameter set) of the campaign, or None."""
        return None if not self.member_fits else list(self.member_fits)

    def describe(self):
        return {"form": "P = Phi(ln(PGA / median) / beta)", "label": self.label,
                "median_m_s2": self.median_m_s2, "median_g": self.median_m_s2 / STANDARD_GRAVITY,
                "beta": self.beta, "median_ci95_m_s2": self.median_ci95,
                "beta_ci95": self.beta_ci95, "note": self.note}


@dataclass(frozen=True)
class Logistic:
    """logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s): ``coefficients``
    (b0, b1, b2); ``cov`` (3 x 3) or ``se`` (3, None where fixed) for :meth:`draws`."""
    coefficients: tuple
    cov: tuple | None = None
    se: tuple | None = None
    label: str = "logistic surface"
    note: str | None = None
    member_fits: tuple | None = field(default=None, compare=False)
    uses_ratio = True

    def probability(self, pga_m_s2, pgv_pga_s):
        b0, b1, b2 = self.coefficients
        eta = b0 + b1 * np.log(np.asarray(pga_m_s2, float)) + b2 * np.log(pgv_pga_s)
        return 1.0 / (1.0 + np.exp(-eta))

    def draws(self, n, rng):
        b = np.array(self.coefficients, float)
        if self.cov is not None:
            sample = rng.multivariate_normal(b, np.array(self.cov, float), n)
        elif self.se is not None:
            se = np.array([0.0 if s is None else s for s in self.se], float)
            sample = b + rng.standard_normal((n, 3)) * se
        else:
            return None
        return [replace(self, coefficients=tuple(float(v) for v in row), member_fits=None)
                for row in sample]

    def members(self):
        """One fragility per member (parameter set) of the campaign, or None."""
        return None if not self.member_fits else list(self.member_fits)

    def describe(self):
        return {"form": "logit P = b0 + b1 ln(PGA / 1 m/s^2) + b2 ln(PGV/PGA / 1 s)",
                "label": self.label, "coefficients": dict(zip(("b0", "b1", "b2"),
                                                              self.coefficients)),
                "covariance_used": self.cov is not None, "note": self.note}


def _ln_normal(value, ci95, n, rng):
    """n draws of ln(value) ~ N(ln value, s), s from a 95 % interval (0 without one)."""
    s = 0.0 if ci95 is None else math.log(ci95[1] / ci95[0]) / (2.0 * Z95)
    return math.log(value) + s * rng.standard_normal(n)


def load_campaign_fragility(path, column=None, form=None, below="ramp", component=None,
                            magnitude=None, distance_km=None, record_fraction=None):
    """The fragility of one column entry of ``campaign fragility``'s ``fragility.json``:
    ``form`` "pga" (its lognormal PGA fit) or "pga-pgv" (its logistic surface; default);
    ``column``: monolithic, drums, block2d or block2d_worst (default: the first 3D one).
    A pulse-grid file (``--pulses``): :func:`load_pulse_grid` (``form`` default "grid";
    ``below``: P below the grid, :class:`PulseGrid`).  Each member's own fit of the same
    form (from ``fragility_runs.csv`` beside the file, when there) in ``member_fits``.
    ``component`` (rotd50 or rotd100, the hazard curve's PGA): the fragility put on it
    (:func:`pipeline.hazard.components.on_hazard_measure`, ``record_fraction(record)``
    the RotD50 / vector peak of a record's motion); None: as in the file."""
    fragility, kind, records = _load_campaign_fragility(path, column, form, below)
    if component is None:
        return fragility
    from pipeline.hazard.components import on_hazard_measure  # noqa: PLC0415
    return on_hazard_measure(fragility, kind, component, records, record_fraction,
                             magnitude, distance_km)


def _load_campaign_fragility(path, column, form, below):
    """(fragility, "line" | "records", record ids) of :func:`load_campaign_fragility`."""
    path, data = read_fragility_file(path)          # every value below checked
    if "pulse_grid" in data:
        return load_pulse_grid(path, data, column, form or "grid", below), "line", ()
    form = form or "pga-pgv"
    columns = data["columns"]
    if column is None:
        column = next((c for c in ("monolithic", "drums") if c in columns), next(iter(columns)))
    if column not in columns:
        raise InputError(f"{path}: no column {column!r} (has {', '.join(columns)})")
    entry = columns[column]
    label = f"{column} ({entry.get('description', '')}) from {path.name}"
    if form == "pga":
        fit = entry.get("PGA") or {}
        if fit.get("unit") != "m/s^2":
            raise InputError(f"{path}: column {column}: PGA fit in unknown unit "
                             f"{fit.get('unit')!r} (expected m/s^2)")
        if fit.get("median") is None:
            raise InputError(f"{path}: column {column}: PGA fragility not fitted "
                             f"({fit.get('note') or 'no median'})")
        where = f"{path}: column {column}: PGA"
        pooled = Lognormal(number(fit["median"], f"{where} median", 0, None, "m/s^2", True),
                           number(fit.get("beta"), f"{where} beta", 0, None, "", True),
                           _pair(fit.get("median_ci95"), f"{where} median_ci95"),
                           _pair(fit.get("beta_ci95"), f"{where} beta_ci95"),
                           label=label, note=fit.get("note"))
    elif form == "pga-pgv":
        pooled = _logistic(entry.get("logistic") or {}, f"{path}: column {column}", label)
    else:
        raise InputError(f"--fragility-form must be pga or pga-pgv, got {form!r}")
    fits, note = member_fits(path.parent / "fragility_runs.csv", column, form, data)
    pooled = replace(pooled, member_fits=fits,
                     note="; ".join(filter(None, [pooled.note, note])) or None)
    return pooled, "records", tuple(data.get("records") or ())


def member_fits(runs_path, column, form, data):
    """(one fragility per member of a column campaign fitted to its own runs, note): the
    lognormal PGA fit (form "pga") or the logistic surface ("pga-pgv") of
    :mod:`pipeline.stats.ensemble`, as the campaign fits the pooled runs; (None, note)
    when the runs table is absent or no member's fit is determined."""
    import io  # noqa: PLC0415

    import pandas as pd  # noqa: PLC0415

    from pipeline.stats.ensemble import fragility_fit, logistic_surface  # noqa: PLC0415
    if not runs_path.is_file():
        return None, f"no {runs_path.name} beside the file: the members' spread not available"
    try:
        table = pd.read_csv(io.StringIO(read_text(runs_path, DATA_FILE_BYTES)))
        sub = table[table["column"] == column]
        groups = sorted(sub.groupby("member"), key=lambda item: item[0])
    except (OSError, Unreadable, ValueError, KeyError, pd.errors.ParserError) as exc:
        raise InputError(f"{runs_path}: not a fragility_runs.csv of campaign fragility "
                         f"({exc})") from None
    if len(groups) > MAX_MEMBERS:
        raise InputError(f"{runs_path}: {len(groups)} members (at most {MAX_MEMBERS})")
    block = data.get("block2d") or {}
    fits, skipped = [], []
    for member, rows in groups:
        try:
            y = rows["toppled"].astype(str).str.lower().isin(("true", "1")).to_numpy()
            pga = rows["pga_m_s2"].astype(float).to_numpy()
            ratio = rows["pgv_pga_s"].astype(float).to_numpy()
        except (KeyError, ValueError, TypeError):
            raise InputError(f"{runs_path}: member {show(member)}: no readable toppled, "
                             "pga_m_s2 and pgv_pga_s") from None
        if not (np.isfinite(pga).all() and np.isfinite(ratio).all() and (pga > 0).all()
                and (ratio > 0).all()):
            raise InputError(f"{runs_path}: member {show(member)}: pga_m_s2 and pgv_pga_s "
                             "must be positive finite numbers")
        label = f"member {show(member)}"
        if form == "pga":
            fit = fragility_fit(pga, y)
            if fit["median"] is None:
                skipped.append(f"{show(member)} ({fit['note']})")
                continue
            fits.append(Lognormal(float(fit["median"]), float(fit["beta"]), label=label))
        else:
            fit = logistic_surface(pga, ratio, y, alpha=block.get("alpha_rad"),
                                   p=block.get("p_per_s"))
            b = fit["coefficients"]
            if b is None or not b["b1"] > 0:
                skipped.append(f"{show(member)} ({fit.get('note') or 'does not grow with PGA'})")
                continue
            fits.append(Logistic((b["b0"], b["b1"], b["b2"]), label=label))
    note = None if not skipped else (f"{len(skipped)} of {len(groups)} member(s) not fitted "
                                     f"alone, left out of the members' spread: "
                                     f"{'; '.join(skipped)}")
    return (tuple(fits) or None), note


def _logistic(surface, where, label):
    """The :class:`Logistic` of a fragility.json's ``logistic`` entry."""
    coefficients = surface.get("coefficients")
    if coefficients is None:
        raise InputError(f"{where}: logistic surface not fitted "
                         f"({surface.get('note') or 'no coefficients'})")
    b = tuple(number(coefficients.get(k), f"{where}: logistic {k}") for k in ("b0", "b1", "b2"))
    if not b[1] > 0:
        raise InputError(f"{where}: the logistic surface does not grow with PGA "
                         f"(b1 = {b[1]:g})")
    cov = surface.get("cov")
    if cov is not None and not all(isinstance(v, (int, float)) for row in cov for v in row):
        cov = None                       # a singular information matrix: written as nulls
    se = surface.get("se") or {}
    note = surface.get("note")
    if cov is None:
        note = "; ".join(filter(None, [note, "no covariance in the file: coefficients drawn "
                                       "independently (their correlation ignored)"]))
    return Logistic(b, tuple(map(tuple, cov)) if cov is not None else None,
                    tuple(se.get(k) for k in ("b0", "b1", "b2")) if se else None,
                    label=label, note=note)


def _pair(value, what):
    """A 95 % interval (lo, hi) from a file: positive numbers, lo <= hi; None stays None."""
    if value is None:
        return None
    if not (isinstance(value, list) and len(value) == 2):
        raise InputError(f"{what} must be a pair [lo, hi], got {show(value)}")
    lo, hi = (number(v, what, 0, None, "", True) for v in value)
    if lo > hi:
        raise InputError(f"{what}: {lo:g} above {hi:g}")
    return lo, hi


# ---------------------------------------------------------------- PGV/PGA
@dataclass(frozen=True)
class RatioLognormal:
    """PGV/PGA lognormal with ``median_s`` (s) and ``sigma_ln``, the same at every PGA."""
    median_s: float
    sigma_ln: float

    def ln_mean_sd(self, pga_m_s2):
        pga = np.asarray(pga_m_s2, float)
        return np.full(pga.shape, math.log(self.median_s)), np.full(pga.shape, self.sigma_ln)

    def describe(self):
        return {"source": "user", "distribution": "lognormal, the same at every PGA",
                "median_s": self.median_s, "sigma_ln": self.sigma_ln}


@dataclass(frozen=True)
class RatioFromGmm:
    """PGV/PGA at a PGA level from a ground-motion model at a magnitude and distance:
    ln PGV given ln PGA = a is normal with mean mu_v + rho (s_v / s_a)(a - mu_a) and
    sd s_v sqrt(1 - rho^2); PGV/PGA = PGV / a."""
    magnitude: float
    distance_km: float
    vs30_m_s: float = 760.0
    mechanism: str = "SS"
    correlation: float = PGA_PGV_CORRELATION
    medians: dict = field(default=None, compare=False)

    def __post_init__(self):
        import pygmm  # noqa: PLC0415  (slow import, only needed here)
        scenario = pygmm.Scenario(mag=self.magnitude, dist_jb=self.distance_km,
                                  v_s30=self.vs30_m_s, mechanism=self.mechanism)
        model = pygmm.BooreStewartSeyhanAtkinson2014(scenario)
        object.__setattr__(self, "medians", {
            "pga_m_s2": float(model.pga) * STANDARD_GRAVITY, "ln_std_pga": float(model.ln_std_pga),
            "pgv_m_s": float(model.pgv) / 100.0, "ln_std_pgv": float(model.ln_std_pgv)})

    def ln_mean_sd(self, pga_m_s2):
        m, rho = self.medians, self.correlation
        ln_a = np.log(np.asarray(pga_m_s2, float))
        eps_a = (ln_a - math.log(m["pga_m_s2"])) / m["ln_std_pga"]
        mean_v = math.log(m["pgv_m_s"]) + rho * m["ln_std_pgv"] * eps_a
        sd = m["ln_std_pgv"] * math.sqrt(1.0 - rho ** 2)
        return mean_v - ln_a, np.full(ln_a.shape, sd)

    def describe(self):
        return {"source": "ground-motion model",
                "model": "Boore, Stewart, Seyhan & Atkinson (2014), pygmm "
                         "BooreStewartSeyhanAtkinson2014 (RotD50)",
                "magnitude": self.magnitude, "distance_jb_km": self.distance_km,
                "vs30_m_s": self.vs30_m_s, "mechanism": self.mechanism,
                "pga_pgv_correlation": self.correlation,
                "median_pga_m_s2": self.medians["pga_m_s2"],
                "median_pgv_m_s": self.medians["pgv_m_s"],
                "ln_std_pga": self.medians["ln_std_pga"], "ln_std_pgv": self.medians["ln_std_pgv"],
                "pygmm": importlib.metadata.version("pygmm"),
                "distribution": "lognormal given PGA: ln PGV | ln PGA by their correlation"}


def overturn_probability(fragilities, ratio_model, pga_m_s2, combine="each"):
    """P(overturn) at PGA levels (m/s^2) averaged over PGV/PGA (Gauss-Hermite in ln PGV/PGA).

    ``combine``: "each" (array n_specimens x n_levels), "any_common" (P that any overturns
    in one event, the specimens independent given the motion they share: 1 - E[prod(1 -
    P_i)]) or "any_correlated" (the specimens' capacities fully correlated: E[max P_i]).
    """
    pga = np.asarray(pga_m_s2, float)
    if any(f.uses_ratio for f in fragilities):
        if ratio_model is None:
            raise InputError("the fragility depends on PGV/PGA: give its distribution "
                             "(--pgv-pga-median and --pgv-pga-sigma, or --magnitude and "
                             "--distance-km)")
        nodes, weights = np.polynomial.hermite_e.hermegauss(RATIO_NODES)
        weights = weights / weights.sum()
        mean, sd = ratio_model.ln_mean_sd(pga)
        ratio = np.exp(mean[:, None] + sd[:, None] * nodes[None, :])
        each = np.array([f.probability(pga[:, None], ratio) for f in fragilities])
    else:
        weights = np.ones(1)
        each = np.array([f.probability(pga)[:, None] for f in fragilities])
    if combine == "each":
        return each @ weights
    if combine == "any_common":
        return 1.0 - np.prod(1.0 - each, axis=0) @ weights
    if combine == "any_correlated":
        return each.max(axis=0) @ weights
    raise ValueError(f"unknown combine {combine!r}")


# ---------------------------------------------------------------- the pulse grid
@dataclass(frozen=True)
class PulseGrid:
    """P(overturn | PGA, PGV/PGA) from the cells of ``campaign fragility --pulses``:
    ``pga_m_s2`` (m/s^2) x ``pgv_pga_s`` (s) axes, ``n`` runs and ``overturned`` per cell
    (arrays n_pga x n_ratio), ``p_per_set`` (n_sets x n_pga x n_ratio, NaN where a set has
    no run) and ``outside``: the fitted logistic surface (or None).

    Inside the grid P is interpolated bilinearly in (ln PGA, ln PGV/PGA) between the
    cells' fractions (:mod:`pipeline.hazard.pulse_cells`, the one interpolation of a
    pulse grid): no functional form is imposed, and the cells are where the runs are.
    Above the grid's PGA and beside its PGV/PGA P follows the logistic surface fitted to
    the same runs from the nearest edge cell: its log-odds shifted to meet that cell's P
    (continuous at the edge; the surface's trend carries it outwards); without a surface,
    the nearest edge cell's P.  Below the grid's first PGA a_1, ``below`` (:data:`BELOW_GRID`):
    the edge P at a_1 times w(a), continuous at a_1, with ``uplift_m_s2`` = g tan(alpha)
    (a rigid body does not leave its rest below it, Housner 1963):

    - "ramp": w = ln(a / a_u) / ln(a_1 / a_u) between a_u and a_1, 0 below a_u (P rises
      linearly in ln PGA from 0 at the uplift acceleration to the edge P);
    - "zero": w = 0 (nothing below the grid: a lower bound on the rate);
    - "edge": w = 1 above a_u, 0 below (the edge P held: an upper bound, P growing with
      PGA);
    - "logistic": the surface, as above and beside the grid (not continuous at a_1).

    Without an uplift acceleration "ramp" and "edge" take a_u = 0 ("ramp" then is
    "zero", and "edge" holds the edge P down to any PGA), said in ``describe``."""
    pga_m_s2: tuple
    pgv_pga_s: tuple
    n: np.ndarray = field(compare=False)
    overturned: np.ndarray = field(compare=False)
    p_per_set: np.ndarray = field(compare=False)
    outside: Logistic | None = None
    label: str = "pulse grid"
    note: str | None = None
    uplift_m_s2: float | None = None
    below: str = "ramp"
    uses_ratio = True

    @property
    def p(self):
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.n > 0, self.overturned / np.maximum(self.n, 1), np.nan)

    def probability(self, pga_m_s2, pgv_pga_s):
        return self._interpolate(self.p, pga_m_s2, pgv_pga_s)

    def _interpolate(self, cells, pga_m_s2, pgv_pga_s):
        pga, ratio = np.broadcast_arrays(np.asarray(pga_m_s2, float),
                                         np.asarray(pgv_pga_s, float))
        low = pga < self.pga_m_s2[0]
        if self.below == "logistic" or not low.any():
            return self._surface(cells, pga, ratio)
        p = np.zeros(pga.shape)
        if not low.all():
            p[~low] = self._surface(cells, pga[~low], ratio[~low])
        weight = self.below_weight(pga[low])
        ramp = weight > 0                # only where P is not 0 is the edge's P needed
        if ramp.any():
            below = np.zeros(weight.shape)
            below[ramp] = weight[ramp] * self._surface(
                cells, np.full(int(ramp.sum()), self.pga_m_s2[0]), ratio[low][ramp])
            p[low] = below
        return p

    def below_weight(self, pga_m_s2):
        """w(a) of the class docstring below the grid's first PGA (1 at a_1)."""
        pga = np.asarray(pga_m_s2, float)
        a_1, a_u = self.pga_m_s2[0], self.uplift_m_s2
        if self.below == "zero" or (self.below == "ramp" and (a_u is None or a_u >= a_1)):
            return np.zeros(pga.shape)
        if self.below == "edge":
            return (pga > (a_u or 0.0)).astype(float)
        return np.clip(np.log(pga / a_u) / math.log(a_1 / a_u), 0.0, 1.0)

    def variants(self):
        """The grid with P = 0 below it ("zero", a lower bound on the rate) and with the
        edge P held down to the uplift acceleration ("edge", an upper bound)."""
        return {name: replace(self, below=name) for name in ("zero", "edge")}

    def grid_range(self):
        """(first, last) PGA of the grid, m/s^2."""
        return self.pga_m_s2[0], self.pga_m_s2[-1]

    def _surface(self, cells, pga, ratio):
        """Inside the grid the cells' one interpolation (:mod:`pipeline.hazard.pulse_cells`:
        bilinear in ln PGA, ln PGV/PGA); outside, the logistic surface's trend carried from
        the nearest edge cell (its log-odds shifted to meet that cell's P, so P is
        continuous at the edge and a cell of P 0 or 1 stays so; the raw surface, with its
        steps, for ``below`` "logistic"), or without a surface the edge cell's P."""
        pga, ratio = np.broadcast_arrays(np.asarray(pga, float), np.asarray(ratio, float))
        held, beyond = interpolate(self.pga_m_s2, self.pgv_pga_s, _fill_empty(cells),
                                   pga, ratio)               # the edge cell's P outside
        p = np.array(held, float)
        if self.outside is not None and beyond.any():      # the surface only where needed
            a, r = pga[beyond], ratio[beyond]
            if self.below == "logistic":
                p[beyond] = self.outside.probability(a, r)
            else:
                edge_a = np.clip(a, self.pga_m_s2[0], self.pga_m_s2[-1])
                edge_r = np.clip(r, self.pgv_pga_s[0], self.pgv_pga_s[-1])
                p[beyond] = _carried(held[beyond], self.outside.probability(a, r),
                                     self.outside.probability(edge_a, edge_r))
        return np.clip(p, 0.0, 1.0)

    def draws(self, n, rng):
        """``n`` grids with every cell's count redrawn Binomial(n_cell, P_cell): the Monte
        Carlo error of the cells (parametric bootstrap); the outside surface kept."""
        return [replace(self, overturned=rng.binomial(self.n, np.nan_to_num(self.p)))
                for _ in range(n)]

    def members(self):
        """One grid per parameter set (its own P in every cell; a cell the set did not run
        takes the pooled P): the spread of the unknown contact parameters."""
        out = []
        for p_set in self.p_per_set:
            p = np.where(np.isnan(p_set), self.p, p_set)
            out.append(replace(self, n=np.ones_like(self.n), overturned=p))
        return out

    def describe(self):
        return {"form": "P(overturn | PGA, PGV/PGA) from the pulse grid's cells",
                "label": self.label,
                "inside": "bilinear in (ln PGA, ln PGV/PGA) between the cells' fractions",
                "outside": "the logistic surface fitted to the same runs"
                if self.outside is not None else "the nearest edge cell's P",
                "below_grid": self.describe_below(),
                "above_grid": self.describe_above(),
                "pga_range_g": [self.pga_m_s2[0] / STANDARD_GRAVITY,
                                self.pga_m_s2[-1] / STANDARD_GRAVITY],
                "pgv_pga_range_s": [self.pgv_pga_s[0], self.pgv_pga_s[-1]],
                "cells": int(self.n.size), "runs": int(self.n.sum()),
                "parameter_sets": int(len(self.p_per_set)),
                "outside_surface": None if self.outside is None else self.outside.describe(),
                "note": self.note}


    def describe_above(self):
        """What P is above the grid's last PGA: how it is extended, the top row's P per
        PGV/PGA and (``summary``) one line of it for the warnings."""
        top = _fill_empty(self.p)[-1]
        a_n = self.pga_m_s2[-1] / STANDARD_GRAVITY
        span = f"{top.min():.3g}" if top.min() == top.max() else \
            f"{top.min():.3g}-{top.max():.3g} over its PGV/PGA"
        if self.outside is None:
            definition = "P = the top edge cell's P (at the nearest PGV/PGA), held at every PGA"
            summary = f"P held at the top cells' P ({span}) at every PGA above"
        elif self.below == "logistic":
            definition = ("P = the logistic surface fitted to the same runs (not continuous "
                          "at the grid's last PGA)")
            summary = "P from the logistic surface fitted to the runs"
        else:
            definition = ("logit P(a, r) = logit P(a_N, r) + logit S(a, r) - logit S(a_N, r): "
                          "the logistic surface S fitted to the same runs carries the top "
                          "edge cell's P upwards (a top cell of P 0 or 1 keeps it at every "
                          "PGA above)")
            summary = f"P carried up from the top cells' P ({span}) by the logistic surface"
        stuck = [r for r, p in zip(self.pgv_pga_s, top) if p == 0]
        note = None
        if stuck and self.below != "logistic":
            note = (f"no run overturned at the grid's last PGA ({a_n:.3g} g) for PGV/PGA "
                    f"{', '.join(f'{r:g}' for r in stuck)} s: P stays 0 at every PGA above it")
            summary += f"; P = 0 at every PGA above for PGV/PGA {', '.join(f'{r:g}' for r in stuck)} s"
        return {"definition": definition, "last_pga_g": a_n,
                "p_at_last_pga": {"pgv_pga_s": list(self.pgv_pga_s),
                                  "P": [float(v) for v in top]},
                "summary": summary, "note": note}

    def describe_below(self):
        """What P is below the grid's first PGA: the choice and its definition."""
        a_u = self.uplift_m_s2
        applied = self.below
        if self.below == "ramp" and (a_u is None or a_u >= self.pga_m_s2[0]):
            applied = "zero"
        definitions = {
            "ramp": "P = P(a_1) ln(a / a_u) / ln(a_1 / a_u) between the uplift acceleration "
                    "a_u = g tan(alpha) and the grid's first PGA a_1, 0 below a_u (a rigid "
                    "body does not leave its rest below a_u)",
            "zero": "P = 0 below the grid's first PGA (a lower bound on the rate)",
            "edge": "P = P(a_1), the edge's P, held down to the uplift acceleration, 0 below "
                    "(an upper bound on the rate, P growing with PGA)",
            "logistic": "the logistic surface fitted to the same runs (not continuous at "
                        "a_1)"}
        note = None
        if applied != self.below:
            note = ("no uplift acceleration in the file: P = 0 below the grid" if a_u is None
                    else "the uplift acceleration is not below the grid's first PGA: P = 0 "
                         "below the grid")
        elif self.below == "edge" and a_u is None:
            note = "no uplift acceleration in the file: the edge's P held down to any PGA"
        return {"choice": self.below, "applied": applied, "definition": definitions[applied],
                "first_pga_g": self.pga_m_s2[0] / STANDARD_GRAVITY,
                "uplift_pga_g": None if a_u is None else a_u / STANDARD_GRAVITY,
                "uplift_source": None if a_u is None else
                "the 2D block in the file: a_u = g tan(alpha), alpha the smallest critical "
                "angle of its runs (block2d uplift_g_smallest) or, in a file without it, "
                "their median",
                "note": note}


def _carried(p_edge, surface, surface_at_edge):
    """P outside a grid: logit P = logit p_edge + logit surface - logit surface_at_edge."""
    from scipy.special import expit, logit  # noqa: PLC0415
    tiny = 1e-12
    shift = (logit(np.clip(surface, tiny, 1 - tiny))
             - logit(np.clip(surface_at_edge, tiny, 1 - tiny)))
    with np.errstate(divide="ignore"):
        return expit(logit(np.clip(p_edge, 0.0, 1.0)) + shift)


def _fill_empty(cells):
    """A grid's NaN cells (no run) filled from the nearest cell with runs (along PGA)."""
    cells = np.array(cells, float)
    if not np.isnan(cells).any():
        return cells
    for j in range(cells.shape[1]):
        column = cells[:, j]
        good = ~np.isnan(column)
        if good.any():
            idx = np.arange(len(column))
            cells[:, j] = np.interp(idx, idx[good], column[good])
    return np.where(np.isnan(cells), np.nanmean(cells), cells)


def load_pulse_grid(path, data, model=None, form="grid", below="ramp"):
    """One model of a pulse-grid ``fragility.json`` (``models``: monolithic, block2d), its
    ``data`` checked by :func:`pipeline.hazard.fragility_file.check_fragility`: ``form``
    "grid" (:class:`PulseGrid`, ``below`` what P is below it; a grid of one row or column
    interpolated along the other axis) or "pga-pgv" (its logistic surface)."""
    if below not in BELOW_GRID:
        raise InputError(f"--below-grid must be one of {', '.join(BELOW_GRID)}, got {below!r}")
    section = data["pulse_grid"]
    models = section["models"]
    if model is None:
        model = "monolithic" if "monolithic" in models else next(iter(models))
    if model not in models:
        raise InputError(f"{path}: pulse_grid has no model {model!r} (has {', '.join(models)})")
    entry = models[model]
    where = f"{path}: pulse_grid model {model}"
    label = f"{data.get('specimen') or 'specimen'} {model} pulse grid from {path.name}"
    logistic = None
    surface = entry.get("logistic") or {}
    if surface.get("coefficients") is not None:
        logistic = _logistic(surface, where, label)
    if form == "pga-pgv":
        if logistic is None:
            raise InputError(f"{where}: logistic surface not fitted "
                             f"({surface.get('note') or 'no coefficients'})")
        return logistic
    if form != "grid":
        raise InputError(f"--fragility-form for a pulse grid must be grid or pga-pgv, got "
                         f"{form!r}")
    pga_g = [float(v) for v in section["pga_g"]]        # checked: increasing, positive
    ratios = [float(v) for v in section["pgv_pga_s"]]
    n_sets = section["members"]
    n = np.zeros((len(pga_g), len(ratios)), int)
    overturned = np.zeros_like(n)
    per_set = np.full((n_sets, len(pga_g), len(ratios)), np.nan)
    index_a = {round(v, 9): i for i, v in enumerate(pga_g)}
    index_r = {round(v, 9): j for j, v in enumerate(ratios)}
    for cell in entry["cells"]:                        # checked: on the grid, once each
        i, j = index_a[round(cell["pga_g"], 9)], index_r[round(cell["pgv_pga_s"], 9)]
        n[i, j], overturned[i, j] = cell["n"], cell["overturned"]
        for s, p in zip(cell.get("sets") or [], cell.get("P_per_set") or []):
            if p is not None:
                per_set[s, i, j] = float(p)
    empty = int((n == 0).sum())
    if empty == n.size:
        raise InputError(f"{where}: no cell with runs (every n is 0)")
    note = None if not empty else (f"{empty} of {n.size} cells without runs: filled from the "
                                   "nearest cell along PGA")
    uplift = _uplift(section, where)
    return PulseGrid(tuple(v * STANDARD_GRAVITY for v in pga_g), tuple(ratios), n,
                     overturned, per_set, logistic, label, note, uplift, below)


def _uplift(section, where):
    """g tan(alpha) (m/s^2) of a pulse grid's 2D block (``block2d``: the smallest over its
    runs, uplift_g_smallest, where written; else uplift_g or alpha_rad, the runs' median),
    or None when the file has none."""
    block = section.get("block2d") or {}
    if block.get("uplift_g_smallest") is not None:
        return number(block["uplift_g_smallest"], f"{where}: block2d uplift_g_smallest", 0,
                      None, "g", True) * STANDARD_GRAVITY
    if block.get("uplift_g") is not None:
        return number(block["uplift_g"], f"{where}: block2d uplift_g", 0, None, "g",
                      True) * STANDARD_GRAVITY
    if block.get("alpha_rad") is not None:
        alpha = number(block["alpha_rad"], f"{where}: block2d alpha_rad", 0, math.pi / 2,
                       "rad", True)
        return STANDARD_GRAVITY * math.tan(alpha)
    return None
