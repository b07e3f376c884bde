"""The members of the ``ensemble`` campaign (and of the campaigns that sample as it does:
fragility, convergence, the inversion's forward runs): their parameters sampled
reproducibly (scipy.stats.qmc Latin hypercube, the seed recorded), the nominal run with
the paper's values, and the ``--vary`` and ``--seed`` options.

Ranges (``ENSEMBLE_RANGES``, all around the paper's values; override with
``--vary NAME=LO,HI``):

- ``mu_s`` 0.55-0.85: marble on marble; Hinzen (2009) used 0.7, DEM studies of
  classical marble columns use values in this band; mu_k = 0.6 / 0.7 mu_s (the
  paper's ratio, :func:`pipeline.scenario.parameters.kinetic_friction`) unless given;
- ``damping`` 0.2-0.5 around the paper's 0.36;
- ``kn_factor`` 0.5-2 (log-uniform) on the paper's 1.2e8 N/m per point: the
  rocking response changes < 0.5 % for kn 1.2e7-1.2e9 (measured on the block);
- ``height_tolerance`` and ``diameter_tolerance`` +-1 % of the nominal column
  (masonry tolerances of cut drums; a real column's geometry: ``--column-file``);
- ``rim_phase_deg`` 0 to one rim spacing: the rim discretisation moves a fall by
  up to ~12 deg (make bench); sampling its phase turns that bias into noise;
- ``tilt_deg`` 0-0.5 deg toward ``tilt_azimuth_deg`` 0-360: a column already out
  of plumb (every block leans alike; joints square to the inclined axis);
- ``drum_offset_mm`` 0-3 mm: each drum above the first sits this far at most off
  the centre of the drum below, in a random direction (seeded per member);
- ``scale`` (off by default): an amplitude scaling of the motion.

Tilt and offsets make each member a column description (``pipeline.scenario.geometry``);
with ``--column both`` the monolith beside it has the same outline and tilt.

With ``--column-file`` every member is the described column with the same sampled values
applied to its blocks (:func:`pipeline.campaign.column_file.perturbed`: tolerances on
every block, the tilt added to the described one, drum offsets on the blocks above the
first that are not joined), and ``kn_factor`` multiplies the description's contact
stiffness (``--stiffness``, as in ``campaign columns``).
"""
import math

import numpy as np
from scipy.stats import qmc

from pipeline import paper
from pipeline.campaign.column_file import perturbed
from pipeline.constants import RIM_POINTS
from pipeline.files import InputError
from pipeline.scenario import Contact, Numerics
from pipeline.scenario.colonnade_file import load_if_colonnade
from pipeline.scenario.column_format import MAX_OFFSET_M
from pipeline.scenario.contact_file import ranges_left
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.parameters import kinetic_friction
from pipeline.scenario.time_step import check_time_step
from pipeline.simulate import check_scale

DEFAULT_SEED = 20091001        # BSSA 99(5), October 2009
ENSEMBLE_RANGES = {            # name: (low, high, "uniform" | "log")
    "mu_s": (0.55, 0.85, "uniform"),
    "damping": (0.2, 0.5, "uniform"),
    "kn_factor": (0.5, 2.0, "log"),
    "height_tolerance": (-0.01, 0.01, "uniform"),
    "diameter_tolerance": (-0.01, 0.01, "uniform"),
    "rim_phase_deg": (0.0, 360.0 / RIM_POINTS, "uniform"),
    "tilt_deg": (0.0, 0.5, "uniform"),
    "tilt_azimuth_deg": (0.0, 360.0, "uniform"),
    "drum_offset_mm": (0.0, 3.0, "uniform"),
}
GEOMETRY_KEYS = ("tilt_deg", "tilt_azimuth_deg", "drum_offset_mm")
# what --vary may ask of the parameters without a home of their own (the others are
# checked by their dataclass: Contact, Numerics; scale by simulate.check_scale)
VARY_LIMITS = {"kn_factor": (0.01, 100.0), "height_tolerance": (-0.2, 0.2),
               "diameter_tolerance": (-0.2, 0.2), "tilt_deg": (0.0, 10.0),
               "tilt_azimuth_deg": (0.0, 360.0), "drum_offset_mm": (0.0, 50.0)}


def check_seed(seed):
    """InputError unless the Latin-hypercube seed is a non-negative integer (--seed)."""
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)
                             or not 0 <= seed < 2 ** 63):
        raise InputError(f"--seed must be an integer in [0, 2^63), got {seed!r}")
    return seed


def check_vary_value(name, value):
    """InputError when ``value`` of --vary parameter ``name`` is outside what a run of
    that parameter allows (the same check as its flag)."""
    flag = f"--vary {name}="
    if name == "scale":
        check_scale(value, flag.rstrip("="))
    elif name in ("mu_s", "damping"):
        try:
            check_time_step(Contact(**{name: value}), Numerics())
        except InputError as exc:
            raise InputError(f"{flag}: {exc}") from None
    elif name == "rim_phase_deg":
        try:
            Numerics(rim_phase_deg=value)
        except InputError as exc:
            raise InputError(f"{flag}: {exc}") from None
    else:
        lo, hi = VARY_LIMITS[name]
        if not lo <= value <= hi:
            raise InputError(f"{flag}{value:g} outside the allowed range [{lo:g}, {hi:g}]")


def sample_batches(members, batch, seed, ranges=None, column="both", description=None,
                   kn=paper.COLUMN_KN_N_M):
    """Parameters of ``members`` runs in Latin-hypercube batches of ``batch``: batch 0 is
    :func:`sample_members` of ``seed`` (a fixed ensemble of ``batch`` members), batch b
    a hypercube of its own (seed [seed, b]), so that adding a batch reuses every member
    that ran."""
    rows = []
    for b in range(-(-members // batch)):
        rows += sample_members(batch, seed if b == 0 else [seed, b], ranges, column,
                               description=description, kn=kn, first_index=b * batch)
    return rows[:members]


def sample_members(members, seed, ranges=None, column="both", description=None, kn=paper.COLUMN_KN_N_M, first_index=0):
    """Parameters of ``members`` runs (list of dicts for run_column_spec), Latin hypercube
    (``seed``: an integer, or a list for a batch; members numbered from ``first_index``).

    ``description`` (a column description dict): every member is that column with the
    sampled tolerances, tilt and offsets applied
    (:func:`pipeline.campaign.column_file.perturbed`), validated; ``kn``: the contact
    stiffness the sampled ``kn_factor`` multiplies."""
    ranges = dict(ENSEMBLE_RANGES if ranges is None else ranges)
    if not (isinstance(members, int) and 1 <= members <= 10000):
        raise InputError(f"--members must be an integer in [1, 10000], got {members!r}")
    names = sorted(ranges)
    rng = seed if isinstance(seed, int) else np.random.default_rng(seed)
    unit = qmc.LatinHypercube(d=len(names), seed=rng).random(members)
    rows = []
    for index, u in enumerate(unit, start=first_index):
        v = {}
        for name, x in zip(names, u):
            lo, hi, kind = ranges[name]
            v[name] = float(math.exp(math.log(lo) + x * (math.log(hi) - math.log(lo)))
                            if kind == "log" else lo + x * (hi - lo))
        height = paper.COLUMN_HEIGHT_M * (1 + v.get("height_tolerance", 0.0))
        diameter = paper.COLUMN_HEIGHT_M / paper.COLUMN_HD * (1 + v.get("diameter_tolerance", 0.0))
        mu_s = round(v.get("mu_s", paper.MU_STATIC), 6)
        params = {"column": column, "hd": round(height / diameter, 6), "height": round(height, 6),
                  "mu_s": mu_s, "mu_k": kinetic_friction(mu_s),
                  "damping": round(v.get("damping", paper.DAMPING_RATIO), 6),
                  "kn": round(kn * v.get("kn_factor", 1.0), 1),
                  "rim_phase_deg": round(v.get("rim_phase_deg", 0.0), 6)}
        if "scale" in v:
            params["scale"] = round(v["scale"], 6)
        if description is not None:
            params["column_file"] = described_member(description, v, _first(seed), index)
        elif any(v.get(k) for k in GEOMETRY_KEYS):
            params["column_file"] = perturbed(
                paper_drums(height, diameter), tilt_deg=v.get("tilt_deg", 0.0),
                tilt_azimuth_deg=v.get("tilt_azimuth_deg", 0.0),
                max_offset_m=v.get("drum_offset_mm", 0.0) / 1000.0,
                rng=np.random.default_rng([_first(seed), index]))
        if "column_file" in params:             # the description fixes the sizes
            del params["hd"], params["height"]
        rows.append(params)
    return rows


def _first(seed):
    """The campaign's seed of an integer seed or a batch's [seed, b]."""
    return seed if isinstance(seed, int) else int(seed[0])


def described_member(data, v, seed, index):
    """Member ``index`` of a described column from its sampled values ``v``.  Validated
    before anything runs without the sampled offsets (sizes, tilts, statics: milliseconds;
    a member with offset joints takes about a second), whose size is checked alone.  Of a
    colonnade (a dict with ``stylobate``): :func:`colonnade_member`."""
    if "stylobate" in data:
        return colonnade_member(data, v, seed, index)
    args = (data, 1 + v.get("height_tolerance", 0.0), 1 + v.get("diameter_tolerance", 0.0),
            v.get("tilt_deg", 0.0), v.get("tilt_azimuth_deg", 0.0))
    member = perturbed(*args, v.get("drum_offset_mm", 0.0) / 1000.0,
                       np.random.default_rng([seed, index]))
    try:
        ColumnGeometry.from_dict(perturbed(*args))
        for k, block in enumerate(member["blocks"]):
            if max(map(abs, block.get("offset_m", [0.0, 0.0]))) > MAX_OFFSET_M:
                raise InputError(f"blocks[{k}]: offset_m above {MAX_OFFSET_M:g} m")
    except InputError as exc:
        raise InputError(f"ensemble member {index} of {data['name']}: {exc}") from None
    return member


def colonnade_member(data, v, seed, index):
    """Member ``index`` of a colonnade (its dict, every column written out): every
    column takes the same sampled height and diameter tolerances; no tilt and no drum
    offsets (they would move the capitals apart or together, and beams laid joint to
    joint over the column axes would part or overlap): tilts and offsets as described.
    Validated as a colonnade (InputError naming the member)."""
    columns = [{**placed, "column": perturbed(placed["column"],
                                              1 + v.get("height_tolerance", 0.0),
                                              1 + v.get("diameter_tolerance", 0.0))}
               for placed in data["columns"]]
    member = {**data, "columns": columns}
    try:
        load_if_colonnade(member)
    except InputError as exc:
        raise InputError(f"ensemble member {index} of {data['name']}: {exc}") from None
    return member


def paper_drums(height, diameter):
    """Description of the paper's drum column (equal cylindrical drums) of this size."""
    drum = {"shape": "frustum", "height": round(height / paper.N_DRUMS, 9),
            "bottom_diameter": round(diameter, 9), "top_diameter": round(diameter, 9)}
    return {"name": "drums", "density": paper.MARBLE_DENSITY_KG_M3,
            "blocks": [dict(drum) for _ in range(paper.N_DRUMS)]}


def contact_ranges(ranges, contact, vary=None):
    """The ranges without those a contact file fixes (``contact``: its values, or None):
    its damping and friction replace the sampled ones; its kn is what kn_factor
    multiplies.  A ``vary`` range of a field the file sets is refused (one line)."""
    return ranges_left(ranges, contact, vary or {}, "--vary")


def with_fixed_contact(rows, contact):
    """Member parameters with a contact file's damping and friction (its kn is the base
    of their kn, given to the sampling)."""
    fixed = {k: v for k, v in (contact or {}).items() if k != "kn"}
    return [{**row, **fixed} for row in rows]


def nominal(column="both", description=None, kn=None):
    """The nominal run: the paper's values (and a description as described, with ``kn``)."""
    params = {"column": column, "hd": paper.COLUMN_HD, "mu_s": paper.MU_STATIC,
              "mu_k": paper.MU_KINETIC}
    if description is not None:
        params.update(column_file=description, kn=kn)
    return params


def parse_vary(items):
    ranges = {}
    for item in items or []:
        name, _, values = item.partition("=")
        try:
            lo, hi = (float(v) for v in values.split(","))
        except ValueError:
            raise InputError(f"--vary {item!r}: expected NAME=LO,HI") from None
        if name not in ENSEMBLE_RANGES and name != "scale":
            raise InputError(f"--vary: unknown parameter {name!r} (known: "
                             f"{', '.join(ENSEMBLE_RANGES)}, scale)")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise InputError(f"--vary {item!r}: need finite LO <= HI")
        if name in ranges:
            raise InputError(f"--vary {name} given twice")
        check_vary_value(name, lo)
        check_vary_value(name, hi)
        kind = ENSEMBLE_RANGES.get(name, (0, 0, "uniform"))[2]
        if kind == "log" and lo <= 0:
            raise InputError(f"--vary {item!r}: {name} is sampled log-uniformly: LO > 0")
        ranges[name] = (lo, hi, kind)
    return ranges

