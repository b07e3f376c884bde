"""The shake-table experiments and the parameter grid a specimen is calibrated over.

An experiment set is a CSV (records/shake_table/tests.csv, read by
:func:`load_experiments`) with one row per test: ``test``, ``date`` (yyyy-mm-dd),
``pga_g``, ``pgv_pga_s``, the observed outcome (column ``--outcome``, 1 = overturned)
and ``motion_file`` (a lab table, :mod:`pipeline.records.readers.lab_table`, relative to
the CSV; empty when the motion is missing).  A grid (``--grid``, :func:`parse_grid`) names
contact parameters (m, N/m, dimensionless), the specimen's footprint tolerance (m) and the
table motion's turn (deg); :data:`CALIBRATION_NEIGHBOURHOOD` is the one home of the values
the calibration tries (the members' ranges: :mod:`pipeline.campaign.member_ranges`).
"""
import dataclasses
import io
import itertools
import math
from datetime import date
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.campaign.member_ranges import number_text
from pipeline.files import InputError
from pipeline.records import RECORDS_DIR
from pipeline.scenario.geometry import ColumnGeometry
from pipeline.scenario.parameters import Contact
from pipeline.userfiles import DATA_FILE_BYTES, check_regular, read_user_text, show

EXPERIMENTS = RECORDS_DIR / "shake_table" / "tests.csv"
SPECIMEN = RECORDS_DIR / "shake_table" / "sp1.json"
OUTCOME = "sp1_overturned"
AXIS_DEG = 90.0                  # the shipped tests shake along East-West
VALIDATE_FROM = "2021-08-01"     # calibrate on the June-July tests, validate on August's
COLUMNS = ("test", "date", "pga_g", "pgv_pga_s", "motion_file")
# what --grid may vary: contact parameters, and the specimen's footprint tolerance
# (the bounds of Contact's fields; mu_k within mu_s's, and mu_k <= mu_s per point)
GRID_CONTACT = {f.name: (f.metadata["low"], f.metadata["high"])
                for f in dataclasses.fields(Contact) if f.metadata["low"] is not None}
GRID_CONTACT["mu_k"] = GRID_CONTACT["mu_s"]
GRID_SPECIMEN = {"footprint_tolerance_m": (0.0, 0.05)}
# and the motion: rotate_deg turns the table motion clockwise (180: the other sign of an
# axis whose sign the laboratory does not state)
GRID_MOTION = {"rotate_deg": (0.0, 360.0)}
# The shake-table calibration's neighbourhood of a rock's seating and contact: per
# parameter the values the calibration grid tries (footprint and damping: two values each;
# mu_s: 0.3, the providers' PyBullet value, and 0.7; rotate_deg: both signs of the
# table's axis; kn: the contact's own, the paper's or a contact file's).  The ranges a
# fragility's members draw are declared apart, in pipeline.campaign.member_ranges.
CALIBRATION_NEIGHBOURHOOD = {
    "footprint_tolerance_m": (0.001, 0.003),
    "damping": (0.05, 0.1),
    "mu_s": (0.3, 0.7),
    "rotate_deg": (0, 180),
}


def neighbourhood_grid():
    """The calibration grid's text (``name=V,V;...``) of the neighbourhood."""
    return ";".join(f"{name}={','.join(number_text(v) for v in grid)}"
                    for name, grid in CALIBRATION_NEIGHBOURHOOD.items())


DEFAULT_GRID = neighbourhood_grid()
DEFAULT_CONTACT = dataclasses.asdict(Contact())      # the paper's contact
PGA_EDGES_G = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0, 2.0])
PGV_PGA_EDGES_S = np.array([0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0])


def load_experiments(path=EXPERIMENTS, outcome=OUTCOME):
    """The experiment table (pandas DataFrame; ``observed`` bool, ``motion_path`` Path or
    None).  One-line InputError for a missing column, a bad date, an outcome not 0/1, a
    duplicated or blank test name or a motion file that is named but absent."""
    path = Path(path)
    try:
        frame = pd.read_csv(io.StringIO(read_user_text(path, "experiment table",
                                                       DATA_FILE_BYTES)),
                            dtype={"test": str, "motion_file": str},
                            keep_default_na=False)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path.name}: not a readable experiment table "
                         f"({str(exc).splitlines()[0][:120]})") from None
    missing = [c for c in COLUMNS + (outcome,) if c not in frame.columns]
    if missing:
        raise InputError(f"{path.name}: missing column(s) {', '.join(missing)}")
    if frame.empty:
        raise InputError(f"{path.name}: no experiments (a header and no rows)")
    for row, name in enumerate(frame["test"], start=2):
        if not (name.strip() and name.isprintable() and len(name) <= 200):
            raise InputError(f"{path.name}, row {row}: test name {show(name)} must be 1-200 "
                             "printable characters, not blank")
    if frame["test"].duplicated().any():
        raise InputError(f"{path.name}: test {frame['test'][frame['test'].duplicated()].iloc[0]}"
                         " appears twice")
    for column in ("pga_g", "pgv_pga_s"):
        values = pd.to_numeric(frame[column], errors="coerce")
        if not (np.isfinite(values) & (values >= 0)).all():
            raise InputError(f"{path.name}: column {column} must hold numbers >= 0")
        frame[column] = values
    try:
        frame["day"] = [date.fromisoformat(d) for d in frame["date"]]
    except ValueError as exc:
        raise InputError(f"{path.name}: bad date ({exc}); expected yyyy-mm-dd") from None
    observed = pd.to_numeric(frame[outcome], errors="coerce")
    if not observed.isin([0, 1]).all():
        raise InputError(f"{path.name}: column {outcome} must be 0 or 1")
    frame["observed"] = observed.astype(bool)
    paths = []
    for name in frame["motion_file"]:
        motion = path.parent / name if name else None
        if motion is not None:
            check_regular(motion, f"{path.name}: motion file")
            if not motion.is_file():
                raise InputError(f"{path.name}: motion file {name} not found")
        paths.append(motion)
    frame["motion_path"] = paths
    return frame

def parse_grid(text):
    """``name=v1,v2;name=v1`` -> list of parameter dicts (the Cartesian product)."""
    axes = {}
    for item in (text or "").split(";"):
        if not item.strip():
            continue
        name, _, values = item.partition("=")
        name = name.strip()
        bounds = GRID_CONTACT.get(name) or GRID_SPECIMEN.get(name) or GRID_MOTION.get(name)
        if bounds is None:
            raise InputError(f"--grid: unknown parameter {name!r} (known: "
                             f"{', '.join([*GRID_CONTACT, *GRID_SPECIMEN, *GRID_MOTION])})")
        try:
            numbers = [float(v) for v in values.split(",") if v.strip()]
        except ValueError:
            raise InputError(f"--grid {name}: values must be numbers, got {values!r}") from None
        if not numbers or not all(math.isfinite(v) and bounds[0] <= v <= bounds[1]
                                  for v in numbers):
            raise InputError(f"--grid {name}: values in [{bounds[0]:g}, {bounds[1]:g}] needed, "
                             f"got {values!r}")
        if name in axes:
            raise InputError(f"--grid names {name} twice")
        repeated = sorted({v for v in numbers if numbers.count(v) > 1})
        if repeated:
            raise InputError(f"--grid {name}: value {repeated[0]:g} given twice (each test "
                             "would count twice)")
        axes[name] = numbers
    names = list(axes)
    points = [dict(zip(names, combo)) for combo in itertools.product(*axes.values())] or [{}]
    for point in points:
        contact = grid_contact(point)
        if contact["mu_k"] > contact["mu_s"]:
            said = {k: "" if k in point else " (default)" for k in ("mu_s", "mu_k")}
            raise InputError(f"--grid: mu_k {contact['mu_k']:g}{said['mu_k']} above mu_s "
                             f"{contact['mu_s']:g}{said['mu_s']}: kinetic friction must not "
                             "exceed static (mu_k <= mu_s)")
    return points


def grid_contact(point, base=None):
    """The contact fields of a grid point: its values over ``base`` (a contact file's
    values) over the paper's; a point that gives mu_s without mu_k gets Contact's
    kinetic friction for that mu_s."""
    given = {k: v for k, v in point.items() if k in GRID_CONTACT}
    out = {**DEFAULT_CONTACT, **(base or {}), **given}
    if "mu_s" in given and "mu_k" not in given:
        out["mu_k"] = Contact(mu_s=given["mu_s"]).mu_k
    return out


def grid_run_params(specimen, point, base=None):
    """Run parameters of one grid point: the specimen alone at the table's centre
    (``base``: a contact file's values, which the point's override)."""
    description = dict(specimen)
    for key in GRID_SPECIMEN:
        if key in point:
            description[key] = point[key]
    ColumnGeometry.from_dict(description)          # refuse a bad point before any run
    contact = grid_contact(point, base)
    motion = {k: v for k, v in point.items() if k in GRID_MOTION and v}
    return {"column": "monolithic", "column_file": description, **contact, **motion}
