"""Scene parameters as dataclasses: one declaration gives each parameter's default,
unit, allowed range and help text; the command line and ``params.json`` derive from it.

Defaults are the paper's (:mod:`pipeline.paper`).  Ranges are what the model can
represent and keep stable (docs/command-line.md); a value outside raises an
:class:`~pipeline.files.InputError` naming the option and its range.
"""
import dataclasses
import logging
import math
from dataclasses import dataclass, field

from pipeline.constants import COLUMN_KINDS, COLUMN_TYPES, RIM_POINTS
from pipeline import paper
from pipeline.files import InputError
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.column_format import DENSITY_RANGE
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.scene_file import SceneFile

log = logging.getLogger(__name__)

RIM_SPHERE_RADIUS_M = 0.005   # rim contact spheres of the columns
MIN_BODY_SIZE_M = 10 * RIM_SPHERE_RADIUS_M   # a drum must hold its two rims of spheres
# An explicit step of a spring-dashpot of damping ratio zeta is stable for
# dt omega <= 2 (sqrt(1 + zeta^2) - zeta).  The scene's fastest mode is not one body on
# its rim springs (omega_n = sqrt(kn x rim points / m), the time step's unit) but the
# drums of a stack rocking on each other: measured on the still twin model over 5 s
# (make bench, section 9), the first factors that turn a body by degrees fit a mode of
# MODE_FREQUENCY_RATIO omega_n with MODE_DAMPING_RATIO times the contact's damping ratio
# (failures at zeta 0.2, 0.36, 0.5, 0.7, 1.0 from factors 0.45, 0.306, 0.24, 0.208, 0.166).
# The allowed factor is STABLE_DT_FRACTION of that mode's bound: at least 1.28x below
# every failure measured.
MODE_FREQUENCY_RATIO = 3.0
MODE_DAMPING_RATIO = 2.3
STABLE_DT_FRACTION = 0.75
CONVERGED_DT_FACTOR = 0.3     # outcomes converged up to this factor (make bench, section 5)
# kinetic over static friction, the one rule mu_k = ratio x mu_s wherever mu_s is given
# alone: the paper's 0.6 / 0.7, the pair the shake-table calibration chose for SP1
MU_K_OVER_MU_S = paper.MU_KINETIC / paper.MU_STATIC


def kinetic_friction(mu_s):
    """The kinetic friction coefficient of a static one: MU_K_OVER_MU_S x mu_s, to 4 places."""
    return round(MU_K_OVER_MU_S * mu_s, 4)


def param(default, unit, help, low=None, high=None, flag=None, low_open=False, choices=None,
          metavar=None):
    """A dataclass field with unit, help text, bounds [low, high] (low excluded when
    ``low_open``), its command-line flag and the flag's metavar (the command line builds
    the flags: :mod:`pipeline.cli._fields`)."""
    return field(default=default, metadata={"unit": unit, "help": help, "low": low, "high": high,
                                            "low_open": low_open, "flag": flag,
                                            "choices": choices, "metavar": metavar})


def check_fields(obj):
    """Validate every field of a parameter dataclass against its metadata."""
    for f in dataclasses.fields(obj):
        value, meta = getattr(obj, f.name), f.metadata
        name = meta.get("flag") or f.name
        if meta.get("choices"):
            if value not in meta["choices"] and not (value is None and f.default is None):
                raise InputError(f"{name} must be one of {', '.join(meta['choices'])}, "
                                 f"got {value!r}")
            continue
        if meta.get("low") is None and meta.get("high") is None:
            continue
        if value is None and f.default is None:      # unset: decided where it is used
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                not math.isfinite(value):
            raise InputError(f"{name} must be a finite number, got {value!r}")
        if f.type in (int, "int") and int(value) != value:
            raise InputError(f"{name} must be an integer, got {value!r}")
        low, high = meta.get("low"), meta.get("high")
        too_low = low is not None and (value <= low if meta.get("low_open") else value < low)
        if too_low or (high is not None and value > high):
            bracket = "(" if meta.get("low_open") else "["
            raise InputError(f"{name} {value:g} outside the allowed range "
                             f"{bracket}{low:g}, {high:g}] {meta['unit']}".rstrip())


@dataclass(frozen=True)
class Contact:
    """Frictional viscoelastic contact between bodies and with the pedestal."""
    kn: float = param(paper.COLUMN_KN_N_M, "N/m", "normal stiffness per rim contact point",
                      1e5, 1e11, "--kn")
    # stability measured on the still twin model (2 s, dt factor 0.3): largest body speed
    # 0.02 m/s (spring settling) up to damping 1.0, 0.2 m/s at 1.2, 11 m/s at 1.5, 76 m/s at 2
    damping: float = param(paper.DAMPING_RATIO, "", "contact damping ratio (1 = critical; "
                           "the explicit contact law is unstable above ~1.2)",
                           0.0, 1.0, "--damping")
    mu_s: float = param(paper.MU_STATIC, "", "static friction coefficient", 0.01, 2.0, "--mu-s")
    mu_k: float = param(None, "", "kinetic friction coefficient (default: "
                        f"{paper.MU_KINETIC:g} / {paper.MU_STATIC:g} x mu_s, the paper's pair)",
                        None, None, "--mu-k")

    def __post_init__(self):
        check_fields(self)
        if self.mu_k is None:
            object.__setattr__(self, "mu_k", kinetic_friction(self.mu_s))
        if not (isinstance(self.mu_k, (int, float)) and math.isfinite(self.mu_k)
                and 0 < self.mu_k <= self.mu_s):
            raise InputError(f"--mu-k must satisfy 0 < mu_k <= mu_s ({self.mu_s:g}), "
                             f"got {self.mu_k!r}")


@dataclass(frozen=True)
class Numerics:
    """How the YADE model discretises and integrates the bodies."""
    rim_points: int = param(RIM_POINTS, "", "contact spheres per circular rim", 8, 128, "--rim-points")
    rim_sphere_radius: float = param(RIM_SPHERE_RADIUS_M, "m", "radius of the rim contact spheres",
                                     0.0, 0.05, low_open=True)
    rim_phase_deg: float = param(0.0, "deg", "angular phase of the rim contact points "
                                 "(ensembles sample it: discretisation becomes noise)",
                                 -360.0, 360.0)
    verlet_distance: float = param(0.02, "m", "collider bound enlargement", 0.0, 1.0)
    dt_factor: float = param(None, "", "time step as a fraction of sqrt(m_min / (kn x rim "
                             "points)); default: the largest stable at the contact damping "
                             f"(0.235 at the paper's 0.36), at most {CONVERGED_DT_FACTOR:g} "
                             "(converged, make bench)", 0.0, 0.5, "--dt-factor", low_open=True)
    drive: str = param("inertial", "", "pedestal drive: gravity table (inertial) or per-step "
                       "velocity (kinematic, slow)", choices=("inertial", "kinematic"))
    drive_interval_s: float = param(0.002, "s", "gravity update interval", 0.0, 0.1,
                                    low_open=True)
    friction: str = param("switch", "", "mu_s sticking / mu_k sliding (switch) or mu_s only",
                          choices=("switch", "static"))
    friction_interval_s: float = param(0.002, "s", "friction switch interval", 0.0, 0.1,
                                       low_open=True)
    record_hz: float = param(100.0, "Hz", "trajectory sampling rate", 1.0, 10000.0)
    rest_velocity: float = param(0.005, "m/s", "bodies slower than this rest", 0.0, 1.0,
                                 low_open=True)
    rest_length: float = param(1.0, "m", "angular velocity times this counts as velocity",
                               0.0, 100.0, low_open=True)
    rest_duration_s: float = param(0.5, "s", "rest this long to stop early", 0.0, 1e9,
                                   low_open=True)
    tail_s: float = param(10.0, "s", "simulated time allowed after the motion ends", 0.0, 600.0)
    quiet_motion: str = param("skip", "", "the motion's quiet parts, where no body at rest can "
                              "start to move (the pre-check's thresholds): skip = start "
                              "quiet_lead_s before the first sample that can move a body and "
                              "stop once every body rests seated after the last; simulate = "
                              "the whole motion", flag="--quiet-motion",
                              choices=("skip", "simulate"))
    quiet_lead_s: float = param(1.0, "s", "simulated time before the first sample that can "
                                "move a body (quiet_motion skip)", 0.0, 600.0)

    def __post_init__(self):
        check_fields(self)


@dataclass(frozen=True)
class Column:
    """The column model: the paper's twin model (both), or one column; with
    ``column_file`` (a shipped example's name or a JSON/YAML file, see
    :mod:`pipeline.scenario.geometry`) the described column takes the drums' place and a
    monolith of the same outline the monolith's."""
    kind: str = param("both", "", "both = drums at x = -1.5 m and monolith at +1.5 m",
                      choices=COLUMN_KINDS, flag="--column")
    hd: float = param(paper.COLUMN_HD, "", "slenderness h/d", 1.0, 30.0, "--hd")
    height: float = param(paper.COLUMN_HEIGHT_M, "m", "column height", 0.1, 30.0, "--height")
    n_drums: int = param(paper.N_DRUMS, "", "number of drums", 1, 60, "--drums")
    density: float = param(paper.MARBLE_DENSITY_KG_M3, "kg/m^3", "density",
                           *DENSITY_RANGE, "--density")
    centred: bool = field(default=None, metadata={"help": "single column at the centre"})
    column_file: object = field(default=None, metadata={
        "help": "column description: a shipped example's name, a .json/.yaml file or the "
        "description as a dict"})
    geometry: object = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        check_fields(self)
        if self.column_file is not None:
            geometry = (ColumnGeometry.from_dict(self.column_file)
                        if isinstance(self.column_file, dict)
                        else ColumnGeometry.load(self.column_file))
            object.__setattr__(self, "geometry", geometry)
            return
        drum_height = self.height / self.n_drums
        diameter = self.height / self.hd
        # a drum must be tall and wide enough for its two rims of contact spheres
        if min(drum_height, diameter) < MIN_BODY_SIZE_M:
            raise InputError(f"--drums {self.n_drums} with --height {self.height:g} and --hd "
                             f"{self.hd:g} gives drums {drum_height:.3f} m high and "
                             f"{diameter:.3f} m wide: at least {MIN_BODY_SIZE_M:g} m each needed")

    @property
    def diameter(self):
        """Column diameter (m)."""
        return self.height / self.hd

    def sizes(self):
        """{hd, height (m), n_drums, density (kg/m^3)} of the column built: a described
        column's own (hd h/d of its base, to 6 places), else the fields'."""
        if self.geometry is None:
            return {"hd": self.hd, "height": self.height, "n_drums": self.n_drums,
                    "density": self.density}
        g = self.geometry
        return {"hd": round(g.height / g.base_width, 6), "height": g.height,
                "n_drums": len(g.bodies()), "density": g.density}

    def geometries(self):
        """(drums, monolith) geometries: the paper's equal drums and cylinder, or the
        described column and a monolith of its outline."""
        if self.geometry is not None:
            return self.geometry, self.geometry.monolithic()
        return (ColumnGeometry.drums(self.height, self.diameter, int(self.n_drums),
                                     self.density),
                ColumnGeometry.monolith(self.height, self.diameter, self.density))

    def specs(self):
        """The columns of the scene (:class:`~pipeline.scenario.geometry.ColumnSpec`):
        'both' puts the drums (or the described column) at x = -1.5 m and the monolith at
        +1.5 m; one column stands at the centre unless centred=False."""
        kinds = list(COLUMN_TYPES) if self.kind == "both" else [self.kind]
        centred = self.kind != "both" if self.centred is None else self.centred
        drums, monolith = self.geometries()
        out = []
        for kind in kinds:
            x = 0.0 if centred else (-paper.TWIN_OFFSET_M if kind == "drums"
                                     else paper.TWIN_OFFSET_M)
            out.append(ColumnSpec(kind, kind, x, 0.0, drums if kind == "drums" else monolith))
        return out


@dataclass(frozen=True)
class Block:
    """A rectangular test block (verification): width along East, depth along North."""
    height: float = param(paper.MARBLE_BLOCK_M["height"], "m", "block height", 0.01, 30.0)
    width: float = param(paper.MARBLE_BLOCK_M["width"], "m", "block width (East)", 0.005, 30.0)
    depth: float = param(paper.MARBLE_BLOCK_M["depth"], "m", "block depth (North)", 0.005, 30.0)
    density: float = param(paper.MARBLE_DENSITY_KG_M3, "kg/m^3", "density", *DENSITY_RANGE)
    theta0_rad: float = param(0.0, "rad", "initial tilt about North (+ leans East)", -1.5, 1.5)

    def __post_init__(self):
        check_fields(self)


MAX_SCALE = 20.0        # the largest motion scale factor (run --scale, ensemble --vary scale)


@dataclass(frozen=True)
class Drive:
    """How the record drives the pedestal: the part of it run (``window``: start and end,
    s on the record's clock; None: all of it), turned clockwise by ``rotate_deg`` and
    scaled by ``scale``."""
    window: tuple = field(default=None, metadata={
        "help": "[start, end] (s, record's clock) of the motion run; None: all of it"})
    rotate_deg: float = param(0.0, "deg", "the motion turned clockwise by this angle",
                              flag="--rotate")
    scale: float = param(1.0, "", "motion scale factor", 0.0, MAX_SCALE, "--scale")

    def __post_init__(self):
        check_fields(self)
        if not (isinstance(self.rotate_deg, (int, float)) and math.isfinite(self.rotate_deg)):
            raise InputError(f"--rotate must be a finite angle, got {self.rotate_deg!r}")
        if self.window is not None:
            window = tuple(self.window) if isinstance(self.window, (list, tuple)) else ()
            numbers = len(window) == 2 and all(
                isinstance(t, (int, float)) and not isinstance(t, bool) for t in window)
            if not (numbers and all(math.isfinite(t) for t in window)
                    and window[0] < window[1]):
                given = f"{window[0]:g} {window[1]:g}" if numbers else repr(self.window)
                raise InputError(f"--window needs START < END (finite), got {given}")
            object.__setattr__(self, "window", window)


@dataclass(frozen=True)
class RunParams:
    """Everything that defines one run besides its motion: the column, the contact, the
    numerics and the drive.  Written and read as one flat dict whose names are the
    fields' names (the column's ``kind`` as ``column``): campaign specs, the run id's
    hash and ``summary.json`` ``parameters`` spell every name the same way."""
    column: Column = field(default_factory=Column)
    contact: Contact = field(default_factory=Contact)
    numerics: Numerics = field(default_factory=Numerics)
    drive: Drive = field(default_factory=Drive)

    GROUPS = ("column", "contact", "numerics", "drive")

    def __post_init__(self):
        for group in self.GROUPS:
            if not isinstance(getattr(self, group), self.group_class(group)):
                raise InputError(f"run parameters: {group} must be a "
                                 f"{self.group_class(group).__name__}, got "
                                 f"{type(getattr(self, group)).__name__}")

    @staticmethod
    def group_class(group):
        """The parameter dataclass of one group (``group``: a GROUPS name)."""
        return {"column": Column, "contact": Contact, "numerics": Numerics,
                "drive": Drive}[group]

    @classmethod
    def names(cls, group):
        """{flat name: field name} of one group's dataclass (``group``: a GROUPS name)."""
        return {("column" if f.name == "kind" else f.name): f.name
                for f in dataclasses.fields(cls.group_class(group)) if f.init}

    @classmethod
    def from_dict(cls, data):
        """The run a flat dict describes (names of :meth:`to_dict`; a name left out takes
        its default); InputError naming an unknown name or a value out of range."""
        if not isinstance(data, dict):
            raise InputError(f"run parameters must be a mapping, got {data!r}")
        groups, known = {}, set()
        for group in cls.GROUPS:
            names = cls.names(group)
            known |= set(names)
            groups[group] = {names[k]: v for k, v in data.items() if k in names}
        unknown = sorted(set(data) - known)
        if unknown:
            raise InputError(f"unknown run parameter(s): {', '.join(unknown)}")
        return cls(*(cls.group_class(g)(**groups[g]) for g in cls.GROUPS))

    def to_dict(self):
        """The flat dict of every parameter (JSON-serialisable)."""
        out = {}
        for group in self.GROUPS:
            obj = getattr(self, group)
            for flat, name in self.names(group).items():
                value = getattr(obj, name)
                out[flat] = list(value) if isinstance(value, tuple) else value
        return out


PEDESTAL = {"size": paper.PEDESTAL_SIZE_M, "thickness": paper.PEDESTAL_THICKNESS_M,
            "mass": paper.PEDESTAL_MASS_KG,
            # the top face extends beyond the 5 m block so that a column falling over
            # the edge still lands at pedestal level (impact points up to ~4 m away)
            "contact_half_size": 12.0}


def largest_stable_dt_factor(damping):
    """Largest time-step factor that keeps contacts of this damping ratio stable."""
    zeta = MODE_DAMPING_RATIO * damping
    return STABLE_DT_FRACTION * 2.0 * (math.sqrt(1 + zeta ** 2) - zeta) / MODE_FREQUENCY_RATIO


def dt_factor_for(contact, numerics):
    """The time-step factor a scene uses: the given one, else the largest stable at the
    contact damping, at most CONVERGED_DT_FACTOR."""
    if numerics.dt_factor is not None:
        return numerics.dt_factor
    return min(CONVERGED_DT_FACTOR, largest_stable_dt_factor(contact.damping))


US_PER_BODY_STEP = 8.0   # wall us per body and time step: twin model 4.5 (8 bodies, ~36 us
#                          a step), a stack of 60 thin drums over 6.7 (it hit its wall limit)


def time_step_s(columns, contact, rim_points, dt_factor):
    """The scene's time step (s): ``dt_factor`` sqrt(m / (kn x base points)) of its
    lightest body on its base rim (at least ``rim_points`` points: a box on its four
    corners steps as finely as a drum on its rim); the scene takes it from the scene
    file."""
    stiffness = []
    for column in columns:
        for body in column["bodies"]:
            base = next(r for r in body["rims"] if r["role"] == "base")
            n_base = rim_points if base["kind"] == "circle" else len(base["points"])
            stiffness.append((body["mass"], contact.kn * max(n_base, rim_points)))
    return dt_factor * math.sqrt(min(m / k for m, k in stiffness))


def check_cost(params, wall_limit_s):
    """InputError when the scene file ``params`` would need more wall time for its t_max than
    ``wall_limit_s`` (the run's wall-clock limit would end it): say so before starting;
    a note on stdout when it takes over 5 minutes.  Returns the estimate (s): t_max /
    time step x bodies x US_PER_BODY_STEP."""
    bodies = sum(len(c["bodies"]) for c in params.columns)
    estimate = params.t_max / params.time_step_s * bodies * US_PER_BODY_STEP * 1e-6
    what = (f"{bodies} bodies stepping {params.time_step_s:.2g} s for "
            f"{params.t_max:.0f} s simulated: about {estimate / 60:.0f} min")
    if estimate > wall_limit_s:
        raise InputError(f"{what}, beyond the run's wall-clock limit ({wall_limit_s / 60:.0f} "
                         "min): use fewer or heavier blocks, a stiffer contact or a shorter "
                         "--window")
    if estimate > 300.0:
        log.info(f"note: {what} at most (quiet parts are skipped)")
    return estimate


def check_time_step(contact, numerics):
    """InputError when the time-step factor is too coarse for the contact damping."""
    limit = largest_stable_dt_factor(contact.damping)
    if numerics.dt_factor is not None and numerics.dt_factor > limit:
        raise InputError(f"--dt-factor {numerics.dt_factor:g} with --damping "
                         f"{contact.damping:g} is unstable (a still column rocks or falls): "
                         f"at this damping use --dt-factor <= {math.floor(limit * 1e3) / 1e3:g}")


def scene_params(columns=(), block=None, contact=None, numerics=None, motion_duration=0.0,
                 t_max=None):
    """The scene file (:class:`~pipeline.scenario.scene_file.SceneFile`) of a scene.

    columns: list of :class:`~pipeline.scenario.geometry.ColumnSpec` (from
    :meth:`Column.specs`); block: a :class:`Block` (placed as a column named "block" at
    the centre) or None; contact, numerics: :class:`Contact`, :class:`Numerics`
    (defaults when None).
    """
    contact = contact or Contact()
    numerics = numerics or Numerics()
    check_time_step(contact, numerics)
    if not columns and block is None:
        raise InputError("a scene needs at least one column or a block")
    if t_max is None:
        t_max = motion_duration + numerics.tail_s
    if not (math.isfinite(t_max) and t_max > 0):
        raise InputError(f"simulated duration must be positive, got {t_max!r}")
    specs = list(columns)
    if block is not None:
        specs.append(ColumnSpec("block", "block", 0.0, 0.0, ColumnGeometry.block(
            block.height, block.width, block.depth, block.density, block.theta0_rad)))
    pedestal = dict(PEDESTAL)
    for spec in specs:
        spec.geometry.check_rims(numerics.rim_sphere_radius)
        # a tall column falling over must still land at pedestal level
        reach = math.hypot(spec.x, spec.y) + 1.1 * spec.geometry.height + 2.0
        if reach > pedestal["contact_half_size"]:
            pedestal["contact_half_size"] = float(math.ceil(reach))
    scene_columns = [spec.scene(numerics.rim_points) for spec in specs]
    dt_factor = dt_factor_for(contact, numerics)
    return SceneFile(
        columns=scene_columns, block=None if block is None else dataclasses.asdict(block),
        contact=dataclasses.asdict(contact), numerics=dataclasses.asdict(numerics),
        pedestal=pedestal, dt_factor=dt_factor,
        time_step_s=time_step_s(scene_columns, contact, numerics.rim_points, dt_factor),
        t_max=float(t_max))


def split_options(options):
    """Split keyword options into (Contact kwargs, Numerics kwargs); InputError on unknown."""
    contact_names = {f.name for f in dataclasses.fields(Contact)}
    numerics_names = {f.name for f in dataclasses.fields(Numerics)}
    unknown = set(options) - contact_names - numerics_names
    if unknown:
        raise InputError(f"unknown scene parameter(s): {', '.join(sorted(unknown))}")
    return ({k: v for k, v in options.items() if k in contact_names},
            {k: v for k, v in options.items() if k in numerics_names})
