"""Site hazard and survival: what a standing rock or column says about the ground motion
its site has seen.

``curves``: one loader for a site's hazard curve (OpenQuake's hazard-curve CSV or a plain
table of PGA and annual rate of exceedance) -> :class:`HazardCurve` (PGA in m/s^2, rates
in 1/yr).  ``fragility``: P(overturn | PGA, PGV/PGA) as a lognormal over PGA or the
logistic surface of ``campaign fragility``, and the PGV/PGA that goes with each PGA.
``survival``: the rate of overturning, survival over an uncertain age, the contribution
by intensity and the bounds, as plain functions on arrays.
"""
from pipeline.hazard.curves import HazardCurve, load_hazard
