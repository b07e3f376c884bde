"""One-time extraction of the gmprocess demo records shipped under ``records/``.

Not a runtime dependency.  Source: the ``gmprocess`` 2.8.0 wheel on PyPI
(USGS, public domain), directory ``gmprocess/data/demo/``:

- ``ci38457511/raw/CICCC.RAW``, ``CICLC.v1``, ``CITOW2.RAW``: CSMIP/DMG
  Volume 1 text (uncorrected acceleration in g, 100 samples/s) of the 2019
  Ridgecrest sequence.  Copied byte for byte, gzip-compressed.
- ``nc72282711/workspace.h5``: ASDF (HDF5) file of the 2014 South Napa
  earthquake, station CE.68150.  Only the raw waveforms (counts), the
  StationXML and the QuakeML are kept; gmprocess' caches and processed
  traces are dropped.

    unzip gmprocess-2.8.0-py3-none-any.whl -d /tmp/gmprocess
    python records/tools/extract_gmprocess_demo.py /tmp/gmprocess/gmprocess/data/demo records
"""
import gzip
import shutil
import sys
from pathlib import Path

import h5py

V1_FILES = {"CICCC.RAW": "ridgecrest2019/CI.CCC.V1.gz",
            "CICLC.v1": "ridgecrest2019/CI.CLC.V1.gz",
            "CITOW2.RAW": "ridgecrest2019/CI.TOW2.V1.gz"}


def extract(demo_dir, records_dir):
    demo_dir, records_dir = Path(demo_dir), Path(records_dir)
    for name, target in V1_FILES.items():
        out = records_dir / target
        out.parent.mkdir(parents=True, exist_ok=True)
        with open(demo_dir / "ci38457511" / "raw" / name, "rb") as src, \
                gzip.GzipFile(out, "wb", mtime=0) as dst:
            shutil.copyfileobj(src, dst)
    out = records_dir / "napa2014" / "CE.68150.h5"
    out.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(demo_dir / "nc72282711" / "workspace.h5", "r") as src, \
            h5py.File(out, "w") as dst:
        for key, value in src.attrs.items():
            dst.attrs[key] = value
        src.copy("QuakeML", dst)
        station = dst.create_group("Waveforms/CE.68150")
        for name, dataset in src["Waveforms/CE.68150"].items():
            if name == "StationXML" or name.endswith("_unprocessed"):
                station.create_dataset(name, data=dataset[()], compression="gzip")
                for key, value in dataset.attrs.items():
                    station[name].attrs[key] = value


if __name__ == "__main__":
    extract(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "records")
