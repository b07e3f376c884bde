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

The file format: :mod:`pipeline.scenario.column_format`; solids:
:mod:`pipeline.scenario.solids`; bodies, statics and placed columns:
:mod:`pipeline.scenario.bodies`.
"""
import math
from dataclasses import dataclass, field, replace

import numpy as np

from pipeline.constants import MODEL_GRAVITY, RIM_POINTS
from pipeline.files import InputError
from pipeline.scenario.bodies import _build, _statics, column_scene
from pipeline.scenario.column_format import (DENSITY_RANGE, EXAMPLES_DIR, MAX_BLOCKS,
                                             MAX_COLUMN_HEIGHT_M, TOP_KEYS, _check_keys, _number,
                                             _one_line, _parse_block, _parse_json, _parse_yaml,
                                             example_names, shipped_or_file)
from pipeline.scenario.mesh import MESH_SUFFIXES, MeshSpecimen
from pipeline.scenario.outline import perimeter_points
from pipeline.scenario.solids import Box, ColumnBlock, Frustum
from pipeline.scenario.specimen import Specimen
from pipeline.userfiles import MAX_NESTING, read_text
from pipeline.userfiles import Unreadable as _Unreadable
from pipeline.userfiles import keys_text as _keys
from pipeline.userfiles import nesting as _nesting


@dataclass(frozen=True)
class ColumnGeometry(Specimen):
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
        path, found, shown = shipped_or_file(name_or_path, EXAMPLES_DIR)
        if found and path.suffix.lower() in MESH_SUFFIXES:
            return MeshSpecimen.load(path)
        if not found:
            known = ", ".join(example_names())
            raise InputError(f"--column-file {shown}: no such file or shipped example "
                             f"(shipped: {known})")
        yaml_file = path.suffix.lower() in (".yaml", ".yml")
        if yaml_file:
            try:
                import yaml  # noqa: F401  # lazy: PyYAML, optional (YAML column files only)
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
        return self._described({"name": self.name, "density": self.density,
                                "blocks": [b.to_dict() for b in self.blocks]})

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

    def scene_column(self, spec, rim_points):
        return column_scene(self, spec, rim_points)

    def check_rims(self, rim_sphere_radius):
        for k, block in enumerate(self.blocks):
            s = block.solid
            sizes = [s.height] + ([s.bottom_diameter, s.top_diameter] if s.shape == "frustum"
                                  else [s.width, s.depth])
            if min(sizes) < 4 * rim_sphere_radius:
                raise InputError(f"{self.name}: block {k} is {min(sizes):g} m thin, less "
                                 f"than 4 contact sphere radii ({rim_sphere_radius:g} m)")

    def contact_rocking_hz(self, kn, rim_points=RIM_POINTS):
        """Frequency (Hz) of the whole column, as one stone, rocking on the contact springs
        of its base (kn N/m per contact point): sqrt(kn sum(x_i^2) / I_base) / 2 pi, the
        smaller about the two horizontal axes.  Rigid-block behaviour needs it well above
        the frequencies of the shaking (the paper's column:
        :func:`pipeline.campaign.column_file.paper_rocking_hz`)."""
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
