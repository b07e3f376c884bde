"""Records stage: strong-motion records in, processed :class:`~pipeline.motion.Motion` out.

A record is a catalogue id (``records/catalog.csv``), a record file (any format
of :mod:`pipeline.records.readers`; a glob pattern for single-channel files) or
an already processed ``.npz``.  :func:`processed_motion` reads, rotates to
East/North/Up and processes it (:mod:`pipeline.records.processing`), caching
the result by content: the input files' bytes, the catalogue row, the
processing steps and the code of this package, never by name.
"""
import glob
import io
import logging
import re
import sys
from pathlib import Path

import numpy as np
from obspy import UTCDateTime
from obspy.geodetics import gps2dist_azimuth

from pipeline import RECORDS_DIR, RESULTS_DIR
from pipeline.files import InputError, code_hash, content_hash, display_path
from pipeline.provenance import software_versions
from pipeline.motion import NPZ_KEYS, Motion
from pipeline.records import processing
from pipeline.records.catalog import catalog, catalog_row
from pipeline.records.readers import is_pattern, read_record
from pipeline.userfiles import check_regular, read_user_bytes
from pipeline.motion.measures import rotd_peak

log = logging.getLogger(__name__)

CACHE_DIR = RESULTS_DIR / "cache" / "motions"
SIDECARS = ("*.xml", "*.xml.gz", "event.json", "*.quakeml", "flatfile_rows.csv")
__all__ = ["processed_motion", "resolve", "build_motion", "catalog", "catalog_row",
           "to_east_north_up", "CACHE_DIR"]


class Source:
    """A resolved record: ``id``, input ``path`` (file or glob), catalogue ``row`` (or None),
    ``processed`` (an npz already processed) and the content ``key`` of its inputs."""

    def __init__(self, record_id, path, row=None, processed=False):
        self.id, self.path, self.row, self.processed = record_id, Path(path), row, processed

    def input_files(self):
        """Files the record depends on: the file (a glob: its matches; an NGA triplet
        RSN<n>_k.AT2: its three files; another AT2: the sibling AT2 files) and the
        metadata beside it (StationXML, event.json, QuakeML, flatfile_rows.csv)."""
        path = self.path
        if is_pattern(path):
            files = [Path(p) for p in sorted(glob.glob(str(path)))]
        elif ".at2" in path.name.lower():
            triplet = re.match(r"(RSN\d+)_[123]\.AT2", path.name, re.I)
            prefix = triplet.group(1).upper() + "_" if triplet else ""
            files = sorted(p for p in path.parent.iterdir() if ".at2" in p.name.lower()
                           and p.name.upper().startswith(prefix))
        else:
            files = [path]
        sidecars = [p for pattern in SIDECARS for p in sorted(path.parent.glob(pattern))]
        return files + [p for p in sidecars if p not in files]

    def key(self, back_azimuth=None, steps=processing.DEFAULT_STEPS):
        """Content key (16 hex) of everything the processed motion depends on."""
        return content_hash(self.row, back_azimuth, [list(s) for s in steps],
                            code_hash("records", "motion"), *self.input_files())


def resolve(record):
    """A :class:`Source` for a catalogue id, record file, glob pattern or processed npz.

    An existing file wins over a catalogue id of the same name; file-based ids are the
    sanitised file stem (``same_stem_id`` makes them unique when needed).
    """
    path = Path(record)
    if is_pattern(path) and glob.glob(str(path)):
        return Source(_sanitise(path.name.split("*")[0].strip("._") or "record"), path)
    check_regular(path, "record file")
    if path.is_file():
        if path.suffix.lower() == ".npz":
            try:
                content = read_user_bytes(path, "record file")
                with np.load(io.BytesIO(content), allow_pickle=False) as archive:
                    names = set(archive.files)
            except (ValueError, OSError, EOFError):
                raise InputError(f"{path.name}: unreadable npz") from None
            if set(NPZ_KEYS) <= names:
                return Source(_sanitise(path.stem), path, processed=True)
        return Source(_sanitise(path.stem), path)
    row = catalog_row(str(record))
    if row is not None:
        path = RECORDS_DIR / row["source_file"]
        if not (path.is_file() or (is_pattern(path) and glob.glob(str(path)))):
            raise InputError(f"catalogue {row['id']}: source file missing: {path}")
        return Source(row["id"], path, row=row)
    if is_pattern(path):
        raise InputError(f"no record files match {record}")
    raise InputError(f"not a catalogue id and no such file: {record}")


def _sanitise(stem):
    text = re.sub(r"[^A-Za-z0-9_.-]", "_", stem).strip("._") or "record"
    return text


def processed_motion(record, back_azimuth=None, cache_dir=CACHE_DIR, mode="default"):
    """The processed :class:`Motion` of ``record`` (anything :func:`resolve` takes, or
    its :class:`Source`) and the path of its cached npz.

    Cached in ``cache_dir/<key>.npz`` (``cache_dir`` None: not cached, path None).
    ``back_azimuth`` (deg) is used only when neither file nor catalogue gives one.
    ``mode``: "default" (:data:`processing.DEFAULT_STEPS`) or "none" (the acceleration
    as given, integrated: a motion that is already processed).  A processed npz is
    always taken as it is.
    """
    steps = processing.steps_for(mode)
    source = record if isinstance(record, Source) else resolve(record)
    if source.processed:
        return Motion.load(source.path), source.path
    key = source.key(back_azimuth, steps)
    path = None if cache_dir is None else Path(cache_dir) / f"{key}.npz"
    if path is not None and path.is_file():
        try:
            motion = Motion.load(path)
            if motion.meta.get("processing", {}).get("input_hash") == key:
                return motion, path
        except InputError:
            pass
    motion = build_motion(source, back_azimuth, key, mode)
    if path is not None:
        motion.save(path)
    return motion, path


def rotd50_fraction(record):
    """RotD50 / RotD100 of the horizontal PGA of ``record``'s processed motion (RotD100 =
    the peak of the horizontal vector; :func:`pipeline.motion.measures.rotd_peak`, 0.5 deg
    steps); unchanged by scaling the record."""
    motion, _ = processed_motion(record, cache_dir=None)
    peak = rotd_peak(motion.acc, 100.0, 0.5)
    if not peak > 0:
        raise InputError(f"record {record}: no horizontal acceleration")
    return rotd_peak(motion.acc, 50.0, 0.5) / peak


def read_east_north_up(source):
    """Read a :class:`Source` and rotate it: (acc (n, 3) m/s^2 East/North/Up, dt s, info,
    has_vertical), with the catalogue's orientation and time window applied."""
    row = source.row or {}
    stream, info = read_record(source.path, row.get("source_key"))
    _apply_catalog_orientation(stream, row, source.path)
    if row.get("start_utc") or row.get("end_utc"):
        stream.trim(starttime=UTCDateTime(row["start_utc"]) if row.get("start_utc") else None,
                    endtime=UTCDateTime(row["end_utc"]) if row.get("end_utc") else None)
    needs_vertical = row.get("has_vertical", True) not in (False, "false", "False", 0)
    enz, dt = to_east_north_up(stream, source.path.name, needs_vertical)
    return enz, dt, info, needs_vertical


def build_motion(source, back_azimuth=None, key=None, mode="default"):
    """Read and process one :class:`Source` (``mode`` as in :func:`processed_motion`);
    return its :class:`Motion` (not written)."""
    row = source.row or {}
    enz, dt, info, needs_vertical = read_east_north_up(source)
    band = (info.get("lowest_usable_hz"), info.get("highest_usable_hz"))
    acc, vel, disp, steps = processing.process(enz, dt, band, processing.steps_for(mode),
                                               name=source.path.name)
    meta = _motion_meta(source, row, info, back_azimuth, needs_vertical)
    if info.get("peer"):
        meta["peer_reference"] = info["peer"]       # PEER's own peaks of this record
    meta["processing"] = {"mode": mode, "steps": steps, "input_hash": key,
                          "reader": info.get("format"), "software": software_versions()}
    trims = [s["window_s"][0] for s in steps if s["step"] == "trim_to_signal"]
    meta["start_in_file_s"] = float(trims[0]) if trims else 0.0
    meta["signal_end_s"] = processing.signal_end_in_motion_s(steps)
    return Motion(dt, acc, vel, disp, meta=meta)


def to_east_north_up(stream, name, needs_vertical=True):
    """Check a raw acceleration stream and rotate it to an (n, 3) East, North, Up array.

    Raises InputError for NaN or gaps, mixed sampling rates, missing or extra
    components.  Returns (array in m/s^2, dt in s).
    """
    if len(stream) == 0:
        raise InputError(f"{name}: no traces")
    for trace in stream:
        data = trace.data
        if np.ma.isMaskedArray(data) and np.ma.is_masked(data):
            raise InputError(f"{name}: trace {trace.id} has gaps")
        if not np.all(np.isfinite(np.asarray(data, dtype=float))):
            raise InputError(f"{name}: trace {trace.id} has NaN or infinite samples")
    rates = {round(trace.stats.sampling_rate, 9) for trace in stream}
    if len(rates) > 1:
        raise InputError(f"{name}: components have different sampling rates "
                         f"({', '.join(f'{r:g}' for r in sorted(rates))} Hz)")
    horizontals = [tr for tr in stream if abs(tr.stats.dip) < 1e-6]
    verticals = [tr for tr in stream if abs(abs(tr.stats.dip) - 90.0) < 1e-6]
    if len(horizontals) != 2 or len(verticals) > 1 or len(horizontals) + len(verticals) != len(stream):
        raise InputError(f"{name}: need 2 horizontal and 1 vertical component, found "
                         f"{len(horizontals)} horizontal, {len(verticals)} vertical, "
                         f"{len(stream) - len(horizontals) - len(verticals)} inclined")
    if not verticals and needs_vertical:
        raise InputError(f"{name}: missing vertical component")
    start = max(tr.stats.starttime for tr in stream)
    end = min(tr.stats.endtime for tr in stream)
    if end - start <= 0:
        raise InputError(f"{name}: components do not overlap in time")
    stream = stream.copy().trim(start, end, nearest_sample=True)
    n = min(tr.stats.npts for tr in stream)
    if n < 100:
        raise InputError(f"{name}: fewer than 100 common samples")
    h1, h2 = (np.asarray(tr.data[:n], dtype=float) for tr in horizontals)
    vertical = verticals[0] if verticals else None
    z = np.asarray(vertical.data[:n], dtype=float) if vertical else np.zeros(n)
    z_dip = vertical.stats.dip if vertical else -90.0
    from obspy.signal.rotate import rotate2zne  # lazy: obspy is slow to import
    try:
        up, north, east = rotate2zne(z, 0.0, z_dip,
                                     h1, horizontals[0].stats.azimuth, 0.0,
                                     h2, horizontals[1].stats.azimuth, 0.0)
    except ValueError:
        raise InputError(f"{name}: horizontal azimuths {horizontals[0].stats.azimuth:g} and "
                         f"{horizontals[1].stats.azimuth:g} are not independent") from None
    if vertical is None:
        up = np.zeros(n)  # rotate2zne leaves round-off (1e-17) of the horizontals here
    return np.column_stack([east, north, up]), stream[0].stats.delta


def _apply_catalog_orientation(stream, row, path):
    """Catalogue ``azimuths_deg`` ("a;b") sets the horizontal azimuths where the file has none."""
    if not row.get("azimuths_deg"):
        if any(tr.stats.azimuth is None for tr in stream):
            raise InputError(f"{path.name}: horizontal azimuths unknown (catalogue azimuths_deg)")
        return
    azimuths = [float(v) for v in str(row["azimuths_deg"]).split(";")]
    horizontals = [tr for tr in stream if tr.stats.dip == 0.0]
    if len(azimuths) != len(horizontals):
        raise InputError(f"catalogue {row['id']}: {len(azimuths)} azimuths for "
                         f"{len(horizontals)} horizontal components")
    for trace, azimuth in zip(horizontals, azimuths):
        trace.stats.azimuth = azimuth % 360.0


def _motion_meta(source, row, info, back_azimuth, has_vertical):
    def pick(key):
        return row.get(key) if row.get(key) is not None else info.get(key)

    meta = {"record_id": source.id, "label": row.get("label") or source.id,
            "event": pick("event"), "station": pick("station"), "magnitude": pick("magnitude"),
            "mechanism": row.get("mechanism"), "has_vertical": bool(has_vertical),
            "horizontals_compass": row.get("horizontals_compass", True),
            "orientation": row.get("orientation", "as-recorded"),
            "source_file": display_path(source.path), "source_key": row.get("source_key"),
            "units": {"dt": "s", "acc": "m/s^2", "vel": "m/s", "disp": "m"},
            "columns": ["East", "North", "Up"]}
    coords = {k: pick(k) for k in ("station_lat", "station_lon", "event_lat", "event_lon")}
    meta.update(coords)
    if None not in coords.values():
        bad = [k for k, v in coords.items() if not (isinstance(v, (int, float)) and
                                                    abs(v) <= (90 if k.endswith("lat") else 180))]
        if bad:
            raise InputError(f"{source.path.name}: coordinate(s) out of range: "
                             + ", ".join(f"{k} {coords[k]}" for k in bad))
        dist_m, _, baz = gps2dist_azimuth(coords["event_lat"], coords["event_lon"],
                                          coords["station_lat"], coords["station_lon"])
        meta["back_azimuth_deg"] = float(baz % 360.0)
        meta["epicentral_distance_km"] = float(dist_m / 1000.0)
        meta["back_azimuth_source"] = ("gps2dist_azimuth of station and epicentre coordinates from "
                                       + (row.get("citation") or "the record file header"))
        if back_azimuth is not None:
            log.info(f"note: {source.id}: coordinates give the back azimuth; "
                     f"--back-azimuth {back_azimuth:g} ignored", extra={"stderr": True})
    elif row.get("back_azimuth_deg") is not None:
        meta["back_azimuth_deg"] = float(row["back_azimuth_deg"])
        meta["epicentral_distance_km"] = row.get("epicentral_distance_km")
        meta["back_azimuth_source"] = f"catalogue: {row.get('citation')}"
    else:
        meta["back_azimuth_deg"] = None if back_azimuth is None else float(back_azimuth) % 360.0
        meta["epicentral_distance_km"] = row.get("epicentral_distance_km")
        meta["back_azimuth_source"] = ("unknown" if back_azimuth is None
                                       else "given by the user (--back-azimuth)")
    if meta["epicentral_distance_km"] is not None:
        meta["epicentral_distance_km"] = float(meta["epicentral_distance_km"])
    if not has_vertical:
        meta["notes"] = "no vertical component in the source: Up column is zero"
    if row.get("notes"):
        meta["notes"] = (meta.get("notes", "") + "; " + row["notes"]).lstrip("; ")
    return meta
