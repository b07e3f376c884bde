"""Likelihood of observed columns for candidate sources, from a forward table.

For one candidate (slice = mechanism, depth, magnitude; strike phi; epicentre E) and one
site S: r = |S - E| and alpha = azimuth from E to S; the node coordinates are r and
theta = alpha - phi (azimuth from the strike).  Per node and column type the table gives

- P(toppled) = (k + 1/2) / (n + 1) for k falls among n members (the posterior mean under
  Jeffreys' prior: never 0 or 1, so one surprising column cannot zero a candidate);
- the circular density of downfall azimuths *relative to the direction from epicentre to
  site* (a downfall azimuth psi, strike frame, at node azimuth theta_n becomes
  psi - theta_n): a von Mises kernel mixture over the members' falls, the kernel width
  ``kernel_deg`` and the observation's ``uncertainty_deg`` added in quadrature (von Mises
  concentration with the wrapped normal's mean resultant length exp(-sigma^2/2)), floored
  by mixing a fraction ``floor`` of the uniform density (1 / 2 pi per radian).

A fallen column observed at geographic azimuth psi_obs contributes
f(psi_obs - alpha) = sum_nodes w P_n d_n(psi_obs - alpha), a standing one
sum_nodes w (1 - P_n): the sub-density of "fell toward psi" and the probability of
standing are interpolated as mixtures of the four surrounding nodes, bilinearly in
log distance (clamped at the first ring) and in node azimuth (periodic).  The inversion's
candidates never lie beyond the last ring of a site
(:func:`pipeline.inversion.posterior.invert`); only its shell of the sources beyond
(:mod:`pipeline.inversion.beyond`) reads there: the last ring's direction density, its
P carried on by the decay of log-odds P with log distance between the last two rings
(never rising: a node whose P rises between them keeps its last P).  Interpolating in
the site frame moves a fall direction that is fixed relative to the source-to-site
direction smoothly between nodes.

Between spokes (node azimuths ``h`` deg apart) the table cannot tell whether the falls
keep their direction relative to the source-to-site direction (the site frame, in which
it is interpolated) or relative to the fault (the strike frame): read at an azimuth
delta from a node, the two differ by delta.  So a node's direction density read delta
away is spread uniformly over the rotations between its site-frame and its strike-frame
reading (a box of width |delta|; nothing at the node, 30 deg for each neighbour halfway
between 60-deg spokes).  The spread densities are tabulated on virtual azimuths every
``h / refine`` deg (at most :data:`VIRTUAL_STEP_DEG`), between which the interpolation
is linear.

Between magnitude slices (same mechanism and depth) the candidates' magnitudes run every
``mw_step`` (0.1) from the table's smallest to its largest: a candidate at weight w between
slices m0 and m1 takes P and P d (and 1 - P) as (1 - w) x slice m0's + w x slice m1's,
per column before the product (a mixture: the columns of a magnitude between slices fall
like those of either slice in proportion).  :attr:`ForwardModel.sources` lists these
candidates, :attr:`ForwardModel.mix` their weights over the table's slices.  Magnitudes
beyond the table's range are not candidates: the table cannot answer for them.

Log-likelihood = sum over columns (``likelihood="independent"``).
Densities are per radian.

``likelihood="predictive"`` accounts for the ensemble's own sampling error, which the
product above ignores: columns at one site share one ground motion, and the node's fall
distribution is known only through its n members.  The columns of one type at one site
are then exchangeable draws from an unknown distribution centred on the ensemble's, with
the weight of A columns (a Polya urn / Dirichlet-process predictive): the j-th column,
after f earlier falls and s earlier standing columns of its type at the site, contributes

    fallen:   (A f(psi) + sum_i K(psi - psi_i)) / (A + j),   standing: (A q + s) / (A + j)

with 1 / A = 1 / (n + 1) + 1 / m, f(psi) = P d(psi) and q = 1 - P as above, psi_i the
earlier falls and K a von Mises kernel of width sqrt(kernel^2 + sigma^2 + sigma_i^2),
floored like d.  The first
column of a type contributes exactly what the independent product gives; later ones
weigh less the more the site's own columns already say.  A sums two uncertainties of the
site's fall distribution about the table's: the table's n members (1 / (n + 1)) and the
site's own departure from its node (1 / m, ``site_columns``: the site's motion is not the
node's, the candidate's strike and cell are not the source's, the site's columns are a
few draws, not the population).  m was chosen on the member study's calibration draws
(:data:`SITE_COLUMNS`); m -> infinity is the urn of the table's sampling alone, m -> 0
counts a site's columns as one.  With A >> j the urn and the product agree.  The
predictive likelihood is the default (:data:`DEFAULT_LIKELIHOOD`): in the member study its
95 % regions are calibrated within the reach, where the product's are too narrow.
"""
import math

import numpy as np
from scipy import special

from pipeline.files import InputError
from pipeline.inversion.observations import ColumnObservation
from pipeline.stats.circular import concentration, von_mises_pdf

LIKELIHOODS = ("independent", "predictive")
# the default: calibrated in the member study (95 % regions hold the truth in about 0.95 of
# the trials within the reach, where the independent product is too sure)
DEFAULT_LIKELIHOOD = "predictive"
DEFAULT_KERNEL_DEG = 20.0
DEFAULT_FLOOR = 0.05
PSI_STEP_DEG = 0.5
OBS_CHUNK = 8                  # observations per vectorised block (memory)
VIRTUAL_STEP_DEG = 7.5         # the largest spacing of the virtual azimuths between spokes
MW_STEP = 0.1                  # the candidates' magnitude step between the table's slices
SITE_COLUMNS = 3.0             # m: a site's columns as m draws' worth of the node's (predictive;
#                                chosen on the member study's calibration draws, docs/inversion.md)


def p_toppled(k, n):
    """(k + 1/2) / (n + 1)."""
    return (np.asarray(k, float) + 0.5) / (np.asarray(n, float) + 1.0)


def check_model_options(kernel_deg, floor, likelihood):
    """InputError unless the likelihood's options are in range (called before any work)."""
    if likelihood not in LIKELIHOODS:
        raise InputError(f"--likelihood must be one of {', '.join(LIKELIHOODS)}, got "
                         f"{likelihood!r}")
    if not (math.isfinite(kernel_deg) and 0 < kernel_deg <= 90):
        raise InputError(f"--kernel-deg must lie in (0, 90], got {kernel_deg:g}")
    if not (math.isfinite(floor) and 0 < floor < 1):
        raise InputError(f"--floor must lie in (0, 1), got {floor:g}")


class ForwardModel:
    """Per-node toppling probabilities and direction densities of a forward table."""

    def __init__(self, table, kernel_deg=DEFAULT_KERNEL_DEG, floor=DEFAULT_FLOOR,
                 likelihood=DEFAULT_LIKELIHOOD, mw_step=MW_STEP, site_columns=SITE_COLUMNS):
        check_model_options(kernel_deg, floor, likelihood)
        if not site_columns > 0:
            raise InputError(f"site columns must be positive, got {site_columns:g}")
        self.site_columns = float(site_columns)
        if not (math.isfinite(mw_step) and 0 < mw_step <= 1):
            raise InputError(f"magnitude step must lie in (0, 1], got {mw_step:g}")
        self.likelihood, self.mw_step = likelihood, float(mw_step)
        self.table, self.kernel_deg, self.floor = table, float(kernel_deg), float(floor)
        self.k = table.toppled.sum(axis=-1)
        self.n = table.valid.sum(axis=-1)
        self.p_nodes = p_toppled(self.k, self.n)                 # (ns, nr, na, nc)
        theta = table.azimuths_deg[None, None, :, None, None]
        self.relative = np.where(table.toppled, np.mod(table.azimuth_deg - theta, 360.0),
                                 np.nan)                         # site frame, deg
        self.psi = np.arange(0.0, 360.0, PSI_STEP_DEG)
        self.spacing_deg = 360.0 / len(table.azimuths_deg)
        self.refine = max(1, math.ceil(self.spacing_deg / VIRTUAL_STEP_DEG - 1e-9))
        j, w = self._virtual_nodes()
        self.p = ((1 - w)[:, None] * self.p_nodes[:, :, j, :]
                  + w[:, None] * self.p_nodes[:, :, (j + 1) % len(table.azimuths_deg), :])
        self.sources, self.mix = magnitude_sources(table.slices, self.mw_step)
        self._fallen_cache = {}

    def _virtual_nodes(self):
        """(node index j, weight w of node j + 1) of each virtual azimuth."""
        v = np.arange(len(self.table.azimuths_deg) * self.refine)
        return v // self.refine, (v % self.refine) / self.refine

    # ------------------------------------------------------------------ node tables
    def direction_density(self, sigma_deg):
        """d_n(psi) per radian on ``self.psi`` (site frame), floored: (ns, nr, na, nc, npsi)."""
        kappa = concentration(math.hypot(self.kernel_deg, sigma_deg))
        fell = np.isfinite(self.relative)
        count = fell.sum(axis=-1)
        diff = np.radians(self.psi[None, :] - np.where(fell, self.relative, 0.0)[..., None])
        kernel = von_mises_pdf(diff, kappa) * fell[..., None]
        with np.errstate(invalid="ignore", divide="ignore"):
            mixture = kernel.sum(axis=-2) / count[..., None]
        mixture = np.where(count[..., None] > 0, mixture, 1.0 / (2 * math.pi))
        return self._floored(mixture)

    def _floored(self, density):
        """A direction density (per radian) mixed with the fraction ``floor`` of uniform."""
        return (1.0 - self.floor) * density + self.floor / (2 * math.pi)

    def fallen_table(self, sigma_deg):
        """P d(psi) on the virtual azimuths: (ns, nr, n_virtual, nc, npsi), cached per
        uncertainty; between spokes each neighbour's density spread by :func:`spread`."""
        key = round(float(sigma_deg), 9)
        if key not in self._fallen_cache:
            fallen = self.p_nodes[..., None] * self.direction_density(sigma_deg)
            na = len(self.table.azimuths_deg)
            levels = []
            for level in range(self.refine):
                w = level / self.refine
                here = spread(fallen, w * self.spacing_deg)
                there = spread(np.roll(fallen, -1, axis=2), -(1 - w) * self.spacing_deg)
                levels.append(here if level == 0 else (1 - w) * here + w * there)
            stacked = np.stack(levels, axis=3)            # (ns, nr, na, refine, nc, npsi)
            self._fallen_cache[key] = stacked.reshape(
                fallen.shape[:2] + (na * self.refine,) + fallen.shape[3:])
        return self._fallen_cache[key]

    def column_index(self, column):
        try:
            return self.table.columns.index(column)
        except ValueError:
            raise InputError(f"column {column!r}: the forward table models "
                             f"{', '.join(self.table.columns)} only (`invert` adds the table "
                             "of each column file its observations name)") from None

    # ------------------------------------------------------------------ weights
    def distance_weights(self, r_km):
        """(i0, i1, w1, beyond): rings around r, weight of i1, linear in log r, clamped;
        ``beyond`` ln(r / last ring) where r lies beyond the last ring (else 0)."""
        rings = np.log(self.table.distances_km)
        x = np.log(np.maximum(np.asarray(r_km, float), 1e-6))
        beyond = np.maximum(x - rings[-1], 0.0)
        if len(rings) == 1:
            zero = np.zeros(x.shape, int)
            return zero, zero, np.zeros(x.shape), beyond
        i1 = np.clip(np.searchsorted(rings, x), 1, len(rings) - 1)
        i0 = i1 - 1
        w1 = np.clip((x - rings[i0]) / (rings[i1] - rings[i0]), 0.0, 1.0)
        return i0, i1, w1, beyond

    def decay(self, c, beyond):
        """P beyond the last ring over the last ring's P, per slice, candidate and virtual
        azimuth (ns, ne, n_virtual), for column type c at ``beyond`` = ln(r / last ring)
        (ne,): log-odds P carried on along the slope between the last two rings, never
        rising (one ring: no slope, P held)."""
        last = special.logit(self.p[:, -1, :, c])                       # (ns, nv)
        rings = np.log(self.table.distances_km)
        slope = np.zeros(last.shape) if len(rings) == 1 else np.minimum(
            (last - special.logit(self.p[:, -2, :, c])) / (rings[-1] - rings[-2]), 0.0)
        far = special.expit(last[:, None, :] + slope[:, None, :] * beyond[None, :, None])
        return far / self.p[:, -1, :, c][:, None, :]

    def azimuth_weights(self, theta_deg):
        """(i0, i1, w1): virtual azimuths around theta (periodic), weight of i1."""
        na = self.p.shape[2]
        x = np.mod(np.asarray(theta_deg, float), 360.0) / (360.0 / na)
        i0 = np.floor(x).astype(int)
        w1 = x - i0
        return i0 % na, (i0 + 1) % na, w1

    def _psi_weights(self, psi_deg):
        x = np.mod(psi_deg, 360.0) / PSI_STEP_DEG
        j0 = np.floor(x).astype(int)
        return j0 % len(self.psi), (j0 + 1) % len(self.psi), x - j0

    # ------------------------------------------------------------------ likelihood
    def _mixed(self, values):
        """Per-slice values (ns, ...) as the candidate sources' (n_sources, ...)."""
        if self.mix.shape[0] == self.mix.shape[1] and np.array_equal(
                self.mix, np.eye(len(self.mix))):
            return values
        return np.tensordot(self.mix, values, axes=(1, 0))

    def site_log_likelihood(self, site, east_km, north_km, strikes_deg):
        """Log-likelihood of one site's columns: (n_sources, n_strikes, n_epicentres)."""
        alpha, rings, ai0, ai1, aw = self._geometry(site, east_km, north_km, strikes_deg)
        ns, nphi, ne = len(self.sources), ai0.shape[0], alpha.size
        out = np.zeros((ns, nphi, ne))
        by_type = {}
        for obs in site.columns:
            by_type.setdefault(self.column_index(obs.column), []).append(obs)
        for c, group in by_type.items():
            standing = sum(not o.fallen for o in group)
            q = self._mixed(self._standing(c, rings, ai0, ai1, aw)) if standing else None
            fallen = [k for k, o in enumerate(group) if o.fallen]
            if self.likelihood == "independent":
                if standing:
                    out += standing * np.log(q)
                for start in range(0, len(fallen), OBS_CHUNK):
                    chunk = [group[k] for k in fallen[start:start + OBS_CHUNK]]
                    for value in self._fallen(c, chunk, alpha, rings, ai0, ai1, aw):
                        out += np.log(self._mixed(value))
                continue
            # predictive: a Polya urn per site and column type, in the file's order
            weight = self.urn_weight(c)
            values = {}
            for start in range(0, len(fallen), OBS_CHUNK):
                ks = fallen[start:start + OBS_CHUNK]
                values.update(zip(ks, map(self._mixed, self._fallen(
                    c, [group[k] for k in ks], alpha, rings, ai0, ai1, aw))))
            earlier, s_prev = [], 0
            for j, obs in enumerate(group):
                if not obs.fallen:
                    out += np.log((weight * q + s_prev) / (weight + j))
                    s_prev += 1
                    continue
                pair = sum(self._pair_kernel(obs, e) for e in earlier)
                out += np.log((weight * values[j] + pair) / (weight + j))
                earlier.append(obs)
        return out

    def _geometry(self, site, east_km, north_km, strikes_deg):
        """(azimuth epicentre -> site deg (ne,), ring weights, virtual azimuth weights
        (nphi, ne)) of ``site`` from each candidate epicentre and strike."""
        east, north = np.asarray(east_km, float), np.asarray(north_km, float)
        dx, dy = site.east_km - east, site.north_km - north
        alpha = np.mod(np.degrees(np.arctan2(dx, dy)), 360.0)
        theta = alpha[None, :] - np.asarray(strikes_deg, float)[:, None]
        return (alpha, self.distance_weights(np.hypot(dx, dy)))\
            + tuple(self.azimuth_weights(theta))

    def column_distribution(self, site, column, east_km, north_km, strikes_deg, psi_deg,
                            sigma_deg):
        """What the model expects of one column of type ``column`` at ``site``: (1 - P:
        (ns, nphi, ne), P d at the geographic downfall azimuths ``psi_deg`` (per radian,
        observed with ``sigma_deg``): (npsi, ns, nphi, ne)), per candidate source."""
        c = self.column_index(column)
        alpha, rings, ai0, ai1, aw = self._geometry(site, east_km, north_km, strikes_deg)
        q = self._mixed(self._standing(c, rings, ai0, ai1, aw))
        pseudo = [ColumnObservation(column, "fallen", float(p), float(sigma_deg))
                  for p in psi_deg]
        fallen = []
        for start in range(0, len(pseudo), 4 * OBS_CHUNK):
            fallen += [self._mixed(v) for v in self._fallen(
                c, pseudo[start:start + 4 * OBS_CHUNK], alpha, rings, ai0, ai1, aw)]
        return q, np.stack(fallen)

    def urn_weight(self, c):
        """A of the predictive likelihood for column type c: 1 / A = 1 / (n + 1) + 1 / m,
        the table's sampling (n members) and the site's own draw (``site_columns``)."""
        return 1.0 / (1.0 / (float(np.mean(self.n[..., c])) + 1.0) + 1.0 / self.site_columns)

    def _standing(self, c, rings, ai0, ai1, aw):
        """Interpolated 1 - P of column type c: (ns, nphi, ne)."""
        ri0, ri1, rw, beyond = rings
        q = 1.0 - self.p[..., c]                                          # (ns, nr, na)
        qe = (1 - rw)[None, :, None] * q[:, ri0, :] + rw[None, :, None] * q[:, ri1, :]
        if beyond.any():
            qe = 1.0 - self.decay(c, beyond) * (1.0 - qe)
        return np.stack([_pick(qe, ai0[f], ai1[f], aw[f]) for f in range(len(ai0))], axis=1)

    def _fallen(self, c, chunk, alpha, rings, ai0, ai1, aw):
        """Interpolated P d(psi_obs - alpha) of each fallen observation in ``chunk``: list of
        (ns, nphi, ne) arrays in the chunk's order."""
        ri0, ri1, rw, beyond = rings
        scale = self.decay(c, beyond)[:, None] if beyond.any() else 1.0   # (ns, 1, ne, na)
        result = [None] * len(chunk)
        for sigma in sorted({o.uncertainty_deg for o in chunk}):
            index = [k for k, o in enumerate(chunk) if o.uncertainty_deg == sigma]
            table = self.fallen_table(sigma)[..., c, :]                   # (ns, nr, na, npsi)
            psi_obs = np.array([chunk[k].downfall_azimuth_deg for k in index])
            j0, j1, pw = self._psi_weights(psi_obs[:, None] - alpha[None, :])
            g = 0.0
            for ring, wr in ((ri0, 1 - rw), (ri1, rw)):
                lo = table[:, ring[None, :], :, j0]                       # (no, ne, ns, na)
                hi = table[:, ring[None, :], :, j1]
                g = g + wr[None, :, None, None] * (
                    (1 - pw)[..., None, None] * lo + pw[..., None, None] * hi)
            g = g.transpose(2, 0, 1, 3) * scale                           # (ns, no, ne, na)
            val = np.stack([_pick(g, ai0[f], ai1[f], aw[f]) for f in range(len(ai0))],
                           axis=1)                                        # (ns, nphi, no, ne)
            for slot, k in enumerate(index):
                result[k] = val[:, :, slot, :]
        return result

    def _pair_kernel(self, a, b):
        """Floored von Mises density of column a's observed azimuth about column b's."""
        width = math.sqrt(self.kernel_deg ** 2 + a.uncertainty_deg ** 2
                          + b.uncertainty_deg ** 2)
        d = math.radians(a.downfall_azimuth_deg - b.downfall_azimuth_deg)
        return float(self._floored(von_mises_pdf(d, concentration(width))))

    def log_likelihood(self, observations, east_km, north_km, strikes_deg):
        """Sum over sites: (ns, n_strikes, n_epicentres)."""
        total = 0.0
        for site in observations.sites:
            total = total + self.site_log_likelihood(site, east_km, north_km, strikes_deg)
        return total


def spread(density, delta_deg):
    """``density`` (last axis: psi every PSI_STEP_DEG) read ``delta_deg`` away from its
    node: the mean of density(psi + t delta) over t in [0, 1] (trapezoid rule on the psi
    grid), the rotations between the site-frame reading (t = 0) and the strike-frame
    reading (t = 1)."""
    m = int(round(abs(delta_deg) / PSI_STEP_DEG))
    if m == 0:
        return density
    n = density.shape[-1]
    ext = np.concatenate([density, density[..., :m]], axis=-1)
    c = np.concatenate([np.zeros(density.shape[:-1] + (1,)), np.cumsum(ext, axis=-1)],
                       axis=-1)
    ends = density + np.roll(density, -m, axis=-1)
    forward = (c[..., m + 1:m + 1 + n] - c[..., :n] - ends / 2) / m   # psi .. psi + m steps
    return forward if delta_deg > 0 else np.roll(forward, m, axis=-1)


def magnitude_sources(slices, mw_step=MW_STEP):
    """(candidate sources: slice dicts with the magnitude every ``mw_step`` between the
    table's slices of one mechanism and depth, weights (n_sources, n_slices): each
    source's mixture of its two neighbouring slices, linear in magnitude)."""
    groups = {}
    for k, s in enumerate(slices):
        key = (s["mechanism"], s["dip_deg"], s["rake_deg"], s["depth_km"])
        groups.setdefault(key, []).append(k)
    sources, rows = [], []
    for members in groups.values():
        members = sorted(members, key=lambda k: slices[k]["mw"])
        for a, b in zip(members[:-1], members[1:]):
            m0, m1 = slices[a]["mw"], slices[b]["mw"]
            steps = max(1, int(round((m1 - m0) / mw_step)))
            for i in range(steps):
                w = i / steps
                sources.append({**slices[a], "mw": round(m0 + w * (m1 - m0), 4)})
                row = np.zeros(len(slices))
                row[a], row[b] = 1 - w, w
                rows.append(row)
        sources.append(dict(slices[members[-1]]))
        rows.append(np.eye(len(slices))[members[-1]])
    return sources, np.array(rows)


def _pick(values, i0, i1, w1):
    """Interpolate ``values[..., e, a]`` at node azimuth indices (i0, i1, weight w1) per e."""
    shape = (1,) * (values.ndim - 2) + (values.shape[-2], 1)
    lo = np.take_along_axis(values, i0.reshape(shape), axis=-1)[..., 0]
    hi = np.take_along_axis(values, i1.reshape(shape), axis=-1)[..., 0]
    return (1 - w1) * lo + w1 * hi
