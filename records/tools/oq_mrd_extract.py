"""One-time tool (kept for provenance): the mean rate density of PGA and PGV of an
OpenQuake classical calculation, written as a small HDF5 extract of its datastore.

Run with the OpenQuake engine's own Python (it imports ``openquake``; the project does
not), e.g. ``/path/to/oq-venv/bin/python records/tools/oq_mrd_extract.py CALC.hdf5
OUT.hdf5``.  ``CALC.hdf5`` is the datastore of a classical calculation whose ``job.ini``
sets ``postproc_func = dummy.main`` (so the engine keeps the ruptures' contexts, as the
engine's own test of ``compute_mrd`` does) or already holds an ``mrd``.

Where the datastore holds no ``mrd``, the engine's post-processor
``openquake.calculators.postproc.compute_mrd.main`` computes it, with ``imt1='PGA'``,
``imt2='PGV'`` and ``method='direct'`` (the rate density of each rupture from the
bivariate normal of ln PGA and ln PGV), on a copy of the datastore.  Its
``cross_correlation`` must be a class of ``openquake.hazardlib.cross_correlation`` with a
correlation matrix; the engine's PGA-PGV model ``Bradley2012`` has none (engine 3.26.2),
so this tool adds ``Bradley2012Matrix``: the same ``Bradley2012.get_correlation`` (0.733
between ln PGA and ln PGV) given the matrix interface of ``CrossCorrelation``.  Nothing
else of the engine is changed.

The extract keeps the datastore's own names and layout, so the project's reader reads the
engine's datastore and the extract alike: ``mrd`` (L-1 x L-1 x sites, axis 0 the second
IMT, axis 1 the first, as ``openquake.hazardlib.calc.mrd`` fills it), ``oqparam`` (the
calculation's parameters, JSON; its ``postproc_func``/``postproc_args`` set to the call
that made the ``mrd``), ``sitecol/{sids,lon,lat}``, ``hcurves-stats`` and
``hcurves-rlzs`` (probabilities of exceedance in the investigation time, with their
``json`` attribute), ``weights`` (of the realisations) and the root attributes
``engine_version``, ``date`` and ``checksum32``.
"""
import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

MRD_ARGS = {"imt1": "PGA", "imt2": "PGV", "cross_correlation": "Bradley2012Matrix",
            "seed": 42, "meabins": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
            "sigbins": [0.2, 0.3, 0.4, 0.5, 0.6, 0.7], "method": "direct"}
KEPT = ("mrd", "sitecol/sids", "sitecol/lon", "sitecol/lat", "hcurves-stats",
        "hcurves-rlzs", "weights")


def compute_mrd(calc_path, work_dir):
    """A copy of the datastore ``calc_path`` in ``work_dir`` with the engine's ``mrd``."""
    from openquake.calculators.postproc import compute_mrd as engine_mrd
    from openquake.commonlib import datastore
    from openquake.hazardlib import cross_correlation as cc

    class Bradley2012Matrix(cc.CrossCorrelation):
        """The engine's Bradley (2012) PGV correlation with a correlation matrix."""
        def get_correlation(self, from_imt, to_imt):
            return float(cc.Bradley2012().get_correlation(from_imt, to_imt))

    cc.Bradley2012Matrix = Bradley2012Matrix
    copy = Path(work_dir) / Path(calc_path).name
    shutil.copyfile(calc_path, copy)
    dstore = datastore.read(str(copy), mode="r+")
    try:
        engine_mrd.main(dstore, **MRD_ARGS)
    finally:
        dstore.close()
    return copy


def write_extract(calc_path, out_path, computed):
    """Copy what the reader needs of the datastore ``calc_path`` to ``out_path``."""
    with h5py.File(calc_path, "r") as src, h5py.File(out_path, "w") as dst:
        for name in KEPT:
            if name in src:
                dst.create_dataset(name, data=src[name][()])
                for key, value in src[name].attrs.items():
                    dst[name].attrs[key] = value
        params = json.loads(src["oqparam"][()])
        for key in ("base_path", "inputs", "export_dir", "exports"):
            params.pop(key, None)          # paths of the machine that ran it
        if computed:
            params["postproc_func"] = "compute_mrd.main"
            params["postproc_args"] = MRD_ARGS
        dst.create_dataset("oqparam", data=json.dumps(params, indent=1).encode())
        for key in ("engine_version", "date", "checksum32"):
            dst.attrs[key] = src.attrs[key]
        dst.attrs["extracted_by"] = "records/tools/oq_mrd_extract.py"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("calc", help="the calculation's datastore (calc_N.hdf5)")
    parser.add_argument("out", help="the extract to write (.hdf5)")
    args = parser.parse_args(argv)
    with h5py.File(args.calc, "r") as f:
        has_mrd = "mrd" in f
    with tempfile.TemporaryDirectory() as work:
        calc = args.calc if has_mrd else compute_mrd(args.calc, work)
        write_extract(calc, args.out, computed=not has_mrd)
    with h5py.File(args.out, "r") as f:
        mrd = f["mrd"][()]
        print(f"{args.out}: mrd {mrd.shape}, total rate {np.sum(mrd):.6g} /yr")


if __name__ == "__main__":
    sys.exit(main())
