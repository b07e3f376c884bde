"""What one run says, as it flows from the YADE scene to every table: :class:`RunSummary`
(a run's ``summary.json``) holding one :class:`ColumnOutcome` per column.  Built by
:func:`pipeline.outcome.columns.summarise` (a simulated run) or :meth:`RunSummary.still`
(a run the pre-check skipped), written once by :meth:`RunSummary.save` and read back
only by :meth:`RunSummary.load`."""
import math
from dataclasses import dataclass, field, fields
from pathlib import Path

from pipeline.files import InputError, finite_number, read_run_json, write_json
from pipeline.outcome.colonnade import ColonnadeOutcome
from pipeline.outcome.damage import DamageMeasures, damage_at_rest


def _azimuth_or_none(value, name):
    if value is None:
        return None
    value = float(value)
    if not (math.isfinite(value) and 0.0 <= value < 360.0):
        raise InputError(f"{name} {value:g} not in [0, 360)")
    return value


def _non_negative(value, name):
    """``value`` as a float >= 0 (None stays None: not known)."""
    return finite_number(value, name, minimum=0.0)


@dataclass(frozen=True, kw_only=True)
class ColumnOutcome:
    """One column of a run: toppled or standing, downfall azimuth (deg clockwise from
    North, None when standing), first impact time (s, record's clock) and point (m, pedestal
    frame, mass-weighted), largest tilt (deg), base slip (m), initial position (m), the
    rule that decided the fall (``toppled_by``), one dict per body
    (:mod:`pipeline.outcome.columns`) and its :class:`~pipeline.outcome.damage.DamageMeasures`
    (``damage``; None in summaries written before them)."""
    column: str
    toppled: bool
    toppled_by: str = None
    downfall_azimuth_deg: float = None
    impact_time_s: float = None
    impact_point_m: list = None
    max_tilt_deg: float = 0.0
    base_slip_m: float = 0.0
    position_m: list = field(default_factory=lambda: [0.0, 0.0])
    bodies: list = field(default_factory=list)
    damage: DamageMeasures = None

    def __post_init__(self):
        if not isinstance(self.column, str) or not self.column:
            raise InputError(f"column outcome: column name {self.column!r}")
        if not isinstance(self.toppled, bool):
            raise InputError(f"column {self.column}: toppled must be true or false")
        object.__setattr__(self, "downfall_azimuth_deg", _azimuth_or_none(
            self.downfall_azimuth_deg, f"column {self.column}: downfall_azimuth_deg"))
        if self.downfall_azimuth_deg is not None and not self.toppled:
            raise InputError(f"column {self.column}: a downfall azimuth but not toppled")
        object.__setattr__(self, "max_tilt_deg", _non_negative(
            self.max_tilt_deg, f"column {self.column}: max_tilt_deg"))
        object.__setattr__(self, "base_slip_m", _non_negative(
            self.base_slip_m, f"column {self.column}: base_slip_m"))
        if self.damage is not None:
            try:
                damage = (self.damage if isinstance(self.damage, DamageMeasures)
                          else DamageMeasures.from_dict(self.damage))
            except (TypeError, InputError) as exc:
                raise InputError(f"column {self.column}: {exc}") from None
            if damage.toppled != self.toppled:
                raise InputError(f"column {self.column}: its damage measures say toppled "
                                 f"{damage.toppled}, the column {self.toppled}")
            object.__setattr__(self, "damage", damage)

    @classmethod
    def standing(cls, name, x_m, y_m, bodies=None):
        """A column that never moved, at (x_m, y_m) on the pedestal (``bodies``: its
        scene bodies, for its damage measures, all zero)."""
        return cls(column=name, toppled=False, position_m=[x_m, y_m],
                   damage=None if bodies is None else damage_at_rest(bodies))

    def to_dict(self):
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["damage"] = None if self.damage is None else self.damage.to_dict()
        return out


# parameters' names in summaries written before they took the run parameters' spelling
# (:class:`~pipeline.scenario.parameters.RunParams`): read under the new name
OLD_PARAMETER_NAMES = {"height_m": "height", "density_kg_m3": "density", "window_s": "window"}


@dataclass(frozen=True, kw_only=True)
class RunSummary:
    """One run (``summary.json``): the record and its back azimuth (deg, None when
    unknown), the run's parameters (the flat dict of
    :class:`~pipeline.scenario.parameters.RunParams`, with what the run derived from them:
    a description's sizes, ``geometry``, ``dt_factor``, ``motion_file``, ``processing``),
    one :class:`ColumnOutcome` per column, whether YADE
    ran (``simulated``; ``note`` says why not), the simulated time (s) and window, the
    motion's end, whether the scene stopped early, the time step (s), wall time (s),
    provenance, ``quiet_after_s`` when the quiet tail was cut, ``start_in_file_s``, and for
    a colonnade its :class:`~pipeline.outcome.colonnade.ColonnadeOutcome` (``colonnade``).

    Every time (impact and past-90 times, window, motion end, quiet_after_s) is on the
    record's clock: seconds after the record's first sample.  ``start_in_file_s`` is the
    record time of the first sample of the motion the scene ran (negative: filter margin
    before the record), so the scene's and ``trajectory.npz``'s clock reads
    record time - start_in_file_s."""
    record: str
    back_azimuth_deg: float = None
    parameters: dict = field(default_factory=dict)
    columns: tuple = ()
    simulated: bool = True
    note: str = None
    simulated_s: float = 0.0
    simulated_window_s: list = None
    motion_end_s: float = 0.0
    stopped_early: bool = False
    time_step_s: float = None
    wall_s: float = 0.0
    provenance: dict = field(default_factory=dict)
    quiet_after_s: float = None
    start_in_file_s: float = 0.0
    colonnade: ColonnadeOutcome = None

    OPTIONAL = ("note", "quiet_after_s", "colonnade")     # written only when set

    def __post_init__(self):
        if not isinstance(self.record, str):
            raise InputError(f"run summary: record must be a name, got {self.record!r}")
        if not isinstance(self.parameters, dict):
            raise InputError("run summary: parameters must be a mapping")
        object.__setattr__(self, "parameters", {OLD_PARAMETER_NAMES.get(k, k): v
                                                for k, v in self.parameters.items()})
        back = self.back_azimuth_deg
        if back is not None and not math.isfinite(float(back)):
            back = None                         # an unknown back azimuth
        object.__setattr__(self, "back_azimuth_deg",
                           _azimuth_or_none(back, "run summary: back_azimuth_deg"))
        columns = tuple(c if isinstance(c, ColumnOutcome) else ColumnOutcome(**c)
                        for c in self.columns)
        if len({c.column for c in columns}) != len(columns):
            raise InputError("run summary: a column is named twice")
        object.__setattr__(self, "columns", columns)
        for name in ("simulated_s", "wall_s"):
            object.__setattr__(self, name, _non_negative(getattr(self, name),
                                                         f"run summary: {name}"))
        for name in ("motion_end_s", "start_in_file_s"):       # times: may be negative
            object.__setattr__(self, name, finite_number(getattr(self, name),
                                                   f"run summary: {name}"))
        if isinstance(self.colonnade, dict):
            try:
                object.__setattr__(self, "colonnade", ColonnadeOutcome(**self.colonnade))
            except TypeError as exc:
                raise InputError(f"run summary: colonnade ({exc})") from None
        if not isinstance(self.simulated, bool) or not isinstance(self.stopped_early, bool):
            raise InputError("run summary: simulated and stopped_early must be true or false")

    @classmethod
    def still(cls, record, columns, colonnade=None, **values):
        """A run YADE never ran: every column standing (``columns``: scene column dicts
        with name, x, y, and bodies for the damage measures, all zero; none for a
        colonnade's beams, which rest on others); ``colonnade``: the name of the
        colonnade the scene holds (its outcome: nothing fell), or None."""
        outcomes = [ColumnOutcome.standing(c["name"], c["x"], c["y"],
                                           None if c.get("rests_on") else c.get("bodies"))
                    for c in columns]
        whole = None if colonnade is None else ColonnadeOutcome.of(
            colonnade, [o for o, c in zip(outcomes, columns) if not c.get("rests_on")],
            [o for o, c in zip(outcomes, columns) if c.get("rests_on")])
        return cls(record=record, simulated=False, columns=outcomes, colonnade=whole,
                   **values)

    def column(self, name):
        """The :class:`ColumnOutcome` of column ``name``."""
        for c in self.columns:
            if c.column == name:
                return c
        raise KeyError(name)

    def to_dict(self):
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in self.OPTIONAL and value is None:
                continue
            if f.name == "columns":
                value = [c.to_dict() for c in value]
            elif f.name == "colonnade":
                value = {g.name: getattr(value, g.name) for g in fields(value)}
            out[f.name] = value
        return out

    def save(self, path):
        """Write ``summary.json`` atomically (a run's last act)."""
        write_json(path, self.to_dict())
        return Path(path)

    @classmethod
    def load(cls, path):
        """The summary at ``path`` (a ``summary.json`` or the run directory holding it)."""
        path, data = read_run_json(path, "run summary")
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known) if isinstance(data, dict) else None
        if unknown is None or unknown or "record" not in data:
            what = "not an object" if unknown is None else (
                f"unknown keys {', '.join(unknown)}" if unknown else "no record")
            raise InputError(f"{path}: not a run summary ({what})")
        try:
            return cls(**data)
        except (TypeError, InputError) as exc:
            raise InputError(f"{path}: not a run summary ({exc})") from None
