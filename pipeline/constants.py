"""Physical constants and the names of the column models, with one home each.

Two gravities on purpose: ``STANDARD_GRAVITY`` converts accelerations given in
units of g (record files) to m/s^2; ``MODEL_GRAVITY`` is the gravity the YADE
model and the rigid-block theory use (Hinzen 2009 works with 9.81 m/s^2).
"""
import scipy.constants

STANDARD_GRAVITY = scipy.constants.g   # m/s^2, 9.80665: unit conversion "g" -> m/s^2
MODEL_GRAVITY = 9.81                   # m/s^2: gravity of the simulated world

# the column models of a scene: the twin model ("both": drums at x = -1.5 m, monolith at
# +1.5 m) or one of its two columns (also the names of the columns in every output)
COLUMN_TYPES = ("drums", "monolithic")
COLUMN_KINDS = ("both", "monolithic", "drums")

# what lying and standing mean, for the scene's stop checks and the outcome (one home):
# a body's long axis points up at least STANDS_AXIS_Z while it stands (tilt below ~30
# deg), below LIES_AXIS_Z = cos(LIES_TILT_DEG) once it lies; a mesh specimen (a rock)
# lies once tilted LIES_PAST_CRITICAL_DEG past its critical angle (at most LIES_TILT_DEG)
STANDS_AXIS_Z = 0.866
LIES_TILT_DEG = 60.0
LIES_AXIS_Z = 0.5
LIES_PAST_CRITICAL_DEG = 30.0
