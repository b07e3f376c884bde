"""The pulse grid of the ``fragility`` campaign: its pulses and runs.  P(overturn) of any
specimen (a mesh specimen such as a scanned rock, or a column) over PGA (g) x PGV/PGA (s)
of one-cosine displacement pulses (:func:`pipeline.motion.pulses.one_cosine_pulse`, the
Virtual Shake Robot's grid: Chen et al. 2024, Seismica 3(1)).

The unknowns are ensemble members, not fixed values: ``--members`` parameter sets (a
Latin hypercube over ``--ranges``: contact stiffness kn, log-uniform; damping; static
friction mu_s, with mu_k in the calibration's ratio to it; a mesh specimen's footprint
tolerance), each shaken by every pulse from ``--headings`` directions.  The direction
is a fixed azimuth (``--azimuth``, a table) or, by default, sampled per member over
360 deg relative to the specimen's heading (a field rock: the direction it is shaken
from is unknown), stratified so that each member's directions cover the circle.

The 2D rigid block beside it: :mod:`pipeline.campaign.pulse_block`; the summary per cell
(P, contours, logistic surface): :mod:`pipeline.campaign.pulse_summary`; the adaptive
sampling: :mod:`pipeline.campaign.pulse_adaptive`.
"""
import math

import numpy as np
from scipy.stats import qmc

from pipeline.campaign.column_file import column_kn
from pipeline.campaign import member_ranges
from pipeline.campaign.shake_table_experiments import GRID_CONTACT, GRID_SPECIMEN
from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.scenario.contact_file import ranges_left
from pipeline.scenario.parameters import kinetic_friction

G = STANDARD_GRAVITY               # m/s^2 per g (the grid's PGA is in g)
VSR_PULSES = "pga_g=0.2:1.1:10;pgv_pga_s=0.1:1.0:10"   # Chen et al. (2024)
PULSE_PRESETS = {"vsr": VSR_PULSES}
PULSE_AXES = {"pga_g": (0.01, 5.0), "pgv_pga_s": (0.01, 3.0)}
MAX_AXIS_SIZE = 50
PULSE_DT_S = 0.005                # sample interval of the pulses, at most
PULSE_TAIL_S = 4.0                # at rest after the pulse: the body settles or falls
# member ranges: defaults from their one declaration (member_ranges.MEMBER_RANGES);
# bounds as the calibration's --grid; yaw_deg turns the specimen about the vertical
# from its stated heading (a run turns the shaking by -yaw_deg instead)
RANGE_BOUNDS = {"kn": GRID_CONTACT["kn"], "damping": GRID_CONTACT["damping"],
                "mu_s": GRID_CONTACT["mu_s"], **GRID_SPECIMEN, "yaw_deg": (-180.0, 180.0)}
DEFAULT_RANGES = member_ranges.ranges_text()
LOG_UNIFORM = ("kn",)
# the long-run gate's cost of a run, at most (it stops early once the specimen has fallen
# or settled): SP1 over the vsr grid took 1,600 runs in 166 s on 2 cores (2026-11-27),
# 0.09 s of YADE per simulated second (runs stop early: the bound takes twice that) and
# about 0.1 s per run besides
RUN_CORE_S_PER_MOTION_S = 0.2
RUN_CORE_S_PER_RUN = 0.3


def parse_pulses(text):
    """``pga_g=LO:HI:N;pgv_pga_s=LO:HI:N`` or a preset (``vsr``) -> {"pga_g": array,
    "pgv_pga_s": array} (linear, LO and HI included; N = 1 needs LO = HI)."""
    text = str(text).strip()
    text = PULSE_PRESETS.get(text.lower(), text)
    axes = {}
    for name, value in _items(text, "--pulses", PULSE_AXES, "axis",
                              "give pga_g=LO:HI:N;pgv_pga_s=LO:HI:N, or the preset vsr"):
        parts = value.split(":")
        try:
            lo, hi, n = float(parts[0]), float(parts[1]), parts[2]
            if len(parts) != 3 or not n.strip().isdigit():
                raise ValueError
            n = int(n)
        except (ValueError, IndexError):
            raise InputError(f"--pulses {name}={value!r}: expected LO:HI:N (N a whole "
                             "number)") from None
        _check_span("--pulses", name, value, lo, hi, PULSE_AXES[name])
        if not 1 <= n <= MAX_AXIS_SIZE or (n == 1) != (lo == hi):
            raise InputError(f"--pulses {name}: N must be 1-{MAX_AXIS_SIZE}, and 1 exactly "
                             f"when LO = HI, got {value}")
        axes[name] = np.round(np.linspace(lo, hi, n), 9)
    missing = [a for a in PULSE_AXES if a not in axes]
    if missing:
        raise InputError(f"--pulses lacks {missing[0]} (give pga_g=LO:HI:N;pgv_pga_s=LO:HI:N, "
                         "or the preset vsr)")
    return axes


def parse_ranges(text, mesh=True):
    """``name=LO:HI;...`` -> {name: (lo, hi)}: for a mesh specimen over the defaults
    (:data:`DEFAULT_RANGES`, from the shake-table calibration of a rock), for a column
    over none (the paper's values, or a description's matched kn); LO = HI fixes a
    value; footprint_tolerance_m only for a mesh specimen."""
    ranges = {}
    for source in ((DEFAULT_RANGES,) if mesh else ()) + (text or "",):
        given = {}
        for name, value in _items(source, "--ranges", RANGE_BOUNDS, "parameter",
                                  f"known: {', '.join(RANGE_BOUNDS)}"):
            try:
                lo, hi = (float(v) for v in value.split(":"))
            except ValueError:
                raise InputError(f"--ranges {name}={value!r}: expected LO:HI") from None
            _check_span("--ranges", name, value, lo, hi, RANGE_BOUNDS[name])
            given[name] = (lo, hi)
        if "footprint_tolerance_m" in given and not mesh:
            raise InputError("--ranges footprint_tolerance_m: only a mesh specimen has a "
                             "footprint tolerance")
        ranges.update(given)
    return ranges


def _items(text, flag, known, what, hint):
    """(name, value) of each ``name=value`` of ``text`` (``;`` between them), each name one
    of ``known`` and given once; else InputError naming ``flag``, ``what`` and ``hint``."""
    seen = set()
    for item in text.split(";"):
        if not item.strip():
            continue
        name, _, value = (s.strip() for s in item.partition("="))
        if name not in known:
            raise InputError(f"{flag}: unknown {what} {name!r} ({hint})")
        if name in seen:
            raise InputError(f"{flag} names {name} twice")
        seen.add(name)
        yield name, value


def _check_span(flag, name, value, lo, hi, bounds):
    """InputError unless LO and HI are finite and ``bounds[0] <= lo <= hi <= bounds[1]``."""
    low, high = bounds
    if not (math.isfinite(lo) and math.isfinite(hi) and low <= lo <= hi <= high):
        raise InputError(f"{flag} {name}: need {low:g} <= LO <= HI <= {high:g}, got {value}")


def sample_sets(members, seed, ranges):
    """``members`` parameter sets: one Latin hypercube over ``ranges`` (kn log-uniform);
    mu_k from mu_s by the contact's one rule (:func:`~pipeline.scenario.parameters.kinetic_friction`)."""
    names = sorted(ranges)
    if not names:
        return [{} for _ in range(members)]
    u = qmc.LatinHypercube(d=len(names), seed=seed).random(members)
    sets = []
    for row in u:
        point = {}
        for name, q in zip(names, row):
            lo, hi = ranges[name]
            if name in LOG_UNIFORM:
                point[name] = float(math.exp(math.log(lo) + q * (math.log(hi) - math.log(lo))))
            else:
                point[name] = float(lo + q * (hi - lo))
            point[name] = float(f"{point[name]:.6g}")
        if "mu_s" in point:
            point["mu_k"] = kinetic_friction(point["mu_s"])
        sets.append(point)
    return sets


def member_azimuths(members, headings, seed, heading_deg=0.0):
    """(members, headings) shaking azimuths (deg): stratified over 360 deg per member
    (heading j of ``headings`` in [j, j + 1) * 360 / headings, uniform), relative to the
    specimen's heading (turning the specimen turns them with it)."""
    rng = np.random.default_rng([int(seed), 4242])
    u = (np.arange(headings)[None, :] + rng.random((members, headings))) / headings
    return np.round((heading_deg + 360.0 * u) % 360.0, 6)


def yawed(azimuths, sets):
    """(members, headings) shaking azimuths (deg) relative to each member's yawed
    specimen: a specimen turned clockwise by its ``yaw_deg`` is shaken from azimuth
    minus that turn."""
    yaw = np.array([[point.get("yaw_deg", 0.0)] for point in sets], float)
    turned = np.round((azimuths - yaw) % 360.0, 6) % 360.0
    return np.where(yaw == 0.0, azimuths, turned)


def pulse_file(cache_dir, pga_m_s2, pgv_pga_s):
    """The pulse of one cell along North (a run turns it by its azimuth), saved once."""
    name = f"cosine_pulse_{pga_m_s2:.6g}ms2_{pgv_pga_s:.6g}s.npz"
    path = cache_dir / name
    if not path.is_file():
        cache_dir.mkdir(parents=True, exist_ok=True)
        one_cosine_pulse(pga_m_s2, pgv_pga_s, 0.0, PULSE_DT_S, PULSE_TAIL_S).save(path)
    return path


def pulse_runs(data, column, pulses, members, headings, azimuth, seed, ranges,
               stiffness="matched", contact=None):
    """(pulse cells, [(pga, ratio, params, tags)]): every cell x parameter set x heading.
    ``data``: the description dict (None: the paper's column); ``contact``: a contact
    file's values, fixed for every run (not drawn; a --ranges of a field it sets is
    refused)."""
    mesh = data is not None and "mesh" in data
    grid = parse_pulses(pulses)
    ranges = drawn_ranges(ranges, mesh, contact)

    if not (isinstance(headings, int) and 1 <= headings <= 360):
        raise InputError(f"--headings must be an integer in [1, 360], got {headings!r}")
    if azimuth is not None:
        if not (math.isfinite(azimuth) and 0 <= azimuth < 360):
            raise InputError(f"--azimuth must be in [0, 360) deg, got {azimuth:g}")
        if headings != 1:
            raise InputError("--azimuth fixes the direction: --headings must be 1")
    sets = sample_sets(members, seed, ranges)
    if azimuth is not None and members > 1 and all(lo == hi for lo, hi in ranges.values()):
        raise InputError(f"--members {members} with nothing drawn (no --ranges) and a fixed "
                         "--azimuth would repeat one run: give --ranges or --members 1")
    if azimuth is None:
        heading = float(data.get("heading_deg", 0.0)) if mesh else 0.0
        azimuths = member_azimuths(members, headings, seed, heading)
    else:
        azimuths = np.full((members, 1), float(azimuth))
    azimuths = yawed(azimuths, sets)
    runs = []
    for i, ratio in enumerate(grid["pgv_pga_s"]):
        for j, pga_g in enumerate(grid["pga_g"]):
            for m, point in enumerate(sets):
                for h in range(azimuths.shape[1]):
                    params = {"column": "monolithic" if mesh else column, **(contact or {}),
                              **{k: v for k, v in point.items() if k in GRID_CONTACT},
                              "rotate_deg": float(azimuths[m, h])}
                    if data is not None:
                        params["column_file"] = {**data, **{k: v for k, v in point.items()
                                                            if k in GRID_SPECIMEN}}
                    if "kn" not in point and "kn" not in (contact or {}) and data is not None:
                        params["kn"] = column_kn(data, stiffness)
                    runs.append((round(float(pga_g) * G, 6), round(float(ratio), 6), params,
                                 {"cell": [i, j], "pga_g": float(pga_g),
                                  "pgv_pga_s": float(ratio), "member": m, "heading": h,
                                  "azimuth_deg": float(azimuths[m, h]), "point": point}))
    return grid, sets, azimuths, runs


def drawn_ranges(text, mesh, contact=None):
    """The ranges drawn (:func:`parse_ranges` of ``text``) without those a contact file
    fixes (``contact``: its values, or None); a --ranges of a field it sets is refused."""
    given = parse_ranges(text, mesh=False) if contact else {}    # the names --ranges gives
    return ranges_left(parse_ranges(text, mesh), contact, given, "--ranges")


def run_core_s(pgv_pga_s):
    """Core seconds of one run (the long-run gate's estimate): its pulse and tail at
    RUN_CORE_S_PER_MOTION_S."""
    return RUN_CORE_S_PER_RUN + (2 * math.pi * pgv_pga_s + PULSE_TAIL_S) * RUN_CORE_S_PER_MOTION_S
