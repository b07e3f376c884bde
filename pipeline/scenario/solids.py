"""Solids of a column description: :class:`Frustum` and :class:`Box` (closed-form mass
properties and face outlines) and :class:`ColumnBlock`, a solid placed on the block below
(offset, tilt).  Conventions: :mod:`pipeline.scenario.geometry`."""
import math
from dataclasses import dataclass

import numpy as np

from pipeline.scenario.outline import Outline

SHAPES = ("frustum", "box")
TILT_MODES = ("wedge", "edge")


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
