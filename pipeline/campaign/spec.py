"""What goes into one run of a campaign: :class:`RunSpec`.  Its run id is computed from
what defines the run (the code, the processed motion's content and the parameters), so
two campaigns asking for the same run share it; what a campaign adds for its own
bookkeeping (member, seed, node, ...) lives in ``tags`` and changes no run id."""
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from pipeline.files import InputError, content_hash


@dataclass(frozen=True)
class RunSpec(Mapping):
    """One run: ``record`` as the user named it, its unique ``record_id``, the processed
    motion (``motion_file``, npz), the run's ``params`` (column, contact and numerics
    settings and the drive: window, rotation, scale), the ``run_id`` and the campaign's
    ``tags``.  Read-only; a spec reads like the flat dict it is written as
    (``spec["member"]``), and :meth:`tagged` gives a new spec with more tags."""
    record: str
    record_id: str
    motion_file: str
    params: dict
    run_id: str
    tags: dict = field(default_factory=dict)

    CORE = ("record", "record_id", "motion_file", "params", "run_id")   # the fields, in order

    def __post_init__(self):
        for name in ("record", "record_id", "motion_file", "run_id"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise InputError(f"run spec: {name} must be a non-empty name, got "
                                 f"{getattr(self, name)!r}")
        if not isinstance(self.params, dict) or not isinstance(self.tags, dict):
            raise InputError("run spec: params and tags must be mappings")
        clash = set(self.tags) & {*self.CORE, "tags"}
        if clash:
            raise InputError(f"run spec: tag {sorted(clash)[0]!r} would hide a field")

    @classmethod
    def create(cls, record, record_id, motion_file, params, code_version, **tags):
        """A spec whose run id is hash(code version, motion content, parameters)."""
        return cls(str(record), record_id, str(motion_file), params,
                   content_hash(code_version, Path(motion_file), params), tags)

    def tagged(self, **tags):
        """This run with ``tags`` added (or changed); the run id stays."""
        return replace(self, tags={**self.tags, **tags})

    def to_dict(self):
        """The flat dict (fields then tags), as campaign files hold a spec."""
        return {**{name: getattr(self, name) for name in self.CORE}, **self.tags}

    @classmethod
    def from_dict(cls, data):
        missing = [k for k in cls.CORE if k not in data]
        if missing:
            raise InputError(f"run spec lacks {', '.join(missing)}")
        return cls(*(data[k] for k in cls.CORE),
                   {k: v for k, v in data.items() if k not in cls.CORE})

    # read-only mapping over the flat dict
    def __getitem__(self, key):
        if key in self.tags:
            return self.tags[key]
        if key in self.CORE:
            return getattr(self, key)
        raise KeyError(key)

    def __iter__(self):
        return iter(self.to_dict())

    def __len__(self):
        return len(self.CORE) + len(self.tags)

    def __hash__(self):
        return hash(self.run_id)
