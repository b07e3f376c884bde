"""Helpers of the report sections: reading tables, number formats, figure links."""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.stats.circular import circular_summary


def _read_csv(path):
    return pd.read_csv(path) if Path(path).exists() and Path(path).stat().st_size > 1 else None


def _fmt(value, digits=0):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}f}"


def _figure(results, path, caption):
    return f"![{caption}]({Path(path).relative_to(results)})\n" if Path(path).exists() else ""


def _spread(azimuths):
    """Axial spread (deg) of downfall azimuths: circular std of doubled angles, halved."""
    values = np.asarray([a for a in azimuths if math.isfinite(a)])
    if len(values) < 2:
        return None
    return circular_summary(values, axial=True)["circular_std_deg"]


def _table(frame):
    return frame.to_markdown(index=False) if frame is not None and not frame.empty else "(none)"


def _percent(value):
    return "-" if not math.isfinite(value) else f"{100 * value:.0f} %"


def _p(value):
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:.2g}" if value >= 0.001 else "< 0.001"


def _pct(value):
    return "-" if value is None or not math.isfinite(value) else f"{100 * value:.0f} %"
