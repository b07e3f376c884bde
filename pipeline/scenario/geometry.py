"""Column geometry: a column as the stack of blocks that was found, from the bottom.

A column description (JSON, YAML optional; schema in docs/columns-and-model.md) is

    {"name": str, "density": kg/m^3, "blocks": [block, ... from the bottom]}

with each block ``{"shape": "frustum", "height", "bottom_diameter", "top_diameter"}`` or
``{"shape": "box", "height", "width", "depth"}`` (metres; width along East, depth along
North), optional ``density``, ``name``, ``offset_m: [east, north]``, ``tilt_deg``,
``tilt_azimuth_deg``, ``tilt_mode`` ("wedge" or "edge") and ``joined`` (true: carved
from one stone with the block below, e.g. echinus and abacus of one capital).

Rules (docs/columns-and-model.md):

- Placement: a block's bottom face is centred ``offset_m`` from the top-face centre of
  the block below (from the column's position for the bottom block), along that face.
  ``tilt_deg`` is the block's absolute inclination from the vertical as measured on
  site, leaning toward ``tilt_azimuth_deg`` (clockwise from North).  With
  ``tilt_mode`` "wedge" (default) the joint under a tilted block is cut parallel to
  the face it stands on, so the block stands out of plumb in equilibrium; with "edge"
  its bottom face stays square to its axis and it rests on the edge it leans toward
  (released rocking: the Housner check's initial condition).  Mass properties are
  those of the untilted solid (the wedge is second order in the tilt).
- Contact area: where two blocks meet, the contact area is the overlap of the upper
  block's bottom face and the lower block's top face.  The upper block's bottom rim
  contact points lie on the outline of that area: its own rim when its face fits in
  the face below (a drum on a wider base), the face below's rim when that fits in its
  own (a wide capital on a narrower shaft), else the outline of the overlap (offset
  drums).  The lower block's top plate covers its whole top face plus one contact
  sphere radius, hence always the contact area.
- Statics: the stack of bodies k.. starts rocking on its contact area when the
  horizontal acceleration exceeds g x (horizontal distance from the rocking edge to
  the stack's centre of mass) / (height of that centre of mass above the edge); the
  column's threshold is the smallest over all joints (for one cylinder d/h).

Mass, centre of mass and principal inertia are exact for each block (closed forms);
bodies of several joined blocks combine them with the parallel-axis theorem.
"""
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from pipeline.constants import MODEL_GRAVITY
from pipeline.files import InputError
from pipeline.scenario.mesh import MESH_SUFFIXES, MeshSpecimen
from pipeline.scenario.outline import Outline, _edge_distances, contact_outline, perimeter_points
from pipeline.userfiles import MAX_INT_DIGITS, MAX_NESTING, read_text
from pipeline.userfiles import Unreadable as _Unreadable
from pipeline.userfiles import json_int as _json_int
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import nesting as _nesting
from pipeline.userfiles import show as _show

SHAPES = ("frustum", "box")
TILT_MODES = ("wedge", "edge")
EXAMPLES_DIR = Path(__file__).with_name("columns")
# plausibility limits of a column file ("absurd values" are rejected with one line)
MIN_SIZE_M = 0.02            # a block must hold its rims of contact spheres (4 radii)
MAX_BLOCK_HEIGHT_M = 30.0
MAX_WIDTH_M = 10.0
MAX_COLUMN_HEIGHT_M = 40.0
MAX_BLOCKS = 60
DENSITY_RANGE = (100.0, 25000.0)
MAX_TILT_DEG = 30.0
MAX_OFFSET_M = 2.0
TOP_KEYS = {"name", "density", "blocks", "source", "notes"}
BLOCK_KEYS = {"frustum": {"height", "bottom_diameter", "top_diameter"},
              "box": {"height", "width", "depth"}}
OPTIONAL_BLOCK_KEYS = {"shape", "density", "name", "offset_m", "tilt_deg", "tilt_azimuth_deg",
                       "tilt_mode", "joined", "notes"}


# ---------------------------------------------------------------- solids
@dataclass(frozen=True)
class Frustum:
    """Truncated cone (a cylinder when both diameters are equal), axis along z, bottom
    face at z = 0."""
    height: float
    bottom_diameter: float
    top_diameter: float
    shape = "frustum"

    @property
    def cylinder(self):
        return self.bottom_diameter == self.top_diameter

    def mass_properties(self, density):
        """(mass kg, centroid height above the bottom face m, (Ixx, Iyy, Izz) kg m^2 about
        the centroid, principal).  Closed forms for a solid frustum of radii a (bottom),
        b (top) and height h; the cylinder's are written as the scene always had them."""
        h = self.height
        if self.cylinder:
            r = self.bottom_diameter / 2
            m = density * math.pi * r ** 2 * h
            return m, h / 2, (m * (3 * r * r + h * h) / 12,) * 2 + (m * r * r / 2,)
        a, b = self.bottom_diameter / 2, self.top_diameter / 2
        s2 = a * a + a * b + b * b
        s4 = a ** 4 + a ** 3 * b + a * a * b * b + a * b ** 3 + b ** 4
        m = density * math.pi * h * s2 / 3
        zc = h * (a * a + 2 * a * b + 3 * b * b) / (4 * s2)
        izz = 3 * m * s4 / (10 * s2)
        # about the bottom face's diameter: sum of thin discs (rho^4 / 4 + z^2 rho^2) pi dz
        ixx_base = density * math.pi * (h * s4 / 20 + h ** 3 * (a * a + 3 * a * b + 6 * b * b) / 30)
        ixx = ixx_base - m * zc * zc
        return m, zc, (ixx, ixx, izz)

    def outline(self, face):
        """The bottom or top face's outline (an :class:`Outline` centred on the axis)."""
        d = self.bottom_diameter if face == "bottom" else self.top_diameter
        return Outline.circle(d / 2)

    def to_dict(self):
        return {"shape": "frustum", "height": self.height,
                "bottom_diameter": self.bottom_diameter, "top_diameter": self.top_diameter}


@dataclass(frozen=True)
class Box:
    """Rectangular block: width along East (x), depth along North (y), bottom at z = 0."""
    height: float
    width: float
    depth: float
    shape = "box"

    def mass_properties(self, density):
        w, d, h = self.width, self.depth, self.height
        m = density * w * d * h
        return m, h / 2, (m * (d * d + h * h) / 12, m * (w * w + h * h) / 12,
                          m * (w * w + d * d) / 12)

    def outline(self, face):
        return Outline.rectangle(self.width, self.depth)

    def to_dict(self):
        return {"shape": "box", "height": self.height, "width": self.width,
                "depth": self.depth}


# ---------------------------------------------------------------- the description
@dataclass(frozen=True)
class ColumnBlock:
    """One block of a column description (see the module docstring)."""
    solid: object                      # Frustum or Box
    density: float = None              # kg/m^3; None: the column's
    name: str = None
    offset_m: tuple = (0.0, 0.0)       # east, north (m)
    tilt_deg: float = 0.0
    tilt_azimuth_deg: float = 0.0
    tilt_mode: str = "wedge"
    joined: bool = False

    def rotation(self):
        """World rotation (3 x 3) of a block inclined by tilt_deg toward tilt_azimuth_deg."""
        if self.tilt_deg == 0:
            return np.eye(3)
        th, az = math.radians(self.tilt_deg), math.radians(self.tilt_azimuth_deg)
        return _rotation_about(np.array([-math.cos(az), math.sin(az), 0.0]), th)

    def to_dict(self):
        out = self.solid.to_dict()
        if self.density is not None:
            out["density"] = self.density
        if self.name is not None:
            out["name"] = self.name
        if tuple(self.offset_m) != (0.0, 0.0):
            out["offset_m"] = list(self.offset_m)
        if self.tilt_deg:
            out.update(tilt_deg=self.tilt_deg, tilt_azimuth_deg=self.tilt_azimuth_deg)
            if self.tilt_mode != "wedge":
                out["tilt_mode"] = self.tilt_mode
        if self.joined:
            out["joined"] = True
        return out


def _rotation_about(axis, angle):
    """Rotation matrix of ``angle`` (rad) about the unit vector ``axis`` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


@dataclass(frozen=True)
class ColumnGeometry:
    """A column: blocks from the bottom, a density (kg/m^3) for blocks without their own.

    ``edge_rims``: contact spheres on the rims other than the base (they let a falling
    body strike the pedestal; the verification block has none); ``settles``: whether the
    scene may stop early once no stack holds the energy to tip over."""
    name: str
    density: float
    blocks: tuple
    source: str = None
    notes: str = None
    edge_rims: bool = field(default=True, compare=False)
    settles: bool = field(default=True, compare=False)

    # ------------------------------------------------------------ the paper's columns
    @classmethod
    def drums(cls, height, diameter, n_drums, density, name="drums"):
        """The paper's drum column: n equal cylindrical drums."""
        drum = Frustum(height / n_drums, diameter, diameter)
        return cls(name, density, tuple(ColumnBlock(drum) for _ in range(int(n_drums))))

    @classmethod
    def monolith(cls, height, diameter, density, name="monolithic"):
        """The paper's monolithic column: one cylinder."""
        return cls(name, density, (ColumnBlock(Frustum(height, diameter, diameter)),))

    @classmethod
    def block(cls, height, width, depth, density, theta0_rad=0.0):
        """The verification block: a box released from a tilt theta0 about its East
        (theta0 > 0) or West bottom edge, without top rim and never settling early."""
        tilt = ColumnBlock(Box(height, width, depth), tilt_deg=math.degrees(abs(theta0_rad)),
                           tilt_azimuth_deg=90.0 if theta0_rad >= 0 else 270.0,
                           tilt_mode="edge")
        return cls("block", density, (tilt,), edge_rims=False, settles=False)

    def monolithic(self):
        """A monolith of the same outline: every block joined to the one below (the
        bottom block's tilt applies to the whole stone; the others' tilts are dropped)."""
        blocks = [self.blocks[0]] + [replace(b, joined=True, tilt_deg=0.0) for b in
                                     self.blocks[1:]]
        return replace(self, name=f"{self.name} (monolith)", blocks=tuple(blocks))

    # ------------------------------------------------------------ file format
    @classmethod
    def load(cls, name_or_path):
        """A description from a shipped example's name (``doric-peristyle``) or a file
        (.json; .yaml/.yml with PyYAML), a column's or a mesh specimen's (a "mesh" key;
        a bare mesh file too: :mod:`pipeline.scenario.mesh`).  Whatever the file holds, a problem is one
        InputError naming the file (and the line and column where the parser knows them):
        files over MAX_FILE_BYTES are refused unread, and nesting beyond MAX_NESTING,
        integers over MAX_INT_DIGITS digits and YAML tags other than the standard ones
        are refused while parsing."""
        text = str(name_or_path)
        path = Path(text)
        shipped = EXAMPLES_DIR / f"{text}.json"
        try:
            if path.suffix == "" and "/" not in text and shipped.is_file():
                path = shipped
            found = path.is_file()
        except (OSError, ValueError):              # a name too long, a NUL byte
            found = False
        if found and path.suffix.lower() in MESH_SUFFIXES:
            return MeshSpecimen.load(path)
        if not found:
            known = ", ".join(example_names())
            shown = text if text.isprintable() and len(text) <= 300 else _show(text)
            raise InputError(f"--column-file {shown}: no such file or shipped example "
                             f"(shipped: {known})")
        yaml_file = path.suffix.lower() in (".yaml", ".yml")
        if yaml_file:
            try:
                import yaml  # noqa: F401
            except ImportError:
                raise InputError(f"{path}: reading YAML needs PyYAML (pip install pyyaml); "
                                 "or give the description as JSON") from None
        try:
            try:
                raw = read_text(path)
            except _Unreadable as exc:
                raise _Unreadable(f"{exc}; a column description is a few kB"
                                  if exc.kind == "size" else f"not UTF-8 text: {exc}") from None
            data = _parse_yaml(raw) if yaml_file else _parse_json(raw)
            if _nesting(data, MAX_NESTING) > MAX_NESTING:
                raise _Unreadable(f"nested more than {MAX_NESTING} levels deep (or refers "
                                  "to itself)")
        except OSError as exc:
            raise InputError(f"{path}: not a readable column description ("
                             f"{_one_line(exc.strerror or exc)})") from None
        except _Unreadable as exc:
            raise InputError(f"{path}: not a readable column description ({exc})") from None
        if isinstance(data, dict) and "mesh" in data:     # a mesh specimen's description
            return MeshSpecimen.from_dict(data, where=path.name, base=path.resolve().parent)
        return cls.from_dict(data, where=str(path.name))

    @classmethod
    def from_dict(cls, data, where="column description"):
        """Validate a description dict; InputError with one line naming the problem.
        A dict with a "mesh" key describes a mesh specimen (:mod:`pipeline.scenario.mesh`)."""
        if isinstance(data, dict) and "mesh" in data:
            return MeshSpecimen.from_dict(data, where=where)
        if not isinstance(data, dict):
            raise InputError(f"{where}: expected a JSON object with name, density, blocks")
        _check_keys(data, where)
        unknown = set(data) - TOP_KEYS
        if unknown:
            raise InputError(f"{where}: unknown key(s) {_keys(unknown)} "
                             f"(allowed: {', '.join(sorted(TOP_KEYS))})")
        for key in ("name", "density", "blocks"):
            if key not in data:
                raise InputError(f"{where}: missing key '{key}'")
        name = data["name"]
        if not isinstance(name, str) or not name.strip() or len(name) > 80:
            raise InputError(f"{where}: 'name' must be a non-empty string (at most 80 "
                             "characters)")
        density = _number(data["density"], f"{where}: density", *DENSITY_RANGE, "kg/m^3")
        blocks = data["blocks"]
        if not isinstance(blocks, list) or not blocks:
            raise InputError(f"{where}: 'blocks' must be a non-empty list, from the bottom")
        if len(blocks) > MAX_BLOCKS:
            raise InputError(f"{where}: {len(blocks)} blocks, at most {MAX_BLOCKS}")
        parsed = tuple(_parse_block(b, f"{where}: blocks[{k}]", k) for k, b in enumerate(blocks))
        for key in ("source", "notes"):
            if data.get(key) is not None and not isinstance(data[key], str):
                raise InputError(f"{where}: '{key}' must be a string")
        geometry = cls(name.strip(), density, parsed, data.get("source"), data.get("notes"))
        height = geometry.height
        if height > MAX_COLUMN_HEIGHT_M:
            raise InputError(f"{where}: the column is {height:g} m high, at most "
                             f"{MAX_COLUMN_HEIGHT_M:g} m")
        try:
            geometry.check()
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        return geometry

    def to_dict(self):
        out = {"name": self.name, "density": self.density,
               "blocks": [b.to_dict() for b in self.blocks]}
        for key in ("source", "notes"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        return out

    # ------------------------------------------------------------ derived
    @property
    def height(self):
        """Sum of the block heights (m)."""
        return math.fsum(b.solid.height for b in self.blocks)

    @property
    def base_width(self):
        """Width (m) of the bottom block's bottom face (diameter, or the smaller side)."""
        s = self.blocks[0].solid
        return s.bottom_diameter if s.shape == "frustum" else min(s.width, s.depth)

    def bodies(self, x=0.0, y=0.0):
        """The rigid bodies of the column standing at (x, y) on the pedestal, bottom up:
        list of :class:`Body` (placement, mass properties, rims, plate)."""
        return _build(self, x, y)

    def check(self):
        """Raise InputError unless every stack of bodies stands by itself."""
        statics = self.statics()
        bodies = self.bodies()
        for joint in statics:
            if joint["ratio"] <= 0 and not bodies[joint["body"]].edge_mode:
                raise InputError(f"the centre of mass of blocks {joint['from_block']}.. lies "
                                 "outside their contact area: the column as described "
                                 "cannot stand")
        return statics

    def statics(self, g=MODEL_GRAVITY):
        """Per joint (body k on what is below it): ``ratio`` = rocking threshold / g
        (``lever_m``, the horizontal distance from the rocking edge to the centre of mass
        of bodies k.., over its height above that edge; 0 for a block released on its
        edge) and
        ``barrier_j``, the smallest energy that tips that stack over its edge."""
        return _statics(self.bodies(), g)

    def uplift_ratio(self):
        """Smallest rocking threshold of any stack / g (tan alpha of a single block)."""
        return min(j["ratio"] for j in self.statics())

    def overturning_barrier(self, g=MODEL_GRAVITY):
        """Smallest energy (J) that tips any stack of bodies over its edge."""
        return min(j["barrier_j"] for j in self.statics(g))

    def contact_rocking_hz(self, kn, rim_points=16):
        """Frequency (Hz) of the whole column, as one stone, rocking on the contact springs
        of its base (kn N/m per contact point): sqrt(kn sum(x_i^2) / I_base) / 2 pi, the
        smaller about the two horizontal axes.  Rigid-block behaviour needs it well above
        the frequencies of the shaking (the paper's column: 13.5 Hz)."""
        (body,) = self.monolithic().bodies()
        contact = body.contact
        if contact.kind == "circle":
            pts = contact.radius * np.array([[math.cos(a), math.sin(a)] for a in
                                             2 * np.pi * np.arange(rim_points) / rim_points])
            pts = pts + contact.centre
        else:
            pts = perimeter_points(contact.polygon(), rim_points)
        pts = pts - pts.mean(axis=0)
        out = []
        for axis, other in ((0, 1), (1, 0)):
            inertia = body.inertia[other, other] + body.mass * body.com[2] ** 2
            out.append(math.sqrt(kn * (pts[:, axis] ** 2).sum() / inertia) / (2 * math.pi))
        return min(out)


def _number(value, what, low, high, unit, low_open=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            (isinstance(value, float) and not math.isfinite(value)):
        raise InputError(f"{what} must be a finite number, got {_show(value)}")
    if (value <= low if low_open else value < low) or value > high:   # exact for any int
        bracket = "(" if low_open else "["
        raise InputError(f"{what} {_g(value)} outside the plausible range {bracket}{low:g}, "
                         f"{high:g}] {unit}".rstrip())
    return float(value)


def _g(number):
    """A number from a file as ``{:g}`` formats it (a short repr beyond a float's range)."""
    try:
        return f"{float(number):g}"
    except OverflowError:
        return _show(number)


def _one_line(text, most=200):
    """``text`` as one line of at most ``most`` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= most else text[:most - 3] + "..."


def _check_keys(mapping, where):
    for key in mapping:
        if not isinstance(key, str):
            raise InputError(f"{where}: keys must be strings, got {_show(key)}")


def _parse_json(text):
    try:
        return json.loads(text, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise _Unreadable(f"line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
    except RecursionError:
        raise _Unreadable(f"nested more than {MAX_NESTING} levels deep") from None
    except ValueError as exc:
        raise _Unreadable(_one_line(exc)) from None


_YAML_LOADER = None


def _yaml_loader():
    """PyYAML's SafeLoader (standard tags only) that refuses long integers and reports a
    standard tag's bad value (``!!bool maybe``, a 13th month) at its line and column."""
    global _YAML_LOADER
    if _YAML_LOADER is None:
        import yaml
        from yaml.constructor import ConstructorError

        class Loader(yaml.SafeLoader):
            def construct_object(self, node, deep=False):
                try:
                    return super().construct_object(node, deep)
                except (yaml.YAMLError, RecursionError):
                    raise
                except Exception as exc:         # the standard tags' own constructors
                    value = f"{node.value!r:.40} " if isinstance(node, yaml.ScalarNode) else ""
                    raise ConstructorError(None, None, f"cannot read {value}as "
                                           f"{node.tag.rpartition(':')[2]} ({exc})",
                                           node.start_mark) from None

            def construct_yaml_int(self, node):
                digits = len(str(node.value).lstrip("+-"))
                if digits > MAX_INT_DIGITS:
                    raise ConstructorError(None, None, f"an integer of {digits} digits (at "
                                           f"most {MAX_INT_DIGITS})", node.start_mark)
                return super().construct_yaml_int(node)

        Loader.add_constructor("tag:yaml.org,2002:int", Loader.construct_yaml_int)
        _YAML_LOADER = Loader
    return _YAML_LOADER


def _parse_yaml(text):
    import yaml
    try:
        return yaml.load(text, Loader=_yaml_loader())
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        at = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = ", ".join(p for p in (exc.context, exc.problem) if p)
        raise _Unreadable(_one_line(at + (problem or "not YAML"))) from None
    except yaml.YAMLError as exc:                # e.g. a control character
        raise _Unreadable(_one_line(exc)) from None
    except RecursionError:
        raise _Unreadable(f"nested more than {MAX_NESTING} levels deep") from None


def _parse_block(raw, where, index):
    if not isinstance(raw, dict):
        raise InputError(f"{where}: expected an object with shape and sizes")
    _check_keys(raw, where)
    shape = raw.get("shape")
    if shape is None:
        raise InputError(f"{where}: missing key 'shape' (one of {', '.join(SHAPES)})")
    if shape not in SHAPES:
        raise InputError(f"{where}: unknown shape {_show(shape)} (known: {', '.join(SHAPES)})")
    missing = sorted(BLOCK_KEYS[shape] - set(raw))
    if missing:
        raise InputError(f"{where}: missing key(s) {', '.join(missing)} for a {shape}")
    unknown = set(raw) - BLOCK_KEYS[shape] - OPTIONAL_BLOCK_KEYS
    if unknown:
        raise InputError(f"{where}: unknown key(s) {_keys(unknown)} for a {shape}")
    sizes = {}
    for key in sorted(BLOCK_KEYS[shape]):
        value = raw[key]
        if isinstance(value, (int, float)) and not isinstance(value, bool) and \
                (isinstance(value, int) or math.isfinite(value)) and value <= 0:
            raise InputError(f"{where}: {key} must be positive, got {_g(value)}")
        high = MAX_BLOCK_HEIGHT_M if key == "height" else MAX_WIDTH_M
        sizes[key] = _number(value, f"{where}: {key}", MIN_SIZE_M, high, "m")
    solid = Frustum(**sizes) if shape == "frustum" else Box(**sizes)
    density = None if raw.get("density") is None else _number(
        raw["density"], f"{where}: density", *DENSITY_RANGE, "kg/m^3")
    offset = raw.get("offset_m", [0.0, 0.0])
    if not (isinstance(offset, (list, tuple)) and len(offset) == 2):
        raise InputError(f"{where}: offset_m must be [east, north] in metres")
    offset = tuple(_number(v, f"{where}: offset_m", -MAX_OFFSET_M, MAX_OFFSET_M, "m")
                   for v in offset)
    tilt = _number(raw.get("tilt_deg", 0.0), f"{where}: tilt_deg", 0.0, MAX_TILT_DEG, "deg")
    azimuth = _number(raw.get("tilt_azimuth_deg", 0.0), f"{where}: tilt_azimuth_deg", 0.0,
                      360.0, "deg") % 360.0
    mode = raw.get("tilt_mode", "wedge")
    if mode not in TILT_MODES:
        raise InputError(f"{where}: tilt_mode must be one of {', '.join(TILT_MODES)}, "
                         f"got {_show(mode)}")
    joined = raw.get("joined", False)
    if not isinstance(joined, bool):
        raise InputError(f"{where}: joined must be true or false")
    if joined and index == 0:
        raise InputError(f"{where}: the bottom block cannot be joined to a block below")
    if joined and tilt:
        raise InputError(f"{where}: a joined block shares the tilt of the stone it is "
                         "carved with; give tilt_deg on that stone's first block")
    name = raw.get("name")
    if name is not None and not isinstance(name, str):
        raise InputError(f"{where}: name must be a string")
    return ColumnBlock(solid, density, name, offset, tilt, azimuth, mode, joined)


def example_names():
    """Names of the shipped column descriptions."""
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.json"))


# ---------------------------------------------------------------- bodies
@dataclass
class Part:
    """One block inside a body, in the body's base frame (origin at the body's bottom
    face centre, axes of its bottom block)."""
    block: ColumnBlock
    index: int                     # index of the block in the description
    bottom: np.ndarray             # bottom face centre (3,)
    mass: float
    centroid: np.ndarray           # (3,)
    inertia: tuple                 # principal, about its centroid, base-frame axes


@dataclass
class Body:
    """A rigid body of the scene: one block, or several joined blocks."""
    index: int
    parts: list
    mass: float
    com: np.ndarray                # in the base frame
    inertia: np.ndarray            # 3 x 3 about the COM, base-frame axes
    rotation: np.ndarray           # world rotation of the base frame
    base_world: np.ndarray         # world position of the bottom face centre
    contact: Outline               # contact area outline, base frame (x, y)
    support_rotation: np.ndarray   # world rotation of the plane it stands on
    edge_mode: bool
    rims: list = field(default_factory=list)

    @property
    def centre(self):
        return self.base_world + self.rotation @ self.com

    @property
    def top(self):
        """Top face centre of the top part (base frame) and its outline (centred at 0)."""
        p = self.parts[-1]
        return p.bottom + np.array([0.0, 0.0, p.block.solid.height]), \
            p.block.solid.outline("top")

    @property
    def name(self):
        names = [p.block.name for p in self.parts if p.block.name]
        if len(names) > 3:
            return f"{names[0]} .. {names[-1]}"
        return " + ".join(names) if names else None


def _build(geometry, x, y):
    bodies = []
    for k, block in enumerate(geometry.blocks):
        density = geometry.density if block.density is None else block.density
        m, zc, inertia = block.solid.mass_properties(density)
        offset = np.array([block.offset_m[0], block.offset_m[1], 0.0])
        if block.joined:
            body = bodies[-1]
            bottom = body.top[0] + offset
            body.parts.append(Part(block, k, bottom, m, bottom + np.array([0.0, 0.0, zc]),
                                   inertia))
            _finish(body)
            continue
        if bodies:                                   # stands on the top face below
            below = bodies[-1]
            top, support_face = below.top
            support_origin = below.base_world + below.rotation @ top
            support_rot = below.rotation
        else:                                        # on the pedestal (unlimited)
            support_origin, support_rot, support_face = np.array([x, y, 0.0]), np.eye(3), None
        R = block.rotation()
        Q = support_rot.T @ R                        # relative to the face it stands on
        own = block.solid.outline("bottom")
        try:
            contact = contact_outline(support_face, own.shifted(*block.offset_m))
        except InputError as exc:
            raise InputError(f"blocks[{k}] on the block below: {exc}") from None
        contact = contact.shifted(-block.offset_m[0], -block.offset_m[1])
        c = offset
        edge_mode = block.tilt_mode == "edge" and block.tilt_deg > 0
        if edge_mode:                                # pivot about the lowest edge point
            pivot = _lowest_point(own, Q)
            c = offset + (pivot - Q @ pivot)
        base_world = support_origin + support_rot @ c
        part = Part(block, k, np.zeros(3), m, np.array([0.0, 0.0, zc]), inertia)
        bodies.append(Body(len(bodies), [part], m, part.centroid, np.diag(inertia), R,
                           base_world, contact, support_rot, edge_mode))
    for body in bodies:
        body.rims = _rims(body, geometry.edge_rims)
    return bodies


def _finish(body):
    """Mass, centre of mass and inertia tensor of a body from its parts."""
    if len(body.parts) == 1:
        p = body.parts[0]
        body.mass, body.com, body.inertia = p.mass, p.centroid, np.diag(p.inertia)
        return
    masses = np.array([p.mass for p in body.parts])
    body.mass = math.fsum(masses)
    body.com = (masses[:, None] * np.array([p.centroid for p in body.parts])).sum(0) / body.mass
    tensor = np.zeros((3, 3))
    for p in body.parts:
        d = p.centroid - body.com
        tensor += np.diag(p.inertia) + p.mass * (d @ d * np.eye(3) - np.outer(d, d))
    body.inertia = tensor


def _lowest_point(outline, Q):
    """Point (3,) of a bottom outline (base frame, z = 0) lowest after rotation Q (ties:
    their mean, e.g. the midpoint of an edge)."""
    grad = Q[2, :2]
    if outline.kind == "circle":
        n = np.hypot(*grad)
        u = -grad / n if n > 0 else np.zeros(2)
        return np.array([outline.centre[0] + outline.radius * u[0],
                         outline.centre[1] + outline.radius * u[1], 0.0])
    v = outline.polygon()
    height = v @ grad
    lowest = v[height <= height.min() + 1e-12 * max(1.0, np.abs(v).max())]
    return np.append(lowest.mean(axis=0), 0.0)


def _rims(body, edge_rims):
    """Rims of contact spheres (base frame, z of the face, outline, normal into the body):
    the base rim on the contact area (role "base"), then unless ``edge_rims`` is False
    the body's other outer edges (role "edge"): its own bottom outline when it differs
    from the contact area, steps between joined parts, and the top face."""
    wedge = np.eye(3) if body.edge_mode else body.rotation.T @ body.support_rotation
    normal = wedge[:, 2]                     # support plane normal in the base frame
    rims = [{"role": "base", "z": 0.0, "outline": body.contact, "normal": normal}]
    if not edge_rims:
        return rims
    up, down = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    first = body.parts[0]
    own = first.block.solid.outline("bottom").shifted(*first.bottom[:2])
    if not own.same_as(body.contact):
        rims.append({"role": "edge", "z": 0.0, "outline": own, "normal": up})
    for lower, upper in zip(body.parts, body.parts[1:]):
        z = upper.bottom[2]
        top = lower.block.solid.outline("top").shifted(*lower.bottom[:2])
        bottom = upper.block.solid.outline("bottom").shifted(*upper.bottom[:2])
        if top.same_as(bottom):
            continue                          # a continuous side: no edge
        if not top.contains(bottom):
            rims.append({"role": "edge", "z": z, "outline": bottom, "normal": up})
        if not bottom.contains(top):
            rims.append({"role": "edge", "z": z, "outline": top, "normal": down})
    top_centre, top_outline = body.top
    rims.append({"role": "edge", "z": top_centre[2],
                 "outline": top_outline.shifted(*top_centre[:2]), "normal": down})
    return rims


# ---------------------------------------------------------------- statics
def _statics(bodies, g):
    joints = []
    for k, body in enumerate(bodies):
        stack = bodies[k:]
        mass = math.fsum(b.mass for b in stack)
        com = np.array([math.fsum(b.mass * b.centre[i] for b in stack) for i in range(3)]) / mass
        if body.edge_mode:
            joints.append({"body": k, "from_block": body.parts[0].index, "ratio": 0.0,
                           "lever_m": 0.0, "barrier_j": 0.0, "mass_kg": mass,
                           "com_m": com.tolist()})
            continue
        plane_rot = body.support_rotation
        tilted = not np.array_equal(plane_rot, np.eye(3))
        contact = body.contact
        if contact.kind == "circle" and not tilted:
            centre = body.base_world[:2] + np.array(contact.centre)
            d = np.array([contact.radius - math.dist(com[:2], centre)])
            h = np.array([com[2] - body.base_world[2]])
        else:
            # contact area in the world: in the plane through the base centre
            poly = contact.polygon()
            world = body.base_world + np.column_stack(
                [poly, np.zeros(len(poly))]) @ plane_rot.T
            d = _edge_distances(world[:, :2], com[:2])
            h = com[2] - 0.5 * (world[:, 2] + np.roll(world[:, 2], -1))
        ratio = d / h
        barrier = mass * g * (np.hypot(d, h) - h)
        joints.append({"body": k, "from_block": body.parts[0].index,
                       "ratio": float(ratio.min()), "lever_m": float(d.min()),
                       "barrier_j": float(barrier.min()),
                       "mass_kg": mass, "com_m": com.tolist()})
    return joints


# ---------------------------------------------------------------- placed columns
@dataclass(frozen=True)
class ColumnSpec:
    """A column placed on the pedestal: ``name`` (its role in outputs: drums,
    monolithic, block), ``kind`` and position (m)."""
    name: str
    kind: str
    x: float
    y: float
    geometry: ColumnGeometry

    def scene(self, rim_points):
        """The ``params.json`` entry of this column: bodies with placement, mass
        properties, rims and plates (body frames centred on the centre of mass), its
        rocking threshold (``uplift_ratio``), the smallest horizontal distance from a
        rocking edge to the centre of mass of the stack above it (``rocking_lever_m``) and
        the overturning energy barrier."""
        if hasattr(self.geometry, "scene_column"):          # a mesh specimen
            return self.geometry.scene_column(self, rim_points)
        bodies = self.geometry.bodies(self.x, self.y)
        statics = _statics(bodies, MODEL_GRAVITY)
        n = len(bodies)
        # a body released on its edge is not at rest at the start: no energy criterion
        settles = self.geometry.settles and not any(b.edge_mode for b in bodies)
        return {"name": self.name, "kind": self.kind, "x": self.x, "y": self.y,
                "description": self.geometry.name,
                "height": self.geometry.height, "n_bodies": n,
                "uplift_ratio": min(j["ratio"] for j in statics),
                "rocking_lever_m": min(j["lever_m"] for j in statics),
                "overturning_barrier_j": (min(j["barrier_j"] for j in statics)
                                          if settles else None),
                "settles": settles,
                "bodies": [_body_scene(self, b, n, rim_points) for b in bodies]}


def _body_scene(spec, body, n_bodies, rim_points):
    com = body.com
    inertia = body.inertia
    off = inertia - np.diag(np.diag(inertia))
    if np.abs(off).max() > 1e-12 * np.abs(inertia).max():
        _, axes = np.linalg.eigh(inertia)
    else:
        axes = np.eye(3)
    rims = []
    for rim in body.rims:
        o = rim["outline"]
        entry = {"role": rim["role"], "z": rim["z"] - com[2], "normal": list(rim["normal"])}
        if o.kind == "circle":
            entry.update(kind="circle", radius=o.radius,
                         centre=[o.centre[0] - com[0], o.centre[1] - com[1]])
        else:
            v = o.polygon() - com[:2]
            entry.update(kind="polygon", vertices=v.tolist(),
                         points=perimeter_points(v, rim_points).tolist())
        rims.append(entry)
    top, top_outline = body.top
    hx, hy = top_outline.half_extents()
    plate = None
    if body.index < n_bodies - 1:
        plate = {"centre": [top[0] - com[0], top[1] - com[1], top[2] - com[2]],
                 "half_size": [hx, hy]}
    parts = []
    for p in body.parts:
        entry = dict(p.block.solid.to_dict(), block=p.index, name=p.block.name,
                     bottom_centre=[p.bottom[0] - com[0], p.bottom[1] - com[1],
                                    p.bottom[2] - com[2]])
        parts.append(entry)
    centre = body.base_world + body.rotation @ com
    if np.array_equal(body.rotation, np.eye(3)):
        centre = body.base_world + com            # exact sums for an upright body
    shape = parts[0]["shape"] if len(parts) == 1 else "composite"
    return {"name": f"{spec.name}[{body.index}]", "column": spec.name, "index": body.index,
            "block_name": body.name, "blocks": [p.index for p in body.parts],
            "shape": shape, "height": float(top[2]), "mass": body.mass,
            "inertia": inertia.tolist(), "principal_axes": axes.tolist(),
            "centre": centre.tolist(), "rotation": body.rotation.tolist(),
            "column_position": [spec.x, spec.y], "parts": parts, "rims": rims, "plate": plate}
