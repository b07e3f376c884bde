"""mkdocs-macros hook (``mkdocs.yml``: ``module_name``): the docs pages' measured numbers
and tables from :mod:`pipeline.report.docs_numbers`."""
from pipeline.report import docs_numbers


def define_env(env):
    for name in ("bench_value", "bench_speed_table", "engine_shares", "run_all_steps",
                 "report"):
        env.macro(getattr(docs_numbers, name), name)
