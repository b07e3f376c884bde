"""mkdocs-macros hook (``mkdocs.yml``: ``module_name``): the docs pages' measured numbers
and tables from :mod:`pipeline.report.docs_numbers`; the REPORT's figures that a page
shows are copied beside the page in the built site."""
import html
import shutil
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.report import docs_numbers

NUMBERS = ("bench_convergence_table", "bench_value", "bench_speed_table", "column_examples",
           "column_sources", "engine_shares", "member_ranges_table", "record_rocking_hd",
           "record_value",
           "run_all_minutes", "run_all_steps", "setting", "table_motion_value",
           "time_step_table", "twin_time_step", "value")
WITH_FIGURES = ("report", "report_section")


def define_env(env):
    env.variables["_figures"] = set()          # (page url, figure path under results/)
    for name in NUMBERS:
        env.macro(getattr(docs_numbers, name), name)

    def with_figures(function):
        def macro(*args, **kwargs):
            text = function(*args, **kwargs)
            page_url = env.page.url if env.page is not None else ""
            env.variables["_figures"].update(
                (page_url, figure) for figure in docs_numbers.figures(text))
            # as HTML: mkdocs checks Markdown links against the docs' own files, and
            # these figures are copied beside the page only after the build
            return docs_numbers.FIGURE.sub(
                lambda m: f'<img alt="{html.escape(m[1])}" src="{m[2]}">', text)
        macro.__doc__ = function.__doc__
        return macro

    for name in WITH_FIGURES:
        env.macro(with_figures(getattr(docs_numbers, name)), name)


def on_post_build(env):
    """Copy each figure a page shows from ``results/`` to where the page's link points."""
    site = Path(env.conf["site_dir"])
    for page_url, figure in env.variables.get("_figures", ()):
        source = RESULTS_DIR / figure
        if source.is_file():
            target = site / page_url / figure
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target)
