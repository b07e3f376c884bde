"""A colonnade as it is found: columns standing on one stylobate, epistyle blocks
(architraves) resting on their capitals and, optionally, a frieze course on the
epistyles.  One type, :class:`Colonnade`, which checks itself when it is made; its file
(JSON, YAML optional) is read by :mod:`pipeline.scenario.colonnade_file`; docs/colonnades.md.

Geometry (metres, x East, y North, z up):

- the stylobate is a rectangle: the centre line from ``start`` to ``end`` (x, y) and a
  ``width`` across it; every column's bottom face lies on it;
- a column (:class:`~pipeline.scenario.geometry.ColumnGeometry`) stands with the centre of
  its bottom face at (x, y); its capital is the top face of its top block, where its
  blocks' offsets and tilts put it;
- a beam (an epistyle or a frieze block, :class:`Beam`) is a box of ``length`` along its
  axis, ``width`` across and ``height``: it rests on the top faces of the supports it
  names (capitals for an epistyle, epistyles for a frieze block), all at one level; its
  axis runs from the first support's top-face centre to the last's (a frieze block on one
  epistyle: that epistyle's axis), its centre halfway between them, moved ``shift`` along
  the axis.  Each end of a beam (the middle of its end face's bottom edge) must lie on the
  top face of one of its supports; every support it names must lie under it, and it may
  not rest on one it does not name.

Columns and beams are drawn in plan by their outlines (circles and rectangles of their
faces where their blocks stand); the small tilts of columns as found are ignored in those
outlines and kept in the positions of their capitals.
"""
import enum
import math
from dataclasses import dataclass

import numpy as np

from pipeline.files import InputError
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.outline import Outline, clip_convex

LEVEL_TOLERANCE_M = 0.005     # supports of one beam at one level within this
OVERLAP_AREA_M2 = 1e-6        # plan outlines sharing less than this merely touch
ON_FACE_TOLERANCE_M = 1e-6    # a beam end on the edge of a face rests on it


class Course(enum.Enum):
    """The course a beam belongs to, and what it rests on."""
    EPISTYLE = "epistyle"     # on capitals
    FRIEZE = "frieze"         # on epistyles


@dataclass(frozen=True)
class Stylobate:
    """The platform the columns stand on: centre line ``start`` -> ``end`` (x, y m),
    ``width`` (m) across it."""
    start: tuple
    end: tuple
    width: float

    @property
    def length(self):
        return math.dist(self.start, self.end)

    @property
    def axis(self):
        """Unit vector (x, y) from start to end."""
        return (np.asarray(self.end, float) - self.start) / self.length

    def outline(self):
        """The stylobate in plan (a CCW rectangle)."""
        u = self.axis
        n = np.array([-u[1], u[0]]) * self.width / 2
        s, e = np.asarray(self.start, float), np.asarray(self.end, float)
        return Outline.polygon_of([s - n, e - n, e + n, s + n])


@dataclass(frozen=True)
class PlacedColumn:
    """A column description standing with its bottom face centred at (x, y) m."""
    name: str
    column: ColumnGeometry
    x: float
    y: float

    def bodies(self):
        return self.column.bodies(self.x, self.y)

    def plan_outlines(self):
        """Each block's widest face outline, centred where the block stands (x, y)."""
        out = []
        for body in self.bodies():
            for part in body.parts:
                centre = body.base_world + body.rotation @ part.bottom
                solid = part.block.solid
                face = solid.outline("bottom")
                if solid.shape == "frustum" and solid.top_diameter > solid.bottom_diameter:
                    face = solid.outline("top")
                out.append(face.shifted(centre[0], centre[1]))
        return out

    def capital(self):
        """The top face: :class:`Face` in plan and its height (m)."""
        top = self.bodies()[-1]
        point, outline = top.top
        centre = top.base_world + top.rotation @ point
        x, y, z = (float(v) for v in centre)
        return Face(outline.shifted(x, y), (x, y), None, z)

    @property
    def mass(self):
        """Mass (kg) of the column."""
        return math.fsum(b.mass for b in self.bodies())


@dataclass(frozen=True)
class Face:
    """A horizontal face beams rest on: its plan outline, centre (x, y m), axis (unit
    (x, y) of a beam's length; None for a capital) and height z (m)."""
    outline: Outline
    centre: tuple
    axis: tuple
    z: float


@dataclass(frozen=True)
class Beam:
    """An epistyle or frieze block: a box of ``length``, ``width``, ``height`` (m) and
    ``density`` (kg/m^3) resting on the supports named in ``on``, moved ``shift`` (m)
    along its axis from halfway between its end supports."""
    name: str
    course: Course
    on: tuple
    length: float
    width: float
    height: float
    density: float
    shift: float = 0.0

    @property
    def mass(self):
        """Mass (kg)."""
        return self.length * self.width * self.height * self.density

    @property
    def what(self):
        return f"{self.course.value} {self.name}"


@dataclass(frozen=True)
class Colonnade:
    """Columns on one stylobate with their epistyles and frieze (see the module
    docstring); checked when made: InputError (one line) for a column off the stylobate,
    overlapping columns or beams, a beam longer than the stylobate, an unknown support,
    supports at different levels, a beam end that rests on no support or leaves one, a
    support named that the beam does not reach or one it rests on without naming it, a
    name given twice."""
    name: str
    stylobate: Stylobate
    columns: tuple
    epistyles: tuple
    frieze: tuple = ()
    source: str = None
    notes: str = None

    def __post_init__(self):
        names = [c.name for c in self.columns] + [b.name for b in self.epistyles + self.frieze]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise InputError(f"the name {twice[0]!r} is given twice; columns and beams need "
                             "names of their own")
        self._check_columns()
        self.faces()

    # ------------------------------------------------------------ derived
    def faces(self):
        """Top faces by name: every column's capital and every epistyle's and frieze
        block's top (:class:`Face`); each beam checked on its supports on the way."""
        faces = {c.name: c.capital() for c in self.columns}
        for course, beams in ((Course.EPISTYLE, self.epistyles), (Course.FRIEZE, self.frieze)):
            supports = {name: f for name, f in faces.items()
                        if (name in self._column_names) == (course is Course.EPISTYLE)}
            placed = {b.name: self._place(b, supports) for b in beams}
            _no_overlaps(placed, f"{course.value}s")
            faces.update(placed)
        return faces

    @property
    def _column_names(self):
        return {c.name for c in self.columns}

    @property
    def beam_mass_ratio(self):
        """All epistyles' and frieze blocks' mass over all columns' mass: Makris &
        Vassiliou's gamma when the columns are identical (:mod:`pipeline.rocking.frame`)."""
        beams = math.fsum(b.mass for b in self.epistyles + self.frieze)
        return beams / math.fsum(c.mass for c in self.columns)

    # ------------------------------------------------------------ checks
    def _check_columns(self):
        plate = self.stylobate.outline()
        for column in self.columns:
            base = column.plan_outlines()[0]
            if not plate.contains(base, tol=ON_FACE_TOLERANCE_M):
                raise InputError(f"column {column.name} at ({column.x:g}, {column.y:g}) m "
                                 f"stands off the stylobate ({self.stylobate.length:g} x "
                                 f"{self.stylobate.width:g} m)")
        outlines = {c.name: c.plan_outlines() for c in self.columns}
        names = list(outlines)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                if any(_overlap(p, q) for p in outlines[a] for q in outlines[b]):
                    raise InputError(f"columns {a} and {b} overlap: their blocks share "
                                     "space in plan")

    def _place(self, beam, supports):
        """The top :class:`Face` of ``beam`` resting on its named ``supports``."""
        kind = "capital" if beam.course is Course.EPISTYLE else "epistyle"
        if beam.length > self.stylobate.length:
            raise InputError(f"{beam.what} is {beam.length:g} m long, longer than the "
                             f"stylobate ({self.stylobate.length:g} m)")
        for name in beam.on:
            if name not in supports:
                known = ", ".join(sorted(supports)) or "none"
                raise InputError(f"{beam.what} rests on {name!r}, which is no {kind} of this "
                                 f"colonnade ({kind}s: {known})")
        under = [supports[n] for n in beam.on]
        levels = [f.z for f in under]
        if max(levels) - min(levels) > LEVEL_TOLERANCE_M:
            raise InputError(f"{beam.what}: its {kind}s lie at heights {min(levels):.3f} to "
                             f"{max(levels):.3f} m; a beam rests on supports of one level "
                             f"(within {LEVEL_TOLERANCE_M * 1000:g} mm)")
        first, last = np.asarray(under[0].centre), np.asarray(under[-1].centre)
        if len(under) > 1 and math.dist(first, last) > 0:
            axis = (last - first) / math.dist(first, last)
        elif under[0].axis is not None:
            axis = np.asarray(under[0].axis)
        else:
            raise InputError(f"{beam.what}: its first and last {kind} are one place; an "
                             f"{beam.course.value} spans two {kind}s or more")
        centre = 0.5 * (first + last) + beam.shift * axis
        across = np.array([-axis[1], axis[0]])
        half, side = 0.5 * beam.length * axis, 0.5 * beam.width * across
        footprint = Outline.polygon_of([centre - half - side, centre + half - side,
                                        centre + half + side, centre - half + side])
        for end, sign in (("start", -1.0), ("end", 1.0)):
            _check_end(beam, kind, centre + sign * half, sign * axis, under)
        for name, face in zip(beam.on, under):
            if not _overlap(face.outline, footprint):
                raise InputError(f"{beam.what} does not reach {kind} {name}, which it is "
                                 "said to rest on")
        z = max(levels)
        for name, face in supports.items():
            if name not in beam.on and abs(face.z - z) <= LEVEL_TOLERANCE_M \
                    and _overlap(face.outline, footprint):
                raise InputError(f"{beam.what} also rests on {kind} {name}: name it in "
                                 "'on' or move the beam")
        return Face(footprint, (float(centre[0]), float(centre[1])),
                    (float(axis[0]), float(axis[1])), z + beam.height)


def _check_end(beam, kind, point, outward, under):
    """InputError unless the beam end at ``point`` (x, y) lies on one of the faces
    ``under``; says whether it overhangs the outermost support (``outward``: unit vector
    pointing out of the beam at that end) or falls between supports."""
    if any(_on_face(f.outline, point) for f in under):
        return
    reach = max(float(np.dot(np.asarray(f.centre) - point, outward)) for f in under)
    where = f"({point[0]:.3f}, {point[1]:.3f}) m"
    a_kind = f"{'an' if kind[0] in 'aeiou' else 'a'} {kind}"
    if reach < 0:            # every support centre lies inside: the end overhangs
        raise InputError(f"{beam.what} leaves its {kind}s: its end at {where} lies beyond "
                         f"their top faces (a beam end must rest on {a_kind})")
    raise InputError(f"{beam.what}: its end at {where} rests on no {kind} (a beam end must "
                     f"rest on {a_kind}; it is {beam.length:g} m long)")


def _on_face(outline, point):
    return outline.contains(Outline.circle(0.0, tuple(point)), tol=ON_FACE_TOLERANCE_M)


def _overlap(a, b):
    """Whether two plan outlines share an area (touching is not overlapping)."""
    if a.kind == b.kind == "circle":
        return math.dist(a.centre, b.centre) < a.radius + b.radius - 1e-9
    if not _bounds_meet(a, b):
        return False
    shared = clip_convex(a.polygon(), b.polygon())
    return len(shared) >= 3 and Outline.polygon_of(shared).area() > OVERLAP_AREA_M2


def _bounds_meet(a, b):
    pa, pb = a.polygon(64), b.polygon(64)
    return bool(np.all(pa.min(0) <= pb.max(0)) and np.all(pb.min(0) <= pa.max(0)))


def _no_overlaps(placed, what):
    names = list(placed)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if _overlap(placed[a].outline, placed[b].outline):
                raise InputError(f"{what} {a} and {b} overlap in plan")
