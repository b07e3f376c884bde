"""Scene parameters as dataclasses: one declaration gives each parameter's default,
unit, allowed range and help text; the command line and ``params.json`` derive from it.

Defaults are the paper's (:mod:`pipeline.paper`).  Ranges are what the model can
represent and keep stable (docs/command-line.md); a value outside raises an
:class:`~pipeline.files.InputError` naming the option and its range.
"""
import dataclasses
import math
from dataclasses import dataclass, field

from pipeline.constants import COLUMN_KINDS, COLUMN_TYPES, RIM_POINTS
from pipeline import paper
from pipeline.files import InputError
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.colonnade_file import load_if_colonnade
from pipeline.scenario.column_format import DENSITY_RANGE
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.time_step import CONVERGED_DT_FACTOR
from pipeline.userfiles import number

RIM_SPHERE_RADIUS_M = 0.005   # rim contact spheres of the columns
MIN_BODY_SIZE_M = 10 * RIM_SPHERE_RADIUS_M   # a drum must hold its two rims of spheres
# kinetic over static friction, the one rule mu_k = ratio x mu_s wherever mu_s is given
# alone: the paper's 0.6 / 0.7, the pair the shake-table calibration chose for SP1
MU_K_OVER_MU_S = paper.MU_KINETIC / paper.MU_STATIC


def kinetic_friction(mu_s):
    """The kinetic friction coefficient of a static one: MU_K_OVER_MU_S x mu_s, to 4 places."""
    return round(MU_K_OVER_MU_S * mu_s, 4)


def param(default, unit, help, low=None, high=None, flag=None, low_open=False, choices=None,
          metavar=None, high_open=False, optional=None, required=False):
    """A dataclass field with unit, help text, bounds [low, high] (low excluded when
    ``low_open``, high when ``high_open``; either may be None: unbounded), its command-line
    flag and the flag's metavar (the command line builds the flags:
    :mod:`pipeline.cli._fields`).  A tuple field's bounds hold for each of its values.

    A default of None or () says "not given" and must be declared so: ``optional``, what
    leaving the field unset means (a phrase the help text shows as "unset: ...", or True
    when the help already says it: an alternative not taken, no file), or ``required``
    (None refused on creation: "give --flag").  Any other default is the value a run takes
    when the field is not given."""
    unset = default is None or default == ()
    if unset and not optional and not required:
        raise TypeError(f"param {flag or help!r}: a default of {default!r} must be declared "
                        "optional (what unset means) or required")
    if not unset and (optional or required):
        raise TypeError(f"param {flag or help!r}: only a default of None or () is optional "
                        f"or required, got {default!r}")
    return field(default=default, metadata={"unit": unit, "help": help, "low": low, "high": high,
                                            "low_open": low_open, "high_open": high_open,
                                            "flag": flag, "choices": choices,
                                            "metavar": metavar, "optional": optional,
                                            "required": required})


def check_fields(obj):
    """Validate every field of a parameter dataclass against its metadata: a required
    field given, each value in its choices or range (an optional field may be unset)."""
    for f in dataclasses.fields(obj):
        value, meta = getattr(obj, f.name), f.metadata
        name = meta.get("flag") or f.name
        if value is None and meta.get("required"):
            raise InputError(f"give {name}")
        if value is None and f.default is None:      # unset: its meaning declared (param)
            continue
        if meta.get("choices"):
            if value not in meta["choices"]:
                raise InputError(f"{name} must be one of {', '.join(meta['choices'])}, "
                                 f"got {value!r}")
            continue
        if meta.get("low") is None and meta.get("high") is None:
            continue
        for v in _leaves(value):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or \
                    not math.isfinite(v):
                raise InputError(f"{name} must be a finite number, got {v!r}")
            if f.type in (int, "int") and int(v) != v:
                raise InputError(f"{name} must be an integer, got {v!r}")
            number(v, name, meta.get("low"), meta.get("high"), meta["unit"],
                   meta.get("low_open", False), meta.get("high_open", False))


def _leaves(value):
    """The numbers of a field's value: itself, or each of a tuple (of tuples)."""
    if not isinstance(value, tuple):
        return (value,)
    return tuple(v for item in value for v in _leaves(item))


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
    mu_k: float = param(None, "", "kinetic friction coefficient", None, None, "--mu-k",
                        optional=f"{paper.MU_KINETIC:g} / {paper.MU_STATIC:g} x mu_s, the "
                        "paper's pair")

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
                             "points))", 0.0, 0.5, "--dt-factor", low_open=True,
                             optional="the largest stable at the contact damping (0.235 at "
                             f"the paper's 0.36), at most {CONVERGED_DT_FACTOR:g} (converged, "
                             "make bench)")
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
    monolith of the same outline the monolith's; a colonnade's description there
    (:mod:`pipeline.scenario.colonnade_file`) puts the colonnade in the scene instead
    (``colonnade``; ``geometry`` its first column's)."""
    kind: str = param("both", "", "both = drums at x = -1.5 m and monolith at +1.5 m",
                      choices=COLUMN_KINDS, flag="--column")
    hd: float = param(paper.COLUMN_HD, "", "slenderness h/d", 1.0, 30.0, "--hd")
    height: float = param(paper.COLUMN_HEIGHT_M, "m", "column height", 0.1, 30.0, "--height")
    n_drums: int = param(paper.N_DRUMS, "", "number of drums", 1, 60, "--drums")
    density: float = param(paper.MARBLE_DENSITY_KG_M3, "kg/m^3", "density",
                           *DENSITY_RANGE, "--density")
    centred: bool = param(None, "", "single column at the centre",
                          optional="centred unless the twin model (both)")
    column_file: object = param(None, "", "column description: a shipped example's name, a "
                                ".json/.yaml file or the description as a dict",
                                optional="the paper's column")
    geometry: object = field(default=None, init=False, repr=False, compare=False)
    colonnade: object = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        check_fields(self)
        colonnade = None if self.column_file is None else load_if_colonnade(self.column_file)
        if colonnade is not None:         # a colonnade: its columns and beams, not a column
            object.__setattr__(self, "colonnade", colonnade)
            object.__setattr__(self, "geometry", colonnade.columns[0].column)
            return
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
        if self.colonnade is not None:
            return []                      # the scene takes the colonnade whole
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
    window: tuple = param(None, "s", "[start, end] (record's clock) of the motion run",
                          optional="all of it")
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

def split_options(options):
    """Split keyword options into (Contact kwargs, Numerics kwargs); InputError on unknown."""
    contact_names = {f.name for f in dataclasses.fields(Contact)}
    numerics_names = {f.name for f in dataclasses.fields(Numerics)}
    unknown = set(options) - contact_names - numerics_names
    if unknown:
        raise InputError(f"unknown scene parameter(s): {', '.join(sorted(unknown))}")
    return ({k: v for k, v in options.items() if k in contact_names},
            {k: v for k, v in options.items() if k in numerics_names})
