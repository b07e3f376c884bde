"""What flows through the verification campaign: a :class:`Check` to run (as
:class:`~pipeline.campaign.spec.RunSpec` is for a column run) and the
:class:`CheckResult` it writes (its ``summary.json``, as
:class:`~pipeline.outcome.summary.RunSummary` is).  Both are read-only and validated on
creation; both read like the flat dicts the campaign's files hold."""
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from pipeline.rocking.pulse import MODE_NAMES
from pipeline.files import InputError, content_hash, read_run_json, write_json
from pipeline.scenario import Contact
from pipeline.userfiles import number
from pipeline.verification.checks import (check_pulse_ratios, check_theta0_ratio,
                                          verify_housner, verify_sine_pulse, verify_sliding)
from pipeline.verification.frame import frame_colonnade, verify_frame
from pipeline.verification.one_cosine import check_period, verify_one_cosine

# kind: its setting's names (theta0/alpha and the contact damping ratio; the pulse's
# A / (alpha g) and omega / p; the static friction coefficient; the one-cosine pulse's
# period, s)
KINDS = {"housner": ("theta0_ratio", "damping"),
         "sine-pulse": ("amplitude_ratio", "omega_ratio"),
         "sliding": ("mu_s",),
         "one-cosine": ("period_s",),
         "frame": ("n_columns", "gamma", "period_s")}
# kind: the keys of its result that the campaign's summary and figures read
RESULT_KEYS = {"housner": ("max_rel_error_impact_times", "max_rel_error_peaks",
                           "effective_restitution", "housner_restitution", "yade"),
               "sine-pulse": ("yade",),
               "sliding": ("runs", "augusti_sinopoli_mu_min"),
               "one-cosine": ("yade", "integration", "eq43_g", "omega_ratio", "alpha_rad"),
               "frame": ("yade", "integration", "single_column_threshold_g", "gamma",
                         "n_columns")}
SLIDING_ROW_KEYS = ("mu_s", "pure_rocking", "t", "base_x_m")


@dataclass(frozen=True)
class Check(Mapping):
    """One verification run: ``kind`` (a key of :data:`KINDS`), its ``setting`` (exactly
    that kind's names, range-checked as the ``verify`` command checks them) and the
    ``run_id`` (see :meth:`create`).  Reads like the flat dict campaign files hold:
    ``check["mu_s"]``, ``check["record"]`` (the kind: no motion)."""
    kind: str
    setting: dict
    run_id: str

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"verification check: unknown kind {self.kind!r} (known: "
                             f"{', '.join(KINDS)})")
        if not isinstance(self.setting, dict) or set(self.setting) != set(KINDS[self.kind]):
            raise InputError(f"verification check {self.kind}: its setting must name "
                             f"exactly {', '.join(KINDS[self.kind])}")
        if not isinstance(self.run_id, str) or not self.run_id:
            raise InputError(f"verification check: run id must be a name, got {self.run_id!r}")
        values = {k: number(v, f"verification check: {k}")
                  for k, v in self.setting.items()}
        if self.kind == "housner":
            check_theta0_ratio(values["theta0_ratio"])
            Contact(damping=values["damping"])
        elif self.kind == "sine-pulse":
            check_pulse_ratios(values["amplitude_ratio"], values["omega_ratio"])
        elif self.kind == "one-cosine":
            check_period(values["period_s"])
        elif self.kind == "frame":
            check_period(values["period_s"])
            if values["n_columns"] != int(values["n_columns"]):
                raise InputError(f"verification check: n_columns {values['n_columns']:g} is "
                                 "not a whole number")
            frame_colonnade(int(values["n_columns"]), values["gamma"])
        else:
            Contact(mu_s=values["mu_s"])

    @property
    def record(self):
        """What campaign files name a run's record: the kind (a check has no motion)."""
        return self.kind

    motion_file = None          # a check runs no recorded motion
    # a campaign run's bookkeeping (:class:`~pipeline.campaign.spec.RunSpec`): no tags, the
    # trajectory kept, the campaign's cost estimate, no column description
    tags = None
    keep_trajectory = True
    core_s = None
    column_description = None

    @classmethod
    def create(cls, kind, code_version, **setting):
        """The check whose run id is hash(code version, kind, setting)."""
        return cls(kind, setting, content_hash(code_version, {"kind": kind, "record": kind,
                                                              **setting}))

    @classmethod
    def from_dict(cls, data):
        """The check a flat dict describes (as :meth:`to_dict` writes it)."""
        data = dict(data)
        kind = data.pop("kind", None)
        run_id = data.pop("run_id", None)
        data.pop("record", None)
        return cls(kind, data, run_id)

    def to_dict(self):
        return {"kind": self.kind, **self.setting, "record": self.record,
                "run_id": self.run_id}

    def run(self, run_dir):
        """Run the check's YADE scene(s) in ``run_dir``; its :class:`CheckResult`."""
        run_dir = Path(run_dir)
        s = self.setting
        if self.kind == "housner":
            values = verify_housner(theta0_ratio=s["theta0_ratio"], damping=s["damping"],
                                    run_dir=run_dir / "yade")
        elif self.kind == "sine-pulse":
            values = verify_sine_pulse(amplitude_ratio=s["amplitude_ratio"],
                                       omega_ratio=s["omega_ratio"], run_dir=run_dir / "yade")
        elif self.kind == "one-cosine":
            values = verify_one_cosine(period_s=s["period_s"], run_dir=run_dir / "yade")
        elif self.kind == "frame":
            values = verify_frame(int(s["n_columns"]), s["gamma"], s["period_s"],
                                  run_dir=run_dir / "yade")
        else:
            values = verify_sliding(mu_values=(s["mu_s"],), run_dir=run_dir)
        return CheckResult(values)

    # read-only mapping over the flat dict
    def __getitem__(self, key):
        return self.to_dict()[key]

    def __iter__(self):
        return iter(self.to_dict())

    def __len__(self):
        return len(self.setting) + 3

    def __hash__(self):
        return hash(self.run_id)


@dataclass(frozen=True)
class CheckResult(Mapping):
    """What one check found: the ``verify_*`` function's dict, checked on creation to be
    of a known kind (its ``test``), to say whether it ``passed`` and to hold the keys
    the campaign reads (:data:`RESULT_KEYS`).  Written by :meth:`save`, read by
    :meth:`load`; reads like that dict (``result["yade"]["mode"]``)."""
    values: dict

    def __post_init__(self):
        if not isinstance(self.values, dict):
            raise InputError("verification result: not an object")
        kind, passed = self.values.get("test"), self.values.get("passed")
        if kind not in KINDS:
            raise InputError(f"verification result: unknown test {kind!r}")
        if not isinstance(passed, bool):
            raise InputError("verification result: passed must be true or false")
        missing = [k for k in RESULT_KEYS[kind] if k not in self.values]
        if kind == "housner" and "peaks_over_alpha" not in self.values.get("yade", {}):
            missing.append("yade.peaks_over_alpha")
        if kind == "sine-pulse" and self.values.get("yade", {}).get("mode") \
                not in MODE_NAMES.values():
            missing.append("yade.mode (a mode name)")
        if kind == "sliding" and not (self.values.get("runs") and all(
                set(SLIDING_ROW_KEYS) <= set(row) for row in self.values["runs"])):
            missing.append(f"runs with {', '.join(SLIDING_ROW_KEYS)}")
        if missing:
            raise InputError(f"verification result ({kind}): lacks {', '.join(missing)}")

    @property
    def kind(self):
        return self.values["test"]

    @property
    def passed(self):
        return self.values["passed"]

    def save(self, path):
        """Write ``summary.json`` atomically (a run's last act)."""
        write_json(path, self.values)
        return Path(path)

    @classmethod
    def load(cls, path):
        """The result at ``path`` (a ``summary.json`` or the run directory holding it)."""
        path, data = read_run_json(path, "verification result")
        try:
            return cls(data)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None

    def __getitem__(self, key):
        return self.values[key]

    def __iter__(self):
        return iter(self.values)

    def __len__(self):
        return len(self.values)
