"""What a specimen on the pedestal is to the rest of the code: a column of blocks
(:class:`~pipeline.scenario.geometry.ColumnGeometry`) or a scanned stone
(:class:`~pipeline.scenario.mesh.MeshSpecimen`) implement :class:`Specimen`."""
import abc
import math

from pipeline.constants import MODEL_GRAVITY


class Specimen(abc.ABC):
    """A rigid specimen standing on the pedestal (lengths m, mass kg, energy J)."""

    name: str
    density: float                  # kg/m^3 (a mesh's: its mean)

    @property
    @abc.abstractmethod
    def height(self):
        """Height (m) standing on the pedestal."""

    @property
    @abc.abstractmethod
    def base_width(self):
        """Smallest width (m) of what it stands on."""

    @abc.abstractmethod
    def monolithic(self):
        """A specimen of one stone with the same outline."""

    @abc.abstractmethod
    def bodies(self, x=0.0, y=0.0):
        """Its rigid bodies standing at (x, y), bottom up."""

    @abc.abstractmethod
    def statics(self, g=MODEL_GRAVITY):
        """Per joint: ``ratio`` (rocking threshold / g), ``lever_m``, ``barrier_j``..."""

    @abc.abstractmethod
    def contact_rocking_hz(self, kn, rim_points=16):
        """Frequency (Hz) of the whole specimen rocking on its base's contact springs."""

    @abc.abstractmethod
    def scene_column(self, spec, rim_points):
        """Its :class:`~pipeline.scenario.scene_file.SceneColumn`, placed as ``spec``
        (a :class:`~pipeline.scenario.bodies.ColumnSpec`)."""

    @abc.abstractmethod
    def check_rims(self, rim_sphere_radius):
        """InputError when it is too small for its rims of contact spheres (m)."""

    @abc.abstractmethod
    def to_dict(self):
        """Its description (what its file holds)."""

    def check(self):
        """Its statics; InputError when it cannot stand by itself."""
        return self.statics()

    def uplift_ratio(self):
        """Smallest rocking threshold of any stack / g (tan of the critical angle)."""
        return min(j["ratio"] for j in self.statics())

    def critical_angle_along_deg(self, azimuth_deg):
        """Critical angle (deg) for tipping along a horizontal line (azimuth, deg
        clockwise from North); here the smallest in any direction."""
        return math.degrees(math.atan(self.uplift_ratio()))

    def _described(self, out):
        """``out`` with the description's optional keys."""
        for key in ("source", "notes"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        return out
