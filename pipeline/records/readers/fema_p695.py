"""The compact FEMA P695 file ``records/fema_p695.npz`` (needs a key such as NF11)."""
import io
import json
from pathlib import Path

import numpy as np
from obspy import Stream, Trace

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import InputError
from pipeline.records.readers import read_bytes

FORMAT = "fema-p695"
PRIORITY = 10


def detect(path, head):
    return Path(path).suffix.lower() == ".npz" and head[:2] == b"PK"


def read(path, key=None):
    if key is None:
        raise InputError(f"{Path(path).name}: a FEMA P695 file needs a record key such as NF11")
    return read_fema_p695(path, key)


def read_fema_p695(path, key):
    """Record ``key`` (``FF01``-``FF22``, ``NF01``-``NF28``) of the compact FEMA P695 file.

    Two horizontal components (g in the file); the set has no verticals.  The
    orientation of each component comes from the catalogue (see records/README.md),
    so ``stats.azimuth`` is None here and the caller sets it.
    """
    with np.load(io.BytesIO(read_bytes(path)), allow_pickle=False) as archive:
        meta = json.loads(str(archive["metadata"]))["records"]
        if key not in meta:
            raise InputError(f"{Path(path).name}: no record {key!r} (known: FF01-FF22, NF01-NF28)")
        entry = meta[key]
        stream = Stream()
        for comp, comp_meta in entry["components"].items():
            trace = Trace(archive[f"{key}_{comp}"].astype(np.float64) * STANDARD_GRAVITY)
            trace.stats.delta = comp_meta["dt"]
            trace.stats.channel = comp_meta["name"].split("/")[-1]
            trace.stats.azimuth, trace.stats.dip = None, 0.0
            stream.append(trace)
    info = {"event": f"{entry['EarthquakeName']} {entry['EarthquakeYear']}",
            "station": entry["RecordingStationName"], "magnitude": entry["EarthquakeMagnitude"],
            "lowest_usable_hz": entry["LowestUsableFrequency"],
            "peer": {"measure": "larger component", "source": "FEMA P695 Table A (PEER NGA)",
                     "rsn": entry["RecordSequenceNumber"],
                     "pga_ms2": entry["PGAmax"] * STANDARD_GRAVITY,
                     "pgv_ms": entry["PGVmax"] / 100.0, "pulse_like": entry.get("pulse")}}
    return stream, info
