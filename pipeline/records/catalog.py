"""The record catalogue ``records/catalog.csv``: one row per shipped record."""
import functools

import numpy as np
import pandas as pd

from pipeline import RECORDS_DIR

CATALOG_PATH = RECORDS_DIR / "catalog.csv"


@functools.lru_cache(maxsize=1)
def _read():
    return pd.read_csv(CATALOG_PATH, dtype={"id": str, "source_key": str, "start_utc": str,
                                            "end_utc": str, "azimuths_deg": str})


def catalog():
    """The catalogue as a DataFrame (a copy)."""
    return _read().copy()


def catalog_row(record_id):
    """The catalogue row of ``record_id`` (case-insensitive) as a dict, or None."""
    frame = _read()
    match = frame[frame["id"].str.upper() == str(record_id).upper()]
    return None if match.empty else clean(match.iloc[0].to_dict())


def clean(row):
    """NaN -> None, numpy scalars -> Python scalars."""
    return {k: (None if isinstance(v, float) and np.isnan(v) else
                v.item() if isinstance(v, np.generic) else v) for k, v in row.items()}
