"""What standing specimens say about their sites' hazard: the ``survival`` and
``constrain`` workflows and their options (:mod:`pipeline.assessment.options`); the
commands in :mod:`pipeline.cli` read the flags and call these."""
