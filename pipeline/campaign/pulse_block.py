"""The 2D rigid block of the pulse grid (:mod:`pipeline.campaign.pulse_grid`): a block
of the same critical angle and pivot distance as the specimen along each run's azimuth
(height, width in m), rocked by the toolkit's Housner integrator
(:func:`pipeline.rocking.sampled.rocking_response_sampled`) under the same pulses (PGA in g).
"""
import math

import numpy as np

from pipeline.campaign.pulse_grid import G, PULSE_DT_S
from pipeline.motion.pulses import one_cosine_pulse
from pipeline.rocking.housner import block_constants
from pipeline.rocking.sampled import rocking_response_sampled
from pipeline.scenario.geometry import ColumnGeometry


def block_of(params, azimuth_deg):
    """(height, width) m of the 2D block of the same critical angle and pivot distance
    as the specimen of ``params`` shaken along ``azimuth_deg``: a mesh specimen's
    centre-of-mass height and its smaller lever across that line (critical angle
    :meth:`~pipeline.scenario.mesh.MeshSpecimen.critical_angle_along_deg`), a column's
    overall height and base width."""
    described = params.column.column_file
    if described is not None and "mesh" in described:
        specimen = _specimen(described)
        angle = math.radians(specimen.critical_angle_along_deg(azimuth_deg))
        com_z = float(specimen.com[2])
        return 2 * com_z, 2 * com_z * math.tan(angle)
    return block_size(params)

BLOCK_T_AFTER_S = 30.0          # the 2D block's free rocking after the motion, at most
BLOCK_MAX_STEP_S = 1e-3         # the 2D block's integration step, at most


def block_size(params):
    """(height, width) in m of the 2D block of a run (``params``:
    :class:`~pipeline.scenario.parameters.RunParams`): the paper column's height and
    diameter, or a description's overall height and base width."""
    column = params.column
    if column.column_file is None:
        return column.height, column.height / column.hd
    blocks = column.column_file["blocks"]        # as ColumnGeometry.height and .base_width
    bottom = blocks[0]
    width = (bottom["bottom_diameter"] if bottom["shape"] == "frustum"
             else min(bottom["width"], bottom["depth"]))
    return math.fsum(b["height"] for b in blocks), width


_SPECIMENS = {}


def _specimen(described):
    key = repr(sorted((k, repr(v)) for k, v in described.items()))
    if key not in _SPECIMENS:
        _SPECIMENS[key] = ColumnGeometry.from_dict(described)
    return _SPECIMENS[key]


def block_outcomes(specs, t_after=BLOCK_T_AFTER_S, max_step=BLOCK_MAX_STEP_S):
    """Overturned (bool array, one per spec) of the 2D block of each run under its pulse:
    the pulse along the run's azimuth is the same scalar series for every direction."""
    out = np.zeros(len(specs), bool)
    by_cell = {}
    for k, spec in enumerate(specs):
        by_cell.setdefault((spec.tags.pga_g, spec.tags.pgv_pga_s), []).append(k)
    for (pga_g, ratio), idx in by_cell.items():
        pulse = one_cosine_pulse(pga_g * G, ratio, 0.0, PULSE_DT_S, 0.0)
        sizes = np.array([block_of(specs[k].params, specs[k].tags.azimuth_deg)
                          for k in idx], float)
        acc = np.repeat(pulse.acc[:, 1:2], len(idx), axis=1)       # (n, cases)
        result = rocking_response_sampled(sizes[:, 0], sizes[:, 1], acc, pulse.dt,
                                          t_after=t_after, max_step=max_step)
        out[idx] = result["overturned"]
    return out


def block_reference(specs):
    """alpha (rad), R (m), p (1/s) of the 2D block: medians over the runs; and
    ``alpha_smallest`` (rad), the smallest critical angle of any run's block."""
    sizes = np.array([block_of(s.params, s.tags.azimuth_deg) for s in specs], float)
    c = block_constants(float(np.median(sizes[:, 0])), float(np.median(sizes[:, 1])))
    return {**c, "alpha_smallest": float(np.min(np.arctan2(sizes[:, 1], sizes[:, 0])))}

