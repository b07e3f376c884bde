"""ASDF (HDF5): raw waveforms of one station with StationXML and QuakeML."""
import io

import numpy as np
import obspy
from obspy import Stream, Trace, UTCDateTime

from pipeline.files import InputError
from pipeline.records.readers import orientation_from_code, read_bytes

FORMAT = "asdf"
PRIORITY = 20


def detect(path, head):
    return head[:8] == b"\x89HDF\r\n\x1a\n"


def read(path, key=None):
    return read_asdf(io.BytesIO(read_bytes(path)), path.name)


def read_asdf(source, name="ASDF file"):
    """ASDF (HDF5): raw waveforms of one station with StationXML (sensitivity, orientation)
    and QuakeML (epicentre, magnitude).  Uses the ``*_unprocessed``/``raw_recording`` tag."""
    import h5py  # lazy: h5py, only for ASDF files
    try:
        h5 = h5py.File(source, "r")
    except OSError as exc:
        raise InputError(f"{name}: unreadable HDF5 file ({exc})") from None
    with h5:
        if "Waveforms" not in h5 or len(h5["Waveforms"]) != 1:
            raise InputError(f"{name}: ASDF file must hold exactly one station under Waveforms")
        group = next(iter(h5["Waveforms"].values()))
        if "StationXML" not in group:
            raise InputError(f"{name}: ASDF station has no StationXML")
        inventory = obspy.read_inventory(io.BytesIO(group["StationXML"][()].tobytes()))
        stream = Stream()
        for key, dataset in group.items():
            if key == "StationXML" or not key.endswith(("_unprocessed", "__raw_recording")):
                continue
            network, station, location, channel = key.split("__")[0].split(".")
            trace = Trace(np.asarray(dataset[()], dtype=np.float64))
            trace.stats.update({"network": network, "station": station, "location": location,
                                "channel": channel,
                                "sampling_rate": float(dataset.attrs["sampling_rate"]),
                                "starttime": UTCDateTime(int(dataset.attrs["starttime"]) * 1e-9)})
            stream.append(trace)
        events = (obspy.read_events(io.BytesIO(h5["QuakeML"][()].tobytes()))
                  if "QuakeML" in h5 else [])
    if not stream:
        raise InputError(f"{name}: no raw waveforms (tag unprocessed/raw_recording) found")
    try:
        stream.remove_sensitivity(inventory)
    except Exception as exc:
        raise InputError(f"{name}: no instrument sensitivity for the waveforms ({exc})") from None
    for trace in stream:
        channel = inventory.select(channel=trace.stats.channel)[0][0][0]
        if channel.response.instrument_sensitivity.input_units.upper() not in {"M/S**2", "M/S2"}:
            raise InputError(f"{name}: {trace.id} is not an accelerometer channel")
        azimuth, dip = orientation_from_code(trace.stats.channel)
        if channel.azimuth is not None and azimuth is not None:
            azimuth = channel.azimuth
        if channel.dip is not None:
            dip = channel.dip
        if azimuth is None:
            raise InputError(f"{name}: channel {trace.id} has no azimuth")
        trace.stats.azimuth, trace.stats.dip = azimuth, dip
    site = inventory[0][0]
    info = {"station": f"{inventory[0].code}.{site.code}", "station_lat": site.latitude,
            "station_lon": site.longitude}
    if events:
        origin = events[0].preferred_origin() or events[0].origins[0]
        info.update(event_lat=origin.latitude, event_lon=origin.longitude,
                    origin_time=str(origin.time))
        if events[0].magnitudes:
            info["magnitude"] = events[0].magnitudes[0].mag
    return stream, info
