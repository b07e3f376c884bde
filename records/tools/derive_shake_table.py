#!/usr/bin/env python3
"""Derive the granite shake-table set in ``records/shake_table/`` from a git
mirror of github.com/ZhiangChen/virtual_shake_robot_pybullet (GPL-3.0).

Reads the bare mirror with ``git show`` (no work tree needed) and writes,
deterministically (reruns give the same bytes):

* ``tests.csv``       one row per test of Earthquake_Records_Info.xlsx (582):
                      test, date, pga_g, pgv_pga_s, sp1_overturned, motion_file
* ``motions/Test###.txt.gz``  table acceleration (column 2 of the 800 Hz lab
                      file, g, raw: no offset removal, no band-pass),
                      decimated 800 -> 200 Hz with scipy.signal.decimate
                      (q=4, ftype='fir', zero_phase=True); gzip mtime 0
* ``SP1.obj``         byte copy of data/SP1_PBRmodel/SP1.obj
* ``final_sp2_1.obj`` byte copy of models/SP2_PBRmodel/final_sp2_1.obj (SP2's mesh only:
                      a file-format test; its outcomes stay held out)
* ``sp1.json``        specimen description (mesh, mass, rest pose, table axis)
* ``sp1_numerical.csv`` the providers' own numerical models of SP1 (their 0/1
                      predictions per test, columns "Specimen 1-Numerical ...")
* ``LICENSE``         the repository's GPL-3.0 text

Only the SP1 columns of Results_Granite.xlsx are read (the outcome and the providers'
numerical models of SP1); the SP2 columns are held-out validation data and are
deliberately never read or written.

``--check`` additionally prints the PGA / onset / offset / length statistics
quoted in the README (nothing extra is written).

Usage: derive_shake_table.py [MIRROR_GIT_DIR] [--out DIR] [--check]
Needs numpy, scipy, openpyxl, pandas.
"""
from __future__ import annotations

import argparse
import csv
import gzip
import hashlib
import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy import signal

DEFAULT_MIRROR = "/work/.mirror/ZhiangChen+virtual_shake_robot_pybullet/repo"
COMMIT_EXPECTED = "9f239e7"
REPO_URL = "https://github.com/ZhiangChen/virtual_shake_robot_pybullet"
STR = "data/Shake_Table_Response"
SRC = {
    "info": f"{STR}/Earthquake_Records_Info.xlsx",
    "results": f"{STR}/Results_Granite.xlsx",
    "mesh": "data/SP1_PBRmodel/SP1.obj",
    "sp2_mesh": "models/SP2_PBRmodel/final_sp2_1.obj",
    "yaml": "config/sp1.yaml",
    "license": "LICENSE",
}
FS_RAW = 800.0
DECIM = 4
FS_OUT = FS_RAW / DECIM
SP1_COLUMN_HEADER = "Experimental Results for response-Specimen 1"
SP1_NUMERICAL_PREFIX = "Specimen 1-Numerical "
HERE = Path(__file__).resolve().parent
DEFAULT_OUT = HERE.parent / "shake_table"


# ---------------------------------------------------------------- git helpers
def git(mirror: str, *args: str) -> bytes:
    return subprocess.run(["git", "-C", mirror, *args], check=True,
                          capture_output=True).stdout


def git_show(mirror: str, path: str) -> bytes:
    return git(mirror, "show", f"HEAD:{path}")


def blob_status(mirror: str) -> dict[str, str | None]:
    """Test###.txt path -> blob sha if present in the mirror, else None."""
    rows = git(mirror, "ls-tree", "HEAD", f"{STR}/").decode().splitlines()
    shas = {}
    for r in rows:
        meta, path = r.split("\t", 1)
        name = path.rsplit("/", 1)[-1]
        if name.startswith("Test") and name.endswith(".txt"):
            shas[name[:-4]] = meta.split()[2]
    chk = subprocess.run(["git", "-C", mirror, "cat-file", "--batch-check"],
                         input="\n".join(shas.values()) + "\n", text=True,
                         capture_output=True, check=True).stdout.splitlines()
    out = {}
    for (test, sha), line in zip(shas.items(), chk):
        out[test] = sha if line.split()[-1] != "missing" else None
    return out


# --------------------------------------------------------------- spreadsheets
def read_xlsx(data: bytes):
    import openpyxl
    wb = openpyxl.load_workbook(io.BytesIO(data), data_only=True, read_only=True)
    return [list(r) for r in wb.worksheets[0].iter_rows(values_only=True)]


def load_tests(mirror: str) -> list[dict]:
    info = read_xlsx(git_show(mirror, SRC["info"]))
    hdr_i = next(i for i, r in enumerate(info) if r and r[0] is not None
                 and str(r[0]).strip() == "Test No.")
    hdr = [str(c).strip() if c is not None else "" for c in info[hdr_i]]
    ci = {k: hdr.index(k) for k in ("Test No.", "Date", "PGV/PGA", "Scaled PGA (g)")}
    tests = []
    for r in info[hdr_i + 1:]:
        if r[ci["Test No."]] is None:
            continue
        d = str(int(r[ci["Date"]]))
        tests.append({
            "num": int(r[ci["Test No."]]),
            "date": f"{d[:4]}-{d[4:6]}-{d[6:]}",
            "pga_g": float(r[ci["Scaled PGA (g)"]]),
            "pgv_pga_s": float(r[ci["PGV/PGA"]]),
        })
    # outcomes: SP1 column only (the SP2 column is never touched)
    res = read_xlsx(git_show(mirror, SRC["results"]))
    rh = [str(c).strip() if c is not None else "" for c in res[0]]
    assert rh[0] == "Test Number", rh[0]
    c1 = rh.index(SP1_COLUMN_HEADER)
    sp1 = {}
    for r in res[1:]:
        if r[0] is None:
            continue
        v = r[c1]
        if v not in (0, 1):
            raise ValueError(f"unexpected SP1 outcome {v!r} for test {r[0]}")
        sp1[int(r[0])] = int(v)
    for t in tests:
        t["sp1_overturned"] = sp1[t["num"]]
        t["test"] = f"Test{t['num']:03d}"
    if len(sp1) != len(tests):
        raise ValueError("Results_Granite and Earthquake_Records_Info differ in test count")
    return tests


# -------------------------------------------------------------------- motions
def read_record(mirror: str, test: str) -> np.ndarray:
    """Raw 800 Hz record: array (n, 8) of the 8 numeric columns."""
    import pandas as pd
    raw = git_show(mirror, f"{STR}/{test}.txt")
    df = pd.read_csv(io.BytesIO(raw), sep="\t", header=0, usecols=range(8),
                     dtype=float, engine="c")
    a = df.to_numpy()
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{test}: non-finite values")
    return a


def gzip_bytes(text: bytes) -> bytes:
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0,
                       compresslevel=9) as gz:
        gz.write(text)
    return buf.getvalue()


def decimated(acc: np.ndarray) -> np.ndarray:
    """The 800 Hz acceleration as shipped: 200 Hz, zero-phase FIR anti-alias filter."""
    return signal.decimate(acc, DECIM, ftype="fir", zero_phase=True)


def motion_text(test: str, sha: str, t: np.ndarray, acc: np.ndarray) -> bytes:
    # the source time column is k/800 s printed with 6 significant digits
    # (steps alternate 0.0012/0.0013 s after 10 s); write exact k/200 s
    k = np.arange(len(t))
    if t[0] != 0 or np.max(np.abs(t - k / FS_RAW)) > 1e-4:
        raise ValueError(f"{test}: time column is not k/{FS_RAW:g} s")
    a_dec = decimated(acc)
    t_dec = np.arange(len(a_dec)) / FS_OUT
    assert len(a_dec) == len(t[::DECIM])
    head = (
        f"lab-table: granite shake-table test {test} (Chen et al. 2024), table acceleration\n"
        "units: g\n"
        "axes: 270\n"
        "axis note: one axis, the table's shaking direction, the providers' simulation x axis = "
        "East of the toolkit's scene (sp1.json); positive accel_g along -x (West): the "
        "band-passed acceleration is anti-correlated with the LVDT's second derivative "
        "(median r = -0.73)\n"
        f"source: {REPO_URL} commit {COMMIT_EXPECTED} {STR}/{test}.txt (git blob {sha})\n"
        f"quantity: shake-table acceleration, column 2 of the source ('Amplitude - Plot 0', "
        f"'Acceleration (g)' per {STR}/NOTES.docx), raw: no offset removal, no band-pass\n"
        "axis: the table's shaking direction (the direction of the LVDT displacement, source column 6, "
        "which the providers' simulation drives along world x); the source's orthogonal-direction "
        "acceleration (column 4, 'of no use' per NOTES.docx) is not included: single axis\n"
        f"sampling: {FS_OUT:g} Hz, decimated from {FS_RAW:g} Hz by scipy.signal.decimate(q={DECIM}, "
        "ftype='fir', zero_phase=True); time_s = k/200 (source sample 4k; source time column is k/800 s "
        "to 6 significant digits)\n"
        "units: time_s = s, accel_g = g (standard gravity)\n"
        "licence: GPL-3.0 (see ../LICENSE)\n"
        "time_s accel_g"
    )
    buf = io.BytesIO()
    np.savetxt(buf, np.column_stack([t_dec, a_dec]), fmt="%.6g", delimiter=" ",
               header=head, comments="# ")
    return buf.getvalue()


# ---------------------------------------------------------------- check stats
def bandpass(x: np.ndarray, fs: float) -> np.ndarray:
    b, a = signal.butter(3, [0.1, 25.0], btype="band", fs=fs)
    return signal.filtfilt(b, a, x)


def record_stats(t: np.ndarray, acc: np.ndarray, disp: np.ndarray) -> dict:
    abp = bandpass(acc, FS_RAW)
    pk = float(np.max(np.abs(abp)))
    onset_i = int(np.argmax(np.abs(abp) > 0.05 * pk))
    base = float(np.median(acc[:200]))
    onset_raw = float(t[int(np.argmax(np.abs(acc - base) > max(0.02, 0.1 * pk)))])
    pre = acc[: max(onset_i, 1)]
    one = acc[: int(FS_RAW)]
    # sign check: bandpassed accel vs 2nd derivative of bandpassed LVDT
    d = bandpass(disp * 5.9797e-4 * 0.0254, FS_RAW)
    dd = np.gradient(np.gradient(d, 1 / FS_RAW), 1 / FS_RAW) / 9.80665
    corr = float(np.corrcoef(abp, dd)[0, 1])
    return {
        "length_s": float(t[-1] - t[0] + 1 / FS_RAW),
        "t0": float(t[0]),
        "dt_ok": bool(np.max(np.abs(t - np.arange(len(t)) / FS_RAW)) <= 1e-4),
        "peak_bp_g": pk,
        "peak_raw_g": float(np.max(np.abs(acc))),
        "onset_s": float(t[onset_i] - t[0]),
        "onset_raw_s": onset_raw,
        "offset_median_first_0p25s_g": base,
        "offset_pre_g": float(np.mean(pre)),
        "offset_first1s_g": float(np.mean(one)),
        "noise_pre_g": float(np.std(pre)),
        "offset_mean_g": float(np.mean(acc)),
        "corr_acc_lvdt": corr,
        "peak_lvdt_g": float(np.max(np.abs(dd))),
    }


# ----------------------------------------------------------------------- main
def sha256(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()


def sp1_numerical(mirror: str) -> tuple[list[str], list[list]]:
    """The providers' numerical models of SP1: (column names, rows of test and 0/1 per
    model). Only the header row and the columns named "Specimen 1-Numerical ..." are
    read (no SP2 column)."""
    res = read_xlsx(git_show(mirror, SRC["results"]))
    rh = [str(c).strip() if c is not None else "" for c in res[0]]
    cols = [k for k, h in enumerate(rh) if h.startswith(SP1_NUMERICAL_PREFIX)]
    names = []
    for k in cols:      # "Specimen 1-Numerical KN=10 KS=1" -> "kn10_ks1"
        words = rh[k][len(SP1_NUMERICAL_PREFIX):].replace("=", "").lower().split()
        names.append("_".join(words))
    rows = []
    for r in res[1:]:
        if r[0] is None:
            continue
        values = [r[k] for k in cols]
        if any(v not in (0, 1) for v in values):
            raise ValueError(f"unexpected SP1 numerical prediction {values} for test {r[0]}")
        rows.append([f"Test{int(r[0]):03d}", *(int(v) for v in values)])
    return names, rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mirror", nargs="?", default=DEFAULT_MIRROR)
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    ap.add_argument("--check", action="store_true", help="print PGA/onset/offset statistics")
    args = ap.parse_args(argv)
    mirror, out = args.mirror, Path(args.out)
    head = git(mirror, "rev-parse", "HEAD").decode().strip()
    if not head.startswith(COMMIT_EXPECTED):
        print(f"warning: mirror HEAD {head} is not {COMMIT_EXPECTED}", file=sys.stderr)
    (out / "motions").mkdir(parents=True, exist_ok=True)

    tests = load_tests(mirror)
    blobs = blob_status(mirror)
    if set(blobs) != {t["test"] for t in tests}:
        raise ValueError("test list in the tree differs from the spreadsheet")

    stats = {}
    for t in tests:
        sha = blobs[t["test"]]
        if sha is None:
            t["motion_file"] = ""
            continue
        rec = read_record(mirror, t["test"])
        time, acc = rec[:, 0], rec[:, 1]
        name = f"motions/{t['test']}.txt.gz"
        (out / name).write_bytes(gzip_bytes(motion_text(t["test"], sha, time, acc)))
        t["motion_file"] = name
        if args.check:
            stats[t["test"]] = record_stats(time, acc, rec[:, 5])

    with open(out / "tests.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["test", "date", "pga_g", "pgv_pga_s", "sp1_overturned", "motion_file",
                    "pga_nominal"])
        for t in tests:
            # tests 180-247 (2021-07-06/08): PGA 0.7, 1.1 or 1.5 exactly, PGV/PGA copied from
            # earlier tests of the same motion: nominal values, not measured (README.md)
            nominal = int(180 <= t["num"] <= 247 and t["pga_g"] in (0.7, 1.1, 1.5))
            w.writerow([t["test"], t["date"], repr(t["pga_g"]), repr(t["pgv_pga_s"]),
                        t["sp1_overturned"], t["motion_file"], nominal])

    names, rows = sp1_numerical(mirror)
    with open(out / "sp1_numerical.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["test", *names])
        w.writerows(rows)

    mesh = git_show(mirror, SRC["mesh"])
    (out / "SP1.obj").write_bytes(mesh)
    (out / "final_sp2_1.obj").write_bytes(git_show(mirror, SRC["sp2_mesh"]))
    (out / "LICENSE").write_bytes(git_show(mirror, SRC["license"]))
    (out / "sp1.json").write_text(json.dumps(sp1_json(), indent=2) + "\n")

    print("SHA-256 of sources:")
    for k in ("info", "results", "mesh", "sp2_mesh", "yaml", "license"):
        print(f"    {sha256(git_show(mirror, SRC[k]))}  {SRC[k]}")
    n_mot = sum(1 for t in tests if t["motion_file"])
    print(f"tests: {len(tests)}, with motion: {n_mot}, missing: {len(tests) - n_mot}")
    if args.check:
        print_check(tests, stats)
    return 0


def sp1_json() -> dict:
    """Specimen SP1 as the toolkit reads it (pipeline/scenario/mesh.py; evidence for each
    value in README.md and in provider_notes())."""
    return {
        "name": "SP1",
        "mesh": "SP1.obj",
        "mass_kg": 353.802,
        "units": "m",
        "rest_pose": "nearest",
        "footprint_tolerance_m": 0.003,
        "source": (f"Chen et al. (2024), Seismica 3(1); {REPO_URL} at {COMMIT_EXPECTED}: "
                   "data/SP1_PBRmodel/SP1.obj, mass from config/sp1.yaml (GPL-3.0)"),
        "notes": ("Scan of granite specimen SP1 in the providers' rest orientation (z up); the "
                  "table shakes along the mesh's x axis (the providers' prismatic joint), East "
                  "in the scene. With a 3 mm footprint tolerance its critical angle toward +x "
                  "is 14.7 deg, as stated for the rock; with 1 mm it stands on its lowest asperities (5.4 "
                  "deg toward +x). The shake-table campaign calibrates the tolerance on the "
                  "June-July tests. See README.md."),
    }


def provider_notes() -> dict:
    """What the providers' files say about SP1 (kept for README.md)."""
    return {
        "specimen": "SP1 (granite precariously balanced rock, shake-table specimen 1)",
        "mesh": "SP1.obj",
        "mesh_units": "m",
        "mesh_note": ("scan mesh as provided (Meshlab export, 14335 vertices, 28666 faces, "
                      "closed); its faces are wound inwards (signed volume -0.12386 m^3): "
                      "flip the winding or use |volume|. Coordinates are not centred: "
                      "centroid (solid) at (1.80169, 51.74461, 311.92726) m, lowest vertex "
                      "0.29445 m below it."),
        "mass_kg": 353.802,
        "mass_source": ("config/sp1.yaml line 6 'mass: 353.802' (also src/inertia.py line 16 "
                        "'target_mass = 353.802', docs/inertia.md lines 44 and 84); "
                        "models/SP1_PBRmodel/sp1.urdf line 7 has '<mass value=\"353.00\"/>'"),
        "mesh_volume_m3": 0.12386,
        "implied_density_kg_m3": 2856.5,
        "rest_rotation_quat_wxyz": [1.0, 0.0, 0.0, 0.0],
        "rest_rotation_note": (
            "identity: SP1.obj is already in the providers' rest orientation, z up. "
            "The providers simulate models/SP1_PBRmodel/final_sp1_pca.obj (sp1.urdf), which is "
            "final_sp1.obj rotated to principal axes by src/inertia.py; config/sp1.yaml "
            "rock_orientation [x,y,z,w] = [0.86766, 0.06594, 0.47910, 0.11521] (pybullet "
            "xyzw) is the inverse of that rotation, so the spawned rock has exactly the "
            "orientation of final_sp1.obj (checked: max vertex mismatch 9e-9 m), and "
            "final_sp1.obj is SP1.obj translated to its centroid (ICP residual rotation 0.03 deg, "
            "translation < 0.1 mm). Only a translation is needed: put the lowest point on the table."),
        "rest_base_tilt_deg": 0.36,
        "rest_base_note": ("largest nearly-horizontal downward convex-hull facets of SP1.obj: "
                           "0.0394 m^2 tilted 1.06 deg and 0.0134 m^2 tilted 0.36 deg; the "
                           "mesh is not re-levelled here"),
        "providers_spawn_position_m": [0.0, 0.0, 2.78],
        "providers_spawn_note": ("config/sp1.yaml rock_position: world position of the centroid "
                                 "at spawn; the rock is dropped onto the pedestal and settles"),
        "table_axis_in_mesh_frame": [1.0, 0.0, 0.0],
        "table_axis_note": (
            "providers' simulation drives the pedestal by a prismatic joint with axis [1, 0, 0] "
            "(src/simulation_node.py lines 540-541), i.e. world x; with the identity rest "
            "rotation this is mesh +x. The providers drive that joint with the LVDT displacement "
            "(source column 6, src/data_loader.py lines 61-70), not with the accelerometer. "
            "Sign: the band-passed accelerometer (motions/) is anti-correlated with the second "
            "derivative of the LVDT displacement in most records (median r = -0.73, 95 % of the "
            "490 records below -0.03), so positive accel_g most likely points along -x of the "
            "providers' frame; the providers state no sign convention. The lab orientation of "
            "the rock on the table is only known through this simulation setup."),
        "up_axis_in_mesh_frame": [0.0, 0.0, 1.0],
        "source": f"{REPO_URL} commit {COMMIT_EXPECTED}",
        "licence": "GPL-3.0",
    }


def print_check(tests: list[dict], stats: dict) -> None:
    by = {t["test"]: t for t in tests}
    ks = sorted(stats)
    def q(v):
        v = np.asarray(v)
        return (f"min {v.min():.4g}  p5 {np.percentile(v, 5):.4g}  p25 {np.percentile(v, 25):.4g}  "
                f"median {np.median(v):.4g}  p75 {np.percentile(v, 75):.4g}  "
                f"p95 {np.percentile(v, 95):.4g}  max {v.max():.4g}")
    ratio = [stats[k]["peak_bp_g"] / by[k]["pga_g"] for k in ks]
    print("n records", len(ks), " uniform 800 Hz:", all(stats[k]["dt_ok"] for k in ks),
          " t0==0:", all(stats[k]["t0"] == 0 for k in ks))
    print("peak |bandpassed accel| / summary PGA:", q(ratio))
    print("peak |raw accel| / summary PGA:      ", q([stats[k]["peak_raw_g"] / by[k]["pga_g"] for k in ks]))
    print("peak LVDT-derived accel / summary PGA:", q([stats[k]["peak_lvdt_g"] / by[k]["pga_g"] for k in ks]))
    print("corr(bandpassed accel, LVDT'' ):      ", q([stats[k]["corr_acc_lvdt"] for k in ks]))
    print("length s:                            ", q([stats[k]["length_s"] for k in ks]))
    print("onset s (|bp|>5% peak):              ", q([stats[k]["onset_s"] for k in ks]))
    print("onset s (|raw-base|>max(.02g,10%pk)):", q([stats[k]["onset_raw_s"] for k in ks]))
    print("offset g (median first 0.25 s):      ", q([stats[k]["offset_median_first_0p25s_g"] for k in ks]))
    print("offset g (mean before onset):        ", q([stats[k]["offset_pre_g"] for k in ks]))
    print("offset g (mean first 1 s):           ", q([stats[k]["offset_first1s_g"] for k in ks]))
    print("offset g (mean whole record):        ", q([stats[k]["offset_mean_g"] for k in ks]))
    print("noise g (std before onset):          ", q([stats[k]["noise_pre_g"] for k in ks]))
    r = np.array(ratio)
    bad = [(k, round(x, 3)) for k, x in zip(ks, r) if x < 0.7 or x > 1.5]
    print("ratio outside [0.7, 1.5]:", len(bad), bad[:40])
    nominal = [t["test"] for t in tests if t["pga_g"] in (0.7, 1.1, 1.5)]
    print("summary PGA exactly 0.7/1.1/1.5 g:", len(nominal), " ".join(nominal))
    print("  of which with motion:", sum(1 for k in nominal if k in stats))
    print("ratio without those:", q([stats[k]["peak_bp_g"] / by[k]["pga_g"] for k in ks if k not in nominal]))
    months = {}
    for t in tests:
        m = t["date"][:7]
        d = months.setdefault(m, [0, 0, 0, 0])
        d[0] += 1
        d[1] += bool(t["motion_file"])
        d[2] += t["sp1_overturned"]
        d[3] += t["sp1_overturned"] and bool(t["motion_file"])
    print("month: tests, with motion, SP1 overturned (all), SP1 overturned (with motion)")
    for m, d in sorted(months.items()):
        print("   ", m, d)
    print("missing:", " ".join(t["test"] for t in tests if not t["motion_file"]))


if __name__ == "__main__":
    sys.exit(main())
