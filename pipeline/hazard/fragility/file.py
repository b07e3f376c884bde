"""``fragility.json``, the file of ``campaign fragility``, as one type
(:class:`FragilityFile`) with one writer (:func:`write_fragility_file`, atomic) and one
reader (:func:`read_fragility_file`: bounded, strict UTF-8, JSON, what a part cannot
check alone checked by :func:`pipeline.hazard.fragility.check.check_fragility`, each part
typed to its leaves and checking itself on construction: :mod:`~pipeline.hazard.
fragility.fits`, :mod:`~pipeline.hazard.fragility.rows`, :mod:`~pipeline.hazard.
fragility.experiments`).  The campaigns that write it, survival, the shake-table check,
the figures and the report share it.

Two layouts: a column campaign (``columns``: per column type its lognormal fits per
intensity measure and logistic surface, :class:`ColumnFits`; ``records``, ``members``,
``block2d``) and a pulse grid (``pulse_grid``, :class:`PulseGridSection`: axes
``pga_g`` (g) x ``pgv_pga_s`` (s), ``members``, ``models`` (:class:`GridModel`) with
their cells, contours and logistic surface, the 2D block :class:`Block2d`).  Keys a
section does not name are kept as written in its ``extra`` (and written back in their
place).  Older files load, brought to today's spelling here and nowhere else: a pulse
grid's 2D block without ``uplift_g_smallest`` takes it from ``uplift_g`` (the runs' median
critical angle) or, without that, from ``alpha_rad`` (g tan alpha), in that order.
"""
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from pipeline.files import write_json
from pipeline.hazard.fragility.check import MAX_MEMBERS, check_fragility, key_text
from pipeline.hazard.fragility.checker import leaf
from pipeline.hazard.fragility.damage_states import damage_states_json, damage_states_of
from pipeline.hazard.fragility.experiments import Experiments
from pipeline.hazard.fragility.fits import LognormalFit, LogisticSurface
from pipeline.hazard.fragility.rows import ContourRow, GridCell
from pipeline.hazard.fragility.keyed import Keyed
from pipeline.hazard.fragility.keyed import build as _build
from pipeline.hazard.fragility.keyed import join as _join
from pipeline.userfiles import DATA_FILE_BYTES, read_json

__all__ = ["MAX_MEMBERS", "Block2d", "ColumnFits", "ContourRow", "FragilityFile",
           "GridCell", "GridModel", "LogisticSurface", "LognormalFit",
           "PulseGridSection", "check_fragility", "read_fragility_file",
           "write_fragility_file"]


@dataclass(frozen=True)
class Block2d(Keyed):
    """The 2D rigid block beside the specimen: ``alpha_rad`` (critical angle, rad),
    ``p_per_s`` (frequency parameter, 1/s), ``R_m`` (pivot distance, m), ``uplift_g``
    (g tan alpha of the runs' median alpha, g), ``uplift_g_smallest`` (of the smallest
    alpha of any run, g), ``model`` (its model name in a pulse grid's ``models``)."""
    alpha_rad: float | None = None
    p_per_s: float | None = None
    R_m: float | None = None
    uplift_g: float | None = None
    uplift_g_smallest: float | None = None
    model: str | None = None


@dataclass(frozen=True)
class GridModel(Keyed):
    """One model of a pulse grid: ``cells`` (:class:`GridCell`), ``contours`` (level,
    e.g. "0.5", -> :class:`ContourRow` per PGV/PGA), ``logistic``
    (:class:`LogisticSurface`), ``runs`` and ``overturned`` (counts)."""
    cells: tuple = ()
    contours: dict = field(default_factory=dict)
    logistic: LogisticSurface | None = None
    runs: int | None = None
    overturned: int | None = None

    def contour(self, level):
        """The :class:`ContourRow` per PGV/PGA of the contour at P = ``level`` (a number,
        e.g. 0.5; the file's key is it as text), () where the model has none."""
        return self.contours.get(f"{float(level):g}", ())


@dataclass(frozen=True)
class PulseGridSection(Keyed):
    """``pulse_grid``: the axes ``pga_g`` (g) and ``pgv_pga_s`` (s), ``members``
    (parameter sets), ``headings`` (directions per set), ``models`` (name ->
    :class:`GridModel`), ``block2d``, ``direction`` and ``ranges`` (text), the runs
    (``runs``, ``runs_finished``, ``full_grid_runs``, ``sampling``, ``yade_wall_s_total``
    in s), ``warnings`` and ``experiments`` (the shake-table check,
    :class:`~pipeline.hazard.fragility.experiments.Experiments`, or None)."""
    pga_g: tuple = ()
    pgv_pga_s: tuple = ()
    members: int | None = None
    headings: int | None = None
    models: dict = field(default_factory=dict)
    block2d: Block2d | None = None
    direction: str | None = None
    ranges: str | None = None
    warnings: tuple = ()
    # set by the campaign after the cells, written in this order after the keys above
    runs_finished: int | None = None
    yade_wall_s_total: float | None = None
    runs: int | None = None
    full_grid_runs: int | None = None
    sampling: str | None = None
    experiments: Experiments | None = None


@dataclass(frozen=True)
class ColumnFits(Keyed):
    """One column type of a column campaign: ``description``, ``model`` ("3D" or "2D"),
    ``runs`` and ``toppled`` (counts), ``fits`` (intensity measure, e.g. "PGA", -> its
    :class:`LognormalFit`) and ``logistic`` (:class:`LogisticSurface`, in PGA and
    PGV/PGA)."""
    description: str | None = None
    model: str | None = None
    runs: int | None = None
    toppled: int | None = None
    fits: dict = field(default_factory=dict)
    logistic: LogisticSurface | None = None


@dataclass(frozen=True)
class FragilityFile(Keyed):
    """``fragility.json``: ``specimen`` (its name), ``mode`` ("pulses" for a pulse grid),
    a column campaign's ``columns`` (name -> :class:`ColumnFits`), ``records`` (ids),
    ``members``, ``block2d`` and ``damage_states`` (3D column type -> the fragility of each
    damage state, :class:`~pipeline.hazard.fragility.damage_states.ColumnStates`; None in
    files written before them), or a pulse grid's ``pulse_grid``; ``path`` where it was
    read from (None when built in memory)."""
    specimen: str | None = None
    mode: str | None = None
    columns: dict | None = None
    records: tuple = ()
    members: int | None = None
    block2d: Block2d | None = None
    pulse_grid: PulseGridSection | None = None
    damage_states: dict | None = None
    path: Path | None = field(default=None, compare=False)

    @classmethod
    def of(cls, data, path=None):
        """The file of ``data``, a dict as the campaign writes it, its fits checked (each
        refusal naming ``path``, or fragility.json, and the key path); the reader checks
        the rest (:func:`pipeline.hazard.fragility.check.check_fragility`)."""
        name = str(path) if path is not None else "fragility.json"
        return _build(cls, data, {
            "columns": lambda v: None if v is None else {
                k: _column(e, name, f"columns.{key_text(k)}") for k, e in v.items()},
            "records": lambda v: tuple(v or ()),
            "block2d": lambda v: None if v is None else _build(Block2d, v),
            "pulse_grid": lambda v: None if v is None else _section(v, name),
            "damage_states": lambda v: damage_states_of(v, name)}, path=path)

    def to_json(self):
        """The dict written to ``fragility.json``."""
        return _join(self, {
            "columns": lambda v: None if v is None else {
                k: _column_json(e) for k, e in v.items()},
            "records": list,
            "block2d": lambda v: None if v is None else _join(v),
            "pulse_grid": lambda v: None if v is None else _section_json(v),
            "damage_states": damage_states_json})


def read_fragility_file(path):
    """The :class:`FragilityFile` at ``path`` (a fragility.json or the directory that
    holds one), every value its readers use checked (InputError, one line, naming the
    file and the key path); an older file brought to today's spelling (:func:`_current`)."""
    path = Path(path)
    if path.is_dir():
        path = path / "fragility.json"
    data = check_fragility(read_json(path, "fragility file", DATA_FILE_BYTES), path)
    return _current(FragilityFile.of(data, path))


def _current(file):
    """``file`` in today's spelling: a pulse grid's 2D block without ``uplift_g_smallest``
    given it from ``uplift_g``, else from g tan(``alpha_rad``)."""
    grid = file.pulse_grid
    block = None if grid is None else grid.block2d
    if block is None or block.uplift_g_smallest is not None:
        return file
    least = block.uplift_g if block.uplift_g is not None else \
        None if block.alpha_rad is None else math.tan(block.alpha_rad)
    return replace(file, pulse_grid=replace(grid, block2d=replace(block,
                                                                  uplift_g_smallest=least)))


def write_fragility_file(directory, file):
    """``file`` written atomically to ``directory``/fragility.json; returns its path."""
    path = Path(directory) / "fragility.json"
    write_json(path, file.to_json())
    return path


# ---------------------------------------------------------------- dict <-> type
def _is_fit(key, value):
    """A lognormal fit of an intensity measure in a column's entry (its PGA fit always)."""
    return isinstance(value, dict) and ("median" in value or key == "PGA")


def _surface(value, name, where):
    return None if value is None else leaf(LogisticSurface, value, name, where)


def _column(entry, name, where):
    fits = {k: leaf(LognormalFit, v, name, f"{where}.{key_text(k)}")
            for k, v in entry.items() if _is_fit(k, v)}
    column = _build(ColumnFits, {k: v for k, v in entry.items() if k not in fits},
                    {"logistic": lambda v: _surface(v, name, f"{where}.logistic")})
    return replace(column, fits=fits, order=tuple(entry))


def _column_json(column):
    fits = {k: v.to_json() for k, v in column.fits.items()}
    return _join(replace(column, extra={**column.extra, **fits}, fits={}), _SURFACE_JSON)


_SURFACE_JSON = {"logistic": lambda v: None if v is None else v.to_json()}


def _section(section, name):
    return _build(PulseGridSection, section, {
        "pga_g": tuple, "pgv_pga_s": tuple, "warnings": tuple,
        "block2d": lambda v: None if v is None else _build(Block2d, v),
        "models": lambda v: {k: _model(m, name, f"pulse_grid.models.{key_text(k)}")
                             for k, m in v.items()},
        "experiments": lambda v: None if v is None else
        leaf(Experiments, v, name, "pulse_grid.experiments")})


def _section_json(section):
    return _join(section, {
        "pga_g": list, "pgv_pga_s": list, "warnings": list,
        "block2d": lambda v: None if v is None else _join(v),
        "models": lambda v: {k: _model_json(m) for k, m in v.items()},
        "experiments": lambda v: None if v is None else v.to_json()})


def _model(model, name, where):
    return _build(GridModel, model, {
        "cells": lambda v: tuple(leaf(GridCell, c, name, f"{where}.cells[{k}]")
                                 for k, c in enumerate(v or ())),
        "contours": lambda v: {
            level: tuple(leaf(ContourRow, r, name, f"{where}.contours.{key_text(level)}[{k}]")
                         for k, r in enumerate(rows)) for level, rows in (v or {}).items()},
        "logistic": lambda v: _surface(v, name, f"{where}.logistic")})


def _model_json(model):
    return _join(model, {
        "cells": lambda v: [c.to_json() for c in v],
        "contours": lambda v: {level: [r.to_json() for r in rows] for level, rows in v.items()},
        **_SURFACE_JSON})
