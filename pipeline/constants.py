"""Physical constants with one home each.

Two gravities on purpose: ``STANDARD_GRAVITY`` converts accelerations given in
units of g (record files) to m/s^2; ``MODEL_GRAVITY`` is the gravity the YADE
model and the rigid-block theory use (Hinzen 2009 works with 9.81 m/s^2).
"""
import scipy.constants

STANDARD_GRAVITY = scipy.constants.g   # m/s^2, 9.80665: unit conversion "g" -> m/s^2
MODEL_GRAVITY = 9.81                   # m/s^2: gravity of the simulated world
