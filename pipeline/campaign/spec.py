"""What goes into one run of a campaign: :class:`RunSpec`.  Its run id is computed from
what defines the run (the code, the processed motion's content and the run's
:class:`~pipeline.scenario.parameters.RunParams`), so two campaigns asking for the same
run share it; what a campaign adds for its own bookkeeping (member, seed, node, ...)
lives in ``tags``, a frozen dataclass of the campaign's own (:mod:`pipeline.campaign.tags`),
and changes no run id."""
import dataclasses
from dataclasses import dataclass
from pathlib import Path

from pipeline.files import InputError, content_hash
from pipeline.scenario import RunParams


@dataclass(frozen=True)
class RunSpec:
    """One run: ``record`` as the user named it, its unique ``record_id``, the processed
    motion (``motion_file``, npz), the run's ``params`` (:class:`RunParams`: column,
    contact, numerics and drive), the ``run_id``, the campaign's ``tags`` (a frozen
    dataclass read by attribute: ``spec.tags.member``; None for a campaign without),
    ``keep_trajectory`` (False: only summary.json is kept), the run's own core-seconds
    estimate ``core_s`` (None: the campaign's) and the ``column_description`` the run's
    column follows (a description dict, named in outputs).  Read-only:
    :func:`dataclasses.replace` gives a changed copy with the same run id."""
    record: str
    record_id: str
    motion_file: str
    params: RunParams
    run_id: str
    tags: object = None
    keep_trajectory: bool = True
    core_s: float = None
    column_description: dict = None

    def __post_init__(self):
        for name in ("record", "record_id", "motion_file", "run_id"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise InputError(f"run spec: {name} must be a non-empty name, got "
                                 f"{getattr(self, name)!r}")
        if not isinstance(self.params, RunParams):
            raise InputError("run spec: params must be run parameters (RunParams)")
        if self.tags is not None and not (dataclasses.is_dataclass(self.tags)
                                          and not isinstance(self.tags, type)):
            raise InputError("run spec: tags must be a campaign's tags dataclass")

    @classmethod
    def create(cls, record, record_id, motion_file, params, code_version, tags=None,
               **fields):
        """A spec whose run id is hash(code version, motion content, parameters);
        ``params``: :class:`RunParams` or its flat dict; ``fields``: keep_trajectory,
        core_s, column_description."""
        if not isinstance(params, RunParams):
            params = RunParams.from_dict(params)
        return cls(str(record), record_id, str(motion_file), params,
                   content_hash(code_version, Path(motion_file), params.to_dict()), tags,
                   **fields)

    def __hash__(self):
        return hash(self.run_id)
