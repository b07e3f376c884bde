"""How many fallen columns bound the earthquake's direction?  The member study.

The demo's truth tests (:mod:`pipeline.inversion.demo`) use half of a few members per node
for the likelihood, so they cannot tell whether the physics or the forward table keeps the
direction unknown.  Here the table's members are split once: the last
``observation_members`` are the "observed" columns, never used by a likelihood; the
likelihood takes the first L members, for every L of ``likelihood_members`` that fits.
A trial draws a table slice (mechanism, depth, magnitude) among those where some
observation member falls, a strike (uniform: between the candidates' strike steps), S
sites at nodes where the observation members fall, and K fallen columns per site (the
standing ones drawn on the way are observed too), as the demo does; each (likelihood, L,
S, K) is inverted ``trials`` times with the same draws (seeded by S, K and the trial, not
by L), so that a change with L is the likelihood's alone.

The observed columns are runs, so they stand where the table has nodes; sources as they
come lie off them.  A trial therefore also draws where its source lies for the likelihood
(``PLACEMENTS``, equally often): ``node`` (the likelihood's table holds the sites' nodes),
``between`` (the likelihood's table leaves out the inner rings (or, with two rings, every
other node azimuth) and the sites lie on those: between the rings it keeps),
``between_spokes`` (the likelihood's table leaves out every other node azimuth and the
sites lie on those: halfway between spokes twice as far apart as the table's),
``between_magnitudes`` (the source's magnitude lies between two slices of one mechanism
and depth, at a weight w drawn uniformly: each observed column is one of the upper
slice's with probability w, else the lower's, the mixture the likelihood assumes between
slices, so this tests the inversion's reading of it, not whether the physics is such a
mixture) and ``beyond`` (the likelihood's table leaves out the last ring and the first
site lies on it: the source lies beyond the inversion's reach, and the right answer is a
warning that it may lie farther, with no direction) and ``just_beyond`` (the same
likelihood's table, every site between its last ring and ``JUST_BEYOND_FACTOR`` times it,
or the pool's next ring if nearer: :func:`just_beyond_sites`; the sources just beyond the
reach, where a larger source outside and a smaller one at the reach's edge are hardest to
tell apart).

Per configuration: coverage of the 95 % back-azimuth arc (with its Wilson interval: a
coverage is calibrated when the interval holds 0.95), its median width, the share of arcs
within the paper's bound (:data:`pipeline.paper.BACK_AZIMUTH_BOUND_DEG`), the coverage of the distance's 95 % interval and of the epicentre's 95 %
credible area (and its median size), each also counting a warning that the source may lie
beyond the reach as an answer (``*_or_warned``), per placement too, and the magnitude's:
whether the true Mw lies in the smallest set of table magnitudes holding 95 % of the
posterior, and the posterior probability of the true Mw.  Per placement
(:func:`placement_summary`): the coverages of back azimuth, distance, epicentre and
magnitude and how often the reach warning is given; over the trials within the reach its
false alarms, beyond the reach its hits.  The shell beyond the reach in the posterior
(:mod:`pipeline.inversion.beyond`): each trial's P(beyond) (``p_beyond``), whether the
shell lies in the 95 % epicentre region (``beyond_in_95``) and how many of its sites lie
beyond the likelihood's last ring from the source (``sites_beyond``).
"""

import math
import os
from functools import partial
from multiprocessing import Pool

import numpy as np
import pandas as pd

from pipeline.inversion import truth_check
from pipeline.inversion.demo import FALLEN_PER_SITE, REACH_KEYS, SITE_COUNTS, out_of_reach_row
from pipeline.inversion.sites import OBS_UNCERTAINTY_DEG, draw_site_columns, site_frame, \
    site_position
from pipeline.inversion.likelihood import DEFAULT_FLOOR, DEFAULT_KERNEL_DEG, LIKELIHOODS, \
    ForwardModel
from pipeline.inversion.candidates import OutOfReach
from pipeline.inversion.posterior import invert
from pipeline.stats.circular import azimuth_deg
from pipeline.files import InputError, die_with_parent
from pipeline.inversion.options import STUDY_TRIALS   # declared with --trials

LIKELIHOOD_MEMBERS = (3, 6, 12, 24, 48)
OBSERVATION_MEMBERS = 16
STUDY_SEED = 2027
PLACEMENTS = ("node", "between", "between_spokes", "between_magnitudes", "beyond",
              "just_beyond")
BEYOND_PLACEMENTS = ("beyond", "just_beyond")    # sources beyond the likelihood's reach
JUST_BEYOND_FACTOR = 1.5    # just beyond: sites between the reach and this many times it


def split_for_study(table, observation_members=OBSERVATION_MEMBERS):
    """(members the likelihoods may use: all but the last ``observation_members``, the
    observation pool: those last members)."""
    order = np.sort(table.members)
    if not 1 <= observation_members < order.size:
        raise InputError(f"the member study needs more than {observation_members} members "
                         f"per node (the table has {order.size})")
    pool = np.isin(table.members, order[-observation_members:])
    return table.select_members(~pool), table.select_members(pool)


def held_out_nodes(table):
    """{placement: (bool over the rings the likelihood's table keeps, node azimuth stride)}
    for the placements ``table`` allows (see the module docstring)."""
    nr, na = len(table.distances_km), len(table.azimuths_deg)
    out = {"node": (np.ones(nr, bool), 1)}
    if nr >= 3:
        out["between"] = (np.isin(np.arange(nr), [0, nr - 1]), 1)
    elif na >= 4 and na % 2 == 0:
        out["between"] = (np.ones(nr, bool), 2)
    if na >= 4 and na % 2 == 0:
        out["between_spokes"] = (np.ones(nr, bool), 2)
    if magnitude_pairs(table):
        out["between_magnitudes"] = (np.ones(nr, bool), 1)
    if nr >= 2:
        out["beyond"] = (np.arange(nr) < nr - 1, 1)
        out["just_beyond"] = (np.arange(nr) < nr - 1, 1)
    return out


def magnitude_pairs(table):
    """[(lower slice, upper slice)]: neighbouring magnitudes of one mechanism and depth."""
    groups = {}
    for k, sl in enumerate(table.slices):
        groups.setdefault((sl["mechanism"], sl["depth_km"]), []).append(k)
    pairs = []
    for members in groups.values():
        members = sorted(members, key=lambda k: table.slices[k]["mw"])
        pairs += list(zip(members[:-1], members[1:]))
    return pairs


def _site_nodes(pool, slices, placement, rings, stride):
    """(nodes where the first site may lie, nodes for the others): (ring, azimuth) indices
    where an observation member of one of ``slices`` falls, for ``placement``."""
    nr, na = pool.toppled.shape[1:3]
    falls = [(i, j) for i in range(nr) for j in range(na)
             if any(pool.toppled[s, i, j].any() for s in slices)]
    if placement in ("between", "between_spokes"):
        falls = [(i, j) for i, j in falls if not rings[i] or j % stride]
        return falls, falls
    if placement == "beyond":
        return [(i, j) for i, j in falls if i == nr - 1], falls
    return falls, falls


def draw_columns(pool, slices, upper_weight, i, j, strike_deg, fallen, rng,
                 sigma_deg=OBS_UNCERTAINTY_DEG):
    """Columns at node (ring i, azimuth j) drawn until ``fallen`` have fallen: each from
    the upper of ``slices`` (lower, upper) with probability ``upper_weight``, else from the
    lower; a column type and a member at random; falls turned by the strike, with a
    normal measurement error of ``sigma_deg``.  None when neither slice falls there."""
    if not any(pool.toppled[s, i, j].any() for s in slices):
        return None

    def pick_slice():
        return slices[1] if rng.uniform() < upper_weight else slices[0]
    return draw_site_columns(pool, slices[0], i, j, strike_deg, fallen, rng, sigma_deg,
                             pick_slice)


def _draw_source(models, pool, rng):
    """(placement, (lower, upper) slices, upper weight, true Mw) of one trial; None when
    no observation member of the table ever falls."""
    table = models["node"].table
    falling = np.flatnonzero(pool.toppled.reshape(len(table.slices), -1).any(axis=1))
    if not falling.size:
        return None
    s = int(rng.choice(falling))
    placement = str(rng.choice(PLACEMENTS))
    if placement not in models:
        placement = "node"
    if placement == "between_magnitudes":
        pairs = [pq for pq in magnitude_pairs(table) if set(pq) & set(falling.tolist())]
        if pairs:
            lower, upper = pairs[int(rng.integers(len(pairs)))]
            w = float(rng.uniform(0.0, 1.0))
            mw = (1 - w) * table.slices[lower]["mw"] + w * table.slices[upper]["mw"]
            return placement, (lower, upper), w, float(mw)
        placement = "node"
    return placement, (s, s), 0.0, float(table.slices[s]["mw"])


def study_trial(models, pool, n_sites, fallen, candidates, rng):
    """One truth test of the study: a dict, or None when no observation member of the
    table ever falls.  A slice without falls (a magnitude too small to topple anything at
    the table's rings) cannot be the truth of a test with fallen columns.  ``models``:
    {placement: ForwardModel} (:func:`held_out_nodes`); a placement whose nodes see no
    fall is tried as ``node``."""
    table = models["node"].table
    drawn = _draw_source(models, pool, rng)
    if drawn is None:
        return None
    placement, pair, weight, true_mw = drawn
    strike = float(rng.uniform(0.0, 360.0))
    placed = _draw_sites(models, pool, placement, pair, weight, strike, n_sites, fallen, rng)
    if placed is None:
        return None
    placement, sites = placed
    model = models[placement]
    reach = model.table.distances_km[-1]
    observations, truth = site_frame(sites)
    true_baz = azimuth_deg(truth[0], truth[1])
    distances = [float(np.hypot(e, n)) for _, e, n, _ in sites]
    row = {"slice": pair[0] if weight < 0.5 else pair[1],
           "mechanism": table.slices[pair[0]]["mechanism"], "true_mw": true_mw,
           "sites": len(sites), "fallen_per_site": fallen, "strike_deg": strike,
           "placement": placement, "true_back_azimuth_deg": true_baz,
           "true_distance_km": float(np.hypot(*truth)),
           "site_distances_km": " ".join(f"{r:g}" for r in distances),
           "standing_observed": sum(not c.fallen for *_, cols in sites for c in cols),
           "no_candidate": False,
           # sites farther from the source than the likelihood's last ring
           "sites_beyond": int(sum(r > reach + 1e-9 for r in distances)),
           # a site as far as the likelihood's last ring: the source at the reach's edge
           "at_reach_edge": bool(max(distances) >= reach - candidates.step_km)}
    try:
        post = invert(model, observations, candidates)
    except OutOfReach:
        return _refused_row(row, truth, observations, model.table, candidates)
    return _answer_row(row, post, truth, true_baz, true_mw)


def _draw_sites(models, pool, placement, pair, weight, strike, n_sites, fallen, rng):
    """(placement, [(name, east km, north km, columns)] about the source at the origin) of
    a trial; a placement whose nodes see no fall is tried as ``node``; None when no node
    sees one."""
    table = models["node"].table
    if placement == "just_beyond":
        sites = just_beyond_sites(pool, pair[0], models[placement].table.distances_km[-1],
                                  strike, n_sites, fallen, rng)
        if sites is not None:
            return placement, sites
        placement = "node"
    first, others = _site_nodes(pool, pair, placement, *held_out_nodes(table)[placement])
    if not first:
        placement = "node"
        first, others = _site_nodes(pool, pair, "node", *held_out_nodes(table)["node"])
    if not first:
        return None
    start = first[int(rng.integers(len(first)))]
    rest = [n for n in others if n != start]
    picks = rng.choice(len(rest), size=min(n_sites - 1, len(rest)), replace=False)
    sites = []
    for k, (i, j) in enumerate([start] + [rest[p] for p in picks]):
        e, n = site_position(pool.distances_km[i], (pool.azimuths_deg[j] + strike) % 360.0)
        sites.append((f"S{k + 1}", e, n, draw_columns(pool, pair, weight, i, j, strike,
                                                      fallen, rng)))
    return placement, sites


def just_beyond_sites(pool, s, reach_km, strike_deg, n_sites, fallen, rng):
    """Sites of a source of slice ``s`` just beyond the reach ``reach_km`` (the likelihood's
    last ring): each at a distance uniform between the reach and ``JUST_BEYOND_FACTOR``
    times it (or the pool's next ring, if nearer), at a node azimuth where the pool falls
    at the rings about it, the first's or a neighbour of it (sites that see the source
    from one side, near enough to each other for candidates in common); each column drawn
    from the nearer ring's members or the farther's in proportion to the distance's
    log-distance weight (the mixture the likelihood assumes between rings).  None when
    the pool has no ring beyond the reach or no fall at its rings about it."""
    rings = pool.distances_km
    i1 = int(np.searchsorted(rings, reach_km + 1e-9))
    if i1 == 0 or i1 >= len(rings):
        return None
    i0, top = i1 - 1, min(JUST_BEYOND_FACTOR * reach_km, rings[i1])
    falls = [j for j in range(len(pool.azimuths_deg))
             if pool.toppled[s, i0, j].any() or pool.toppled[s, i1, j].any()]
    if not falls:
        return None
    first = falls[int(rng.integers(len(falls)))]
    na = len(pool.azimuths_deg)
    near = [j for j in falls if min((j - first) % na, (first - j) % na) <= 1]
    sites = []
    for k, r in enumerate(np.sort(rng.uniform(reach_km, top, n_sites))):
        r = max(float(r), reach_km * (1 + 1e-6))
        j = first if k == 0 else near[int(rng.integers(len(near)))]
        w = math.log(r / rings[i0]) / math.log(rings[i1] / rings[i0])

        def pick_ring(w=w):
            return i1 if rng.uniform() < w else i0
        e, n = site_position(r, (pool.azimuths_deg[j] + strike_deg) % 360.0)
        sites.append((f"S{k + 1}", e, n, draw_site_columns(
            pool, s, i0, j, strike_deg, fallen, rng, pick_ring=pick_ring)))
    return sites


def _refused_row(row, truth, observations, table, candidates):
    """A study trial's row when no candidate lies within the table's reach of every site."""
    lost = out_of_reach_row(truth, observations, table, candidates)
    return {**row, **{k: lost[k] for k in ("back_azimuth_in_95", "width95_deg",
                                           "epicentre_in_95", "distance_in_95",
                                           "credible_area_95_km2", "no_candidate")},
            **{k: lost[k] for k in REACH_KEYS}, "mw_in_95": False, "p_true_mw": np.nan,
            "mw_ci95_width": np.nan, "reach_edge_bayes_factor": np.nan,
            "reach_edge_warning": False, "fit_warning": False, "fit_p_value": np.nan,
            "beyond_bayes_factor": np.nan, "beyond_warning": False,
            "p_beyond": np.nan, "beyond_in_95": False, "p_true_mechanism": np.nan}


def _answer_row(row, post, truth, true_baz, true_mw):
    """A study trial's row from its posterior, checked against the truth."""
    summary = post.summary()
    check = truth_check(post, {"epicentre_km": truth, "back_azimuth_deg": true_baz,
                               "distance_km": row["true_distance_km"],
                               "mechanism": row["mechanism"], "mw": true_mw}, summary)
    lo, hi = summary["magnitude_ci95"]
    nearest = min(summary["magnitude_posterior"], key=lambda m: abs(float(m) - true_mw))
    return {**row,
            "back_azimuth_in_95": check["back_azimuth_in_95"],
            "width95_deg": summary["back_azimuth_ci95_width_deg"],
            "epicentre_in_95": check["epicentre_in_95"],
            "distance_in_95": check["distance_in_95"],
            "credible_area_95_km2": summary["credible_area_95_km2"],
            **{k: check[k] for k in REACH_KEYS},
            "reach_edge_bayes_factor": summary["reach_edge_bayes_factor"],
            "reach_edge_warning": summary["reach_edge_warning"],
            "fit_warning": summary["fit_warning"] is not None,
            "fit_p_value": summary["fit_p_value"],
            "beyond_bayes_factor": summary["beyond_bayes_factor"],
            "beyond_warning": summary["beyond_warning"],
            "p_beyond": summary["p_beyond"], "beyond_in_95": summary["beyond_in_95"],
            "mw_in_95": check["mw_in_95"], "mw_ci95_width": hi - lo,
            "p_true_mw": summary["magnitude_posterior"][nearest],
            "p_true_mechanism": summary["mechanism_posterior"].get(row["mechanism"], 0.0)}


def member_study(table, candidates, likelihood_members=LIKELIHOOD_MEMBERS,
                 observation_members=OBSERVATION_MEMBERS, trials=STUDY_TRIALS,
                 kernel_deg=DEFAULT_KERNEL_DEG, floor=DEFAULT_FLOOR, likelihoods=LIKELIHOODS,
                 fallen_per_site=FALLEN_PER_SITE, site_counts=SITE_COUNTS, seed=STUDY_SEED,
                 jobs=1, progress=None):
    """Every trial of every (likelihood, L, S, K): a DataFrame, one row per trial (see the
    module docstring).  L values above the members the likelihoods may use are left out.
    The (likelihood, L) configurations run on ``jobs`` processes; each trial's draws are
    seeded by S, K and the trial alone, so the rows are the same for any ``jobs``;
    ``progress(kind, L)`` is called as each configuration is done."""
    usable, pool = split_for_study(table, observation_members)
    sizes = [n for n in likelihood_members if n <= usable.members.size]
    if not sizes:
        raise InputError(f"the table's {usable.members.size} likelihood members are fewer "
                         f"than the smallest study size {min(likelihood_members)}")
    configurations = [(kind, size) for kind in likelihoods for size in sizes]
    work = partial(_configuration_trials, usable, pool, candidates, kernel_deg, floor,
                   site_counts, fallen_per_site, trials, seed)
    jobs = max(1, min(jobs, len(configurations)))
    rows = []
    if jobs > 1:
        with Pool(jobs, initializer=die_with_parent, initargs=(os.getpid(),)) as workers:
            for (kind, size), part in zip(configurations,
                                          workers.imap(work, configurations)):
                rows += part
                if progress:
                    progress(kind, size)
    else:
        for kind, size in configurations:
            rows += work((kind, size))
            if progress:
                progress(kind, size)
    return pd.DataFrame(rows)


def _configuration_trials(usable, pool, candidates, kernel_deg, floor, site_counts,
                          fallen_per_site, trials, seed, configuration):
    """The rows of one (likelihood kind, L members) configuration, every S and K."""
    kind, size = configuration
    order = np.sort(usable.members)
    members = usable.select_members(np.isin(usable.members, order[:size]))
    models = {placement: ForwardModel(members.select_nodes(*spec), kernel_deg, floor, kind)
              for placement, spec in held_out_nodes(members).items()}
    rows = []
    for n_sites in site_counts:
        for fallen in fallen_per_site:
            for trial in range(trials):
                rng = np.random.default_rng([seed, n_sites, fallen, trial])
                row = study_trial(models, pool, n_sites, fallen, candidates, rng)
                if row is not None:
                    rows.append({"likelihood": kind, "likelihood_members": size,
                                 **row, "trial": trial})
    return rows
