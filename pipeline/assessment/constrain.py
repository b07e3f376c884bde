"""The ``constrain`` command's workflow: a logic tree reweighted by the specimens still
standing, written as ``constrain.json``, the branch tables, the prior and constrained
curves and ``constrain.png`` (docs/constrained-hazard.md).  The command reads its
options; this loads the inputs, runs :func:`~pipeline.hazard.constrain_assess.constrain_tree`
and writes the files as one set."""
import csv
import io
from dataclasses import replace

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import file_set, write_text
from pipeline.hazard.constrain_assess import constrain_tree
from pipeline.hazard.constrain_sites import SiteGroup
from pipeline.hazard.logictree import load_logic_tree, load_logic_trees

FILES = ("branch_weights.csv", "branch_test.csv", "prior_curves.csv",
         "constrained_curves.csv", "constrain.json", "constrain.png")  # a run replaces them


def constrain_files(o):
    """constrain.json (a :class:`~pipeline.hazard.results.ConstrainResult`) for the options ``o``
    (:class:`~pipeline.assessment.constrain_options.ConstrainOptions`), its files written to
    ``o.out``."""
    from pipeline.figures.constrain import plot_constrain  # lazy: matplotlib, only when a figure is drawn
    ages = o.age_models()
    sites = o.specimen_sites()
    site = o.site if o.site is not None or sites is None else sites[0]
    groups, trees, ratios = None, {}, {}
    if sites is not None:
        trees = load_logic_trees(o.logic_tree, list(dict.fromkeys(sites)))
        ratios = o.site_ratio_models(trees)              # each site its own rate density
        groups = [SiteGroup(trees[s], tuple(j for j, t in enumerate(sites) if t == s), s,
                            ratios.get(s)) for s in trees]
    tree = trees[site] if site in trees else load_logic_tree(o.logic_tree, site)
    specimens = o.specimens()
    ratio = ratios[site] if site in ratios else o.ratio_model(specimens, tree)
    summary, rows, figure = constrain_tree(tree, specimens, ratio, ages, o.rule, o.floor,
                                           o.draws, o.seed, groups)
    files = {"branch_weights.csv": _branch_table(rows),
             "branch_test.csv": summary.branch_test.csv(),
             "prior_curves.csv": _curve_table(summary, summary.prior, "prior")}
    if summary.posterior is not None:
        files["constrained_curves.csv"] = _curve_table(summary, summary.posterior,
                                                       f"constrained ({o.rule})")
    summary = replace(summary, hazard_component=o.hazard_component,
                      files=[*files, "constrain.json", "constrain.png"])
    files["constrain.json"] = summary.text()   # before any file
    with file_set(o.out, FILES, ("constrain.json",)) as stage:
        plot_constrain(figure, stage / "constrain.png")
        for name, text in files.items():
            write_text(stage / name, text)
    return summary


def _branch_table(rows):
    """branch_weights.csv: one row per branch."""
    names = ["branch", "path", "prior_weight", "survival_probability", "posterior_bayes",
             "posterior_eliminate"]
    drawn = bool(rows) and rows[0].given("survival_interval") is not None
    if drawn:
        names += ["survival_lo_2.5pct", "survival_hi_97.5pct"]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(names)
    for row in rows:
        values = [getattr(row, k) for k in ("branch", "path", "prior_weight",
                                            "survival_probability", "posterior_bayes",
                                            "posterior_eliminate")]
        if drawn:
            values += row.survival_interval
        writer.writerow(["" if v is None else (f"{v:.9g}" if isinstance(v, float) else v)
                         for v in values])
    return buf.getvalue()


def _curve_table(summary, stats, what):
    """A curve file: comment lines, then pga_g, pga_m_s2, the mean and each fractile's
    annual rate of exceedance (1/yr) per level."""
    fractiles = list(stats.fractiles)
    lines = [f"# {what} hazard curves of the logic tree {summary.hazard.file}: "
             "annual rates of exceeding PGA (1/yr)",
             "# mean: the weighted mean of the branches' rates; fractile_q: OpenQuake's "
             "weighted quantile over the branches",
             ",".join(["pga_g", "pga_m_s2", "mean_annual_rate_per_yr"]
                      + [f"fractile_{q}_annual_rate_per_yr" for q in fractiles])]
    for k, level in enumerate(summary.levels_m_s2):
        values = [level / STANDARD_GRAVITY, level, stats.mean_rates_per_yr[k]] + \
            [stats.fractiles[q][k] for q in fractiles]
        lines.append(",".join(f"{v:.9g}" for v in values))
    return "\n".join(lines) + "\n"
