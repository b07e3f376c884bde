"""What goes into one run of a campaign: :class:`RunSpec`.  Its run id is computed from
what defines the run (the code, the processed motion's content and the run's
:class:`~pipeline.scenario.parameters.RunParams`), so two campaigns asking for the same
run share it; what a campaign adds for its own bookkeeping (member, seed, node, ...)
lives in ``tags`` and changes no run id."""
from dataclasses import dataclass, field, replace
from pathlib import Path

from pipeline.files import InputError, content_hash
from pipeline.scenario import RunParams


@dataclass(frozen=True)
class RunSpec:
    """One run: ``record`` as the user named it, its unique ``record_id``, the processed
    motion (``motion_file``, npz), the run's ``params`` (:class:`RunParams`: column,
    contact, numerics and drive), the ``run_id`` and the campaign's ``tags`` (names of
    its own: ``spec.tags["member"]``).  Read-only; :meth:`tagged` gives a new spec with
    more tags."""
    record: str
    record_id: str
    motion_file: str
    params: RunParams
    run_id: str
    tags: dict = field(default_factory=dict)

    CORE = ("record", "record_id", "motion_file", "params", "run_id")   # the fields, in order

    def __post_init__(self):
        for name in ("record", "record_id", "motion_file", "run_id"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise InputError(f"run spec: {name} must be a non-empty name, got "
                                 f"{getattr(self, name)!r}")
        if not isinstance(self.params, RunParams):
            raise InputError("run spec: params must be run parameters (RunParams)")
        if not isinstance(self.tags, dict):
            raise InputError("run spec: tags must be a mapping")
        clash = set(self.tags) & {*self.CORE, "tags"}
        if clash:
            raise InputError(f"run spec: tag {sorted(clash)[0]!r} would hide a field")

    @classmethod
    def create(cls, record, record_id, motion_file, params, code_version, **tags):
        """A spec whose run id is hash(code version, motion content, parameters);
        ``params``: :class:`RunParams` or its flat dict."""
        if not isinstance(params, RunParams):
            params = RunParams.from_dict(params)
        return cls(str(record), record_id, str(motion_file), params,
                   content_hash(code_version, Path(motion_file), params.to_dict()), tags)

    @property
    def keep_trajectory(self):
        """False when the campaign keeps only the run's summary.json."""
        return self.tags.get("keep_trajectory", True)

    def tagged(self, **tags):
        """This run with ``tags`` added (or changed); the run id stays."""
        return replace(self, tags={**self.tags, **tags})

    def to_dict(self):
        """The flat dict (fields, params as their flat dict, then tags)."""
        return {"record": self.record, "record_id": self.record_id,
                "motion_file": self.motion_file, "params": self.params.to_dict(),
                "run_id": self.run_id, **self.tags}

    @classmethod
    def from_dict(cls, data):
        """The spec :meth:`to_dict` wrote (its parameters validated)."""
        missing = [k for k in cls.CORE if k not in data]
        if missing:
            raise InputError(f"run spec lacks {', '.join(missing)}")
        return cls(data["record"], data["record_id"], data["motion_file"],
                   RunParams.from_dict(data["params"]), data["run_id"],
                   {k: v for k, v in data.items() if k not in cls.CORE})

    def __hash__(self):
        return hash(self.run_id)
