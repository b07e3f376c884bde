"""Anything :func:`obspy.read` reads (MiniSEED, SAC, ...): the fallback format.

Orientation from SEED channel codes (E/N/Z) or SAC ``cmpaz``/``cmpinc``; SAC
headers also give station and event coordinates.  A glob pattern reads the
single-channel files of one record together.
"""
import io
from pathlib import Path

import obspy

from pipeline.files import InputError
from pipeline.records.readers import is_pattern, orientation_from_code, read_bytes

FORMAT = "obspy"
PRIORITY = 100


def detect(path, head):
    """Fallback: obspy decides in :func:`read`."""
    return True


def read(path, key=None):
    return read_obspy(path)


def read_obspy(path):
    """MiniSEED, SAC, ... via obspy; orientation from channel codes or SAC cmpaz/cmpinc."""
    try:
        stream = obspy.read(str(path) if is_pattern(path) else io.BytesIO(read_bytes(path)))
    except Exception as exc:  # obspy raises many types for unknown formats
        raise InputError(f"{Path(path).name}: not a readable record file ({type(exc).__name__})") \
            from None
    stations = {(tr.stats.network, tr.stats.station, tr.stats.location, tr.stats.channel[:2])
                for tr in stream}
    if len(stations) > 1:
        raise InputError(f"{Path(path).name}: holds {len(stations)} stations or instruments; "
                         "give one record per file")
    try:
        stream.merge(method=0)  # gaps become masked arrays, rejected later
    except Exception as exc:   # obspy: e.g. one channel at two sampling rates
        raise InputError(f"{Path(path).name}: cannot merge the traces of one channel "
                         f"({str(exc).splitlines()[0][:120]})") from None
    info = {}
    for tr in stream:
        sac = tr.stats.get("sac")
        azimuth, dip = orientation_from_code(tr.stats.channel)
        if sac is not None and "cmpaz" in sac and "cmpinc" in sac:
            # SAC: cmpinc is measured from vertical up (0 = up, 90 = horizontal)
            azimuth, dip = float(sac.cmpaz) % 360.0, float(sac.cmpinc) - 90.0
        if azimuth is None:
            raise InputError(f"{Path(path).name}: channel {tr.id} has no azimuth "
                             "(use E/N/Z channel codes or SAC cmpaz/cmpinc)")
        tr.stats.azimuth, tr.stats.dip = azimuth, dip
        if sac is not None:
            info.update(_sac_info(sac))
    first = stream[0].stats if len(stream) else None
    if first is not None:
        info.setdefault("station", ".".join(p for p in (first.network, first.station) if p))
    return stream, info


def _sac_info(sac):
    names = {"stla": "station_lat", "stlo": "station_lon", "evla": "event_lat",
             "evlo": "event_lon", "mag": "magnitude"}
    info = {new: float(sac[old]) for old, new in names.items() if old in sac}
    if "kstnm" in sac:
        info["station"] = sac.kstnm.strip()
    if "kevnm" in sac and sac.kevnm.strip():
        info["event"] = sac.kevnm.strip()
    return info
