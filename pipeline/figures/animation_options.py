"""The ``animate`` command's options, declared as :func:`~pipeline.scenario.parameters.param`
fields (the command builds their flags from them); checked on creation, before any work.
Light: the command imports it at start-up, the animation (matplotlib) only when it runs."""
from dataclasses import dataclass

from pipeline.scenario.parameters import check_fields, param


@dataclass(frozen=True)
class AnimationOptions:
    """How much of a run is animated, and how finely."""
    fps: float = param(20.0, "", "frames per second", 0.0, None, "--fps", low_open=True)
    max_seconds: float = param(None, "s", "animate only the start", 0.0, None,
                               "--max-seconds", low_open=True, optional="the whole run")

    def __post_init__(self):
        check_fields(self)
