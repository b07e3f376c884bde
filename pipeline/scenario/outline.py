"""Convex outlines in a plane (2-D, counter-clockwise): circles and polygons, their
clipping (the contact area of two faces) and contact points along them.  Metres."""
import math
from dataclasses import dataclass, replace

import numpy as np

from pipeline.files import InputError

CIRCLE_SEGMENTS = 720        # polygon of a circle for overlaps and tilted statics
CORNER_TURN_DEG = 20.0       # polygon vertices turning more than this are corners
TOLERANCE_M = 1e-9


@dataclass(frozen=True)
class Outline:
    """A convex face outline in a plane: a circle (radius, centre) or a polygon (CCW
    vertices).  Coordinates in metres."""
    kind: str
    radius: float = 0.0
    centre: tuple = (0.0, 0.0)
    vertices: tuple = ()

    @classmethod
    def circle(cls, radius, centre=(0.0, 0.0)):
        return cls("circle", radius=radius, centre=tuple(centre))

    @classmethod
    def rectangle(cls, width, depth, centre=(0.0, 0.0)):
        cx, cy = centre
        w, d = width / 2, depth / 2
        return cls("polygon", vertices=((cx - w, cy - d), (cx + w, cy - d), (cx + w, cy + d),
                                        (cx - w, cy + d)))

    @classmethod
    def polygon_of(cls, points):
        return cls("polygon", vertices=tuple((float(x), float(y)) for x, y in points))

    def shifted(self, dx, dy):
        if dx == 0 and dy == 0:
            return self
        if self.kind == "circle":
            return replace(self, centre=(self.centre[0] + dx, self.centre[1] + dy))
        return replace(self, vertices=tuple((x + dx, y + dy) for x, y in self.vertices))

    def polygon(self, segments=CIRCLE_SEGMENTS):
        """Vertices (n x 2), CCW; a circle as a regular polygon inscribed in it."""
        if self.kind == "polygon":
            return np.array(self.vertices, float)
        ang = 2 * np.pi * np.arange(segments) / segments
        return np.column_stack([self.centre[0] + self.radius * np.cos(ang),
                                self.centre[1] + self.radius * np.sin(ang)])

    def contains(self, other, tol=TOLERANCE_M):
        """True when ``other`` lies inside this outline (boundaries may touch)."""
        if self.kind == "circle":
            if other.kind == "circle":
                return math.dist(self.centre, other.centre) + other.radius <= self.radius + tol
            return bool(np.all(np.hypot(*(other.polygon() - self.centre).T) <= self.radius + tol))
        if other.kind == "circle":
            return bool(_edge_distances(self.polygon(), other.centre).min() >= other.radius - tol)
        return all(_edge_distances(self.polygon(), p).min() >= -tol for p in other.polygon())

    def same_as(self, other, tol=TOLERANCE_M):
        return self.contains(other, tol) and other.contains(self, tol)

    def area(self):
        if self.kind == "circle":
            return math.pi * self.radius ** 2
        x, y = self.polygon().T
        return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    def half_extents(self, about=(0.0, 0.0)):
        """Half sizes (x, y) of the smallest rectangle centred at ``about`` holding it."""
        if self.kind == "circle":
            return (abs(self.centre[0] - about[0]) + self.radius,
                    abs(self.centre[1] - about[1]) + self.radius)
        v = self.polygon() - about
        return tuple(float(a) for a in np.abs(v).max(axis=0))

    def to_dict(self):
        if self.kind == "circle":
            return {"kind": "circle", "radius": self.radius, "centre": list(self.centre)}
        return {"kind": "polygon", "vertices": [list(v) for v in self.vertices]}


def _edge_distances(poly, point):
    """Signed distances (positive inside) from ``point`` to the edge lines of a CCW
    convex polygon."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    edge = b - a
    normal = np.column_stack([-edge[:, 1], edge[:, 0]]) / np.hypot(*edge.T)[:, None]
    return ((np.asarray(point, float) - a) * normal).sum(axis=1)


def _inside(edge, a, p):
    """True where points p (n x 2) lie left of (or on) the directed edge from a."""
    return edge[0] * (p[:, 1] - a[1]) - edge[1] * (p[:, 0] - a[0]) >= -1e-15


def _crossing(edge, a, p, q):
    """Where segments p-q (n x 2 each) cross the line of the edge from a."""
    d = q - p
    t = (edge[1] * (p[:, 0] - a[0]) - edge[0] * (p[:, 1] - a[1])) / \
        (edge[0] * d[:, 1] - edge[1] * d[:, 0])
    return p + t[:, None] * d


def clip_convex(subject, clipper):
    """Intersection of two convex CCW polygons (Sutherland-Hodgman), n x 2 (may be empty).
    Each clipper edge keeps, for every subject edge p-q in order, the crossing where the
    edge leaves or enters the half-plane, then q when q is inside."""
    out = np.asarray(subject, float).reshape(-1, 2)
    clipper = np.asarray(clipper, float)
    for a, b in zip(clipper, np.roll(clipper, -1, axis=0)):
        if not len(out):
            break
        edge = b - a
        p_in = _inside(edge, a, out)
        if p_in.all():              # nothing cut: the points, starting one further on
            out = np.roll(out, -1, axis=0)
            continue
        q = np.roll(out, -1, axis=0)
        q_in = np.roll(p_in, -1)
        cross = p_in != q_in
        points = np.stack([np.zeros_like(out), q], axis=1)
        if cross.any():
            points[cross, 0] = _crossing(edge, a, out[cross], q[cross])
        out = points[np.column_stack([cross, q_in])]
    return out.reshape(-1, 2)


def contact_outline(below, above):
    """The contact area of a face ``above`` (already shifted by its offset) resting on a
    face ``below`` (None: the pedestal), both in the plane of ``below``: the overlap of
    the two (see the module docstring).  Raises InputError when they hardly overlap."""
    if below is None or below.contains(above):
        return above
    if above.contains(below):
        return below
    overlap = clip_convex(above.polygon(), below.polygon())
    result = Outline.polygon_of(overlap) if len(overlap) >= 3 else None
    if result is None or result.area() < 0.05 * min(above.area(), below.area()):
        raise InputError("two blocks overlap by less than 5 % of the smaller face")
    return result


def perimeter_points(vertices, n):
    """Contact points along a closed convex polygon, for rims whose circles carry ``n``
    points: every corner (a vertex turning by more than CORNER_TURN_DEG), and along each
    curved stretch between corners (an arc of a circle cut by another face) as many
    points, evenly spaced, as a circle has on that angle; straight edges carry their two
    corners only (a box rocks on an edge as Housner's block does: see docs/columns-and-model.md, "Column
    files").  A polygon without corners gets n points evenly spaced."""
    v = np.asarray(vertices, float)
    prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
    a, b = v - prev, nxt - v
    turn = np.degrees(np.abs(np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
                                        (a * b).sum(axis=1))))
    corners = np.flatnonzero(turn > CORNER_TURN_DEG)
    seg = np.hypot(*(nxt - v).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])        # arc length at each vertex
    total = cum[-1]

    def at(s):
        s = s % total
        k = min(np.searchsorted(cum, s, side="right") - 1, len(v) - 1)
        return v[k] + (s - cum[k]) / seg[k] * (nxt[k] - v[k])

    if corners.size == 0:
        return np.array([at(total * j / n) for j in range(n)])
    points = []
    for k, start in enumerate(corners):
        end = corners[(k + 1) % len(corners)]
        inner = np.arange(start + 1, end if end > start else end + len(v)) % len(v)
        s0 = cum[start]
        length = (cum[end] - s0) % total or total
        between = round(n * turn[inner].sum() / 360.0) if len(inner) else 0
        points += [at(s0 + length * j / (between + 1)) for j in range(between + 1)]
    return np.array(points)
