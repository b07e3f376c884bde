"""One place: the hazard curves and what gives PGV/PGA with them (a rate density of PGA and
PGV, a magnitude-distance disaggregation) must be of the same site where both state it
(OpenQuake's exports and the USGS web service state theirs; a plain table states none).
Coordinates in degrees."""
from pipeline.files import InputError

SAME_PLACE_DEG = 1e-3    # two sites agree within this in longitude and latitude (deg)


def check_same_place(what, at, curves_source, curves):
    """InputError when ``curves_source`` (the curves' source: ``lon``, ``lat``) states a
    place and ``at`` ((lon, lat) of ``what``) lies elsewhere; ``curves``: the curves in
    words, for the message."""
    lon, lat = curves_source.get("lon"), curves_source.get("lat")
    if lon is None or lat is None:
        return
    at_lon, at_lat = at
    if abs((at_lon - lon + 180.0) % 360.0 - 180.0) > SAME_PLACE_DEG or \
            abs(at_lat - lat) > SAME_PLACE_DEG:
        raise InputError(f"{what} lies at ({at_lon:g}, {at_lat:g}), {curves} at ({lon:g}, "
                         f"{lat:g}): of another place")
