"""Record sets of the catalogue, selected by rule (never by a hand-kept list).

- ``nearsource``: the paper's selection (Hinzen 2009, "Measured Ground
  Motions"): usable three-component records with compass horizontals, a known
  back azimuth, epicentral distance below ``paper.SELECTION_MAX_DISTANCE_KM``
  and horizontal PGA above ``paper.SELECTION_MIN_PGA_M_S2``; one record per
  station and event (a second file of the same recording, e.g. ``RC19-CCC``
  beside ``RC-CCC``, is left out: the first in catalogue order stays).  The
  PGA is the peak of the horizontal acceleration vector (``pga_h`` of
  :func:`pipeline.motion.measures.record_parameters`) of the processed motion,
  so the rule processes the candidates that pass the other tests: lazily, with
  the motion and its PGA cached by content (``<cache_dir>/<key>.npz`` from
  :func:`pipeline.records.processed_motion` and ``<key>.pga.json`` beside it).
- ``fema``: the FEMA P695 pairs (``source_file`` ``fema_p695.npz``).
- ``all``: every usable catalogue row.

:func:`record_ids` gives a set's ids in catalogue order; :func:`selection` the
nearsource rule's verdict on every catalogue row, with the reason for each
exclusion.
"""
import json
import math
from pathlib import Path

import pandas as pd

from pipeline import paper
from pipeline.files import InputError, csv_number, csv_true, write_json
from pipeline.records.catalog import catalog
from pipeline.motion.measures import record_parameters
from pipeline.records import CACHE_DIR, processed_motion, resolve

SETS = {
    "nearsource": (f"three components, compass horizontals, known back azimuth, epicentral "
                   f"distance < {paper.SELECTION_MAX_DISTANCE_KM:g} km, horizontal PGA > "
                   f"{paper.SELECTION_MIN_PGA_M_S2:g} m/s^2 (the paper's selection), one "
                   "record per station and event"),
    "fema": "the FEMA P695 far- and near-field pairs (horizontals only, no back azimuth)",
    "all": "every usable catalogued record",
}
FEMA_SOURCE_FILE = "fema_p695.npz"
PGA_SUFFIX = ".pga.json"


def names():
    """Names of the record sets."""
    return list(SETS)


def record_ids(name, cache_dir=None, pga=None):
    """Catalogue ids of record set ``name``, in catalogue order.

    ``cache_dir``: motion cache for the PGA of the nearsource rule (default
    ``pipeline.records.CACHE_DIR``); ``pga``: a function id -> horizontal PGA
    (m/s^2) used instead of processing (tests).
    """
    if name not in SETS:
        raise InputError(f"unknown record set {name!r} (known: {', '.join(SETS)})")
    table = catalog()
    usable = table[table["usable"].map(_true)]
    if name == "all":
        return [str(i) for i in usable["id"]]
    if name == "fema":
        return [str(i) for i in usable.loc[usable["source_file"] == FEMA_SOURCE_FILE, "id"]]
    chosen = selection(cache_dir=cache_dir, pga=pga)
    return [str(i) for i in chosen.loc[chosen["selected"], "id"]]


def selection(cache_dir=None, pga=None):
    """The nearsource rule applied to every catalogue row: a DataFrame with ``id``,
    ``epicentral_distance_km``, ``back_azimuth_deg``, ``pga_h`` (m/s^2; NaN where the
    rule stopped before it), ``selected`` and ``reason`` (the first failed test, or
    empty).  Tests in order: usable, has_vertical, horizontals_compass, back azimuth
    known, distance, PGA, not a second record of a station and event already selected."""
    if pga is None:
        def pga(record_id):
            return horizontal_pga(record_id, cache_dir)
    table = catalog()
    max_km, min_pga = paper.SELECTION_MAX_DISTANCE_KM, paper.SELECTION_MIN_PGA_M_S2
    rows, recordings = [], {}
    for _, row in table.iterrows():
        value, reason = math.nan, ""
        distance, baz = csv_number(row.get("epicentral_distance_km")), csv_number(
            row.get("back_azimuth_deg"))
        if not _true(row.get("usable", True)):
            reason = "unusable (see notes)"
        elif not _true(row.get("has_vertical")):
            reason = "no vertical component"
        elif not _true(row.get("horizontals_compass")):
            reason = f"horizontals not compass azimuths (orientation {row.get('orientation')})"
        elif not math.isfinite(baz):
            reason = "back azimuth unknown"
        elif not (math.isfinite(distance) and distance < max_km):
            reason = f"epicentral distance {distance:.1f} km >= {max_km:g} km"
        else:
            value = float(pga(str(row["id"])))
            if not value > min_pga:
                reason = f"horizontal PGA {value:.2f} m/s^2 <= {min_pga:g} m/s^2"
            else:
                recording = tuple(str(row.get(k)).strip().lower()
                                  for k in ("event", "date", "station"))
                if recording in recordings:
                    reason = (f"same station and event as {recordings[recording]} "
                              "(one record per recording)")
                else:
                    recordings[recording] = str(row["id"])
        rows.append({"id": str(row["id"]), "epicentral_distance_km": distance,
                     "back_azimuth_deg": baz, "pga_h": value, "selected": reason == "",
                     "reason": reason})
    return pd.DataFrame(rows)


def horizontal_pga(record_id, cache_dir=None):
    """Peak horizontal acceleration (m/s^2, ``pga_h``) of the processed record.

    Read from ``<cache_dir>/<key>.pga.json`` when present for the record's content key;
    otherwise the record is processed (or its cached motion loaded) through
    :func:`pipeline.records.processed_motion` and the value written there.
    """
    cache_dir = Path(cache_dir) if cache_dir is not None else CACHE_DIR
    source = resolve(record_id)
    key = source.key()
    path = cache_dir / f"{key}{PGA_SUFFIX}"
    if path.is_file():
        try:
            data = json.loads(path.read_text())
            if data.get("input_hash") == key and isinstance(data.get("pga_h"), (int, float)):
                return float(data["pga_h"])
        except (OSError, ValueError):
            pass
    motion, _ = processed_motion(record_id, cache_dir=cache_dir)
    if motion.meta.get("processing", {}).get("input_hash") not in (None, key):
        raise InputError(f"{record_id}: cached motion key differs from the record's key")
    value = float(record_parameters(motion)["pga_h"])
    write_json(path, {"record_id": source.id, "input_hash": key, "pga_h": value,
                      "units": "m/s^2", "measure": "peak of the horizontal acceleration vector"})
    return value


def _true(value):
    return csv_true(value)
