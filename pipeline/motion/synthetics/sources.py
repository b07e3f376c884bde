"""The two synthetic sources (Mw 6.5 strike-slip and thrust) and the layered crust."""
import math

import numpy as np
import pandas as pd

from pipeline.files import InputError

# Simple layered crust: (thickness km, Vp km/s, Vs km/s, density g/cm^3).
CRUST_LAYERS = (
    (1.0, 3.5, 2.0, 2.3),
    (4.0, 5.5, 3.2, 2.6),
    (15.0, 6.2, 3.6, 2.75),
    (10.0, 6.8, 3.9, 2.9),
    (math.inf, 8.0, 4.5, 3.3),
)

# Sub-events: positions along strike relative to the hypocentre (km, positive
# in the strike direction), equal moments, each with a trapezoidal moment-rate
# function (a boxcar of ``subevent_rise_s`` convolved with one of
# ``subevent_duration_s``).  Rise 0.5 s / duration 1.5 s keeps PGA and PGV
# within a factor ~1.5 of the NGA-West2 medians at 5-20 km (gmm_check.csv).
# Both sources rupture alike from a hypocentre at the origin.
RUPTURE = {
    "hypocentre_x_km": 0.0,
    "hypocentre_y_km": 0.0,
    "subevents_along_strike_km": (-4.0, 0.0, 4.0, 8.0, 12.0),
    "rupture_velocity_km_s": 2.8,
    "subevent_rise_s": 0.5,
    "subevent_duration_s": 1.5,
}
SOURCES = {
    "strike_slip": {
        "mechanism": "strike-slip",
        "gmm_mechanism": "SS",
        "strike_deg": 0.0,  # N-S fault ...
        "dip_deg": 90.0,
        "rake_deg": 180.0,  # ... right-lateral
        "mw": 6.5,
        "depth_km": 8.0,
        **RUPTURE,
    },
    "thrust": {
        "mechanism": "reverse",
        "gmm_mechanism": "RS",
        "strike_deg": 90.0,  # E-W fault dipping south
        "dip_deg": 40.0,
        "rake_deg": 90.0,
        "mw": 6.5,
        "depth_km": 10.0,
        **RUPTURE,
    },
}

LEAD_TIME_S = 1.0  # record time of the hypocentral origin time


def moment_from_mw(mw):
    """Scalar moment (N m) of moment magnitude ``mw`` (Hanks & Kanamori 1979)."""
    return 10.0 ** (1.5 * mw + 9.1)


def source_parameters(source_name):
    """The parameter dict of a source in :data:`SOURCES`; InputError if unknown."""
    try:
        return SOURCES[source_name]
    except KeyError:
        raise InputError(f"unknown synthetic source {source_name!r} "
                         f"(known: {', '.join(SOURCES)})") from None


def rupture_centre(source_name):
    """(x_km, y_km) of the middle of the sub-event line of a source."""
    subs = subevents(source_name)
    return tuple(subs[["x_km", "y_km"]].to_numpy()[[0, -1]].mean(axis=0))


def subevents(source_name):
    """Sub-events: DataFrame x_km, y_km, depth_km, delay_s (rupture time), m0_nm."""
    src = source_parameters(source_name)
    strike = math.radians(src["strike_deg"])
    along = np.asarray(src["subevents_along_strike_km"], dtype=float)
    return pd.DataFrame({
        "x_km": src["hypocentre_x_km"] + along * math.sin(strike),
        "y_km": src["hypocentre_y_km"] + along * math.cos(strike),
        "depth_km": float(src["depth_km"]),
        "delay_s": np.abs(along) / src["rupture_velocity_km_s"],
        "m0_nm": moment_from_mw(src["mw"]) / len(along),
    })
