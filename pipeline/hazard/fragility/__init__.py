"""Fragility as survival needs it: P(overturn | PGA, PGV/PGA), and the PGV/PGA that goes
with each PGA level.  The package of the fragility wing; each concern in its module:

- :mod:`pipeline.hazard.fragility.kinds`: the declared :class:`Fragility` and its fitted
  kinds :class:`Lognormal` and :class:`Logistic`;
- :mod:`pipeline.hazard.fragility.grid`: a pulse grid's cells as a fragility
  (:class:`PulseGrid`, :data:`BELOW_GRID`);
- :mod:`pipeline.hazard.fragility.ratio`: PGV/PGA at a PGA level (:class:`RatioLognormal`,
  :class:`RatioFromGmm`) and the nodes P is averaged over it with;
- :mod:`pipeline.hazard.fragility.load`: a campaign's ``fragility.json`` loaded as one
  (:func:`load_campaign_fragility`, :func:`load_pulse_grid`, :func:`member_fits`);
- :mod:`pipeline.hazard.fragility.file`: ``fragility.json`` as one type
  (:class:`~pipeline.hazard.fragility.file.FragilityFile`), its writer and its reader;
  its leaves in :mod:`~pipeline.hazard.fragility.fits` (a lognormal fit, a logistic
  surface) and :mod:`~pipeline.hazard.fragility.rows` (a cell, a contour's row), each
  checking itself on construction (:mod:`~pipeline.hazard.fragility.checker`);
- :mod:`pipeline.hazard.fragility.check`: the checks a part cannot make alone, run by
  the reader.
"""
from pipeline.hazard.fragility.grid import BELOW_GRID, PulseGrid
from pipeline.hazard.fragility.kinds import Fragility, Logistic, Lognormal
from pipeline.hazard.fragility.load import load_campaign_fragility, load_pulse_grid, member_fits
from pipeline.hazard.fragility.ratio import (GMM_MECHANISMS, PGA_PGV_CORRELATION, RATIO_NODES,
                                             RatioFromGmm, RatioLognormal)

__all__ = ["BELOW_GRID", "GMM_MECHANISMS", "PGA_PGV_CORRELATION", "RATIO_NODES", "Fragility",
           "Logistic", "Lognormal", "PulseGrid", "RatioFromGmm", "RatioLognormal",
           "load_campaign_fragility", "load_pulse_grid", "member_fits"]
