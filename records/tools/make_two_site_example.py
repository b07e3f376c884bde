"""One-time tool (kept for provenance): the small example of specimens at two sites and
of an age given as samples, in ``records/hazard/two_site_example/`` (docs/
constrained-hazard.md), written from shipped data and stated numbers:

- ``logic_tree_two_sites.csv``: a plain logic-tree table with a site column.  Site 0 is
  OpenQuake's logic-tree QA case 11 (``records/hazard/openquake_logictree_case_11``: its
  three branches and weights, read by the project's loader, the probabilities of
  exceedance in one year as annual rates); site 1 is the same branches with every rate
  halved (SITE1_RATE_FACTOR): a synthetic, less active site, not a hazard model of any
  place.
- ``age_samples_synthetic.csv``: AGE_SAMPLES synthetic samples of an exposure age, drawn
  from a normal of mean AGE_MEAN_KA and sd AGE_SD_KA (ka) with numpy's default generator
  of seed AGE_SEED; one column, ``age_ka``.

Run from the repository root: ``python records/tools/make_two_site_example.py``.
"""
from pathlib import Path

import numpy as np

from pipeline.constants import STANDARD_GRAVITY
from pipeline.files import write_text
from pipeline.hazard.logictree import load_logic_tree

CASE_11 = Path("records/hazard/openquake_logictree_case_11")
OUT = Path("records/hazard/two_site_example")
SITE1_RATE_FACTOR = 0.5
AGE_MEAN_KA, AGE_SD_KA, AGE_SAMPLES, AGE_SEED = 12.0, 1.5, 200, 61


def logic_tree_table():
    """The two sites' table: branch,weight,pga_g,annual_rate_per_yr,path,site."""
    tree = load_logic_tree(CASE_11)
    lines = ["# two sites: site 0 OpenQuake's logictree QA case 11 (records/hazard/"
             "openquake_logictree_case_11), site 1 its rates halved (synthetic); "
             "written by records/tools/make_two_site_example.py",
             "branch,weight,pga_g,annual_rate_per_yr,path,site"]
    for site, factor in ((0, 1.0), (1, SITE1_RATE_FACTOR)):
        for branch, path, weight, rates in zip(tree.branch_ids, tree.branch_paths,
                                               tree.weights, tree.rates_per_yr):
            for level, rate in zip(tree.levels_m_s2, rates):
                lines.append(f"rlz{branch},{weight:.9g},{level / STANDARD_GRAVITY:.9g},"
                             f"{rate * factor:.9g},{path},{site}")
    return "\n".join(lines) + "\n"


def age_samples():
    """The synthetic age samples (ka), one column."""
    ages = np.random.default_rng(AGE_SEED).normal(AGE_MEAN_KA, AGE_SD_KA, AGE_SAMPLES)
    return (f"# synthetic: {AGE_SAMPLES} samples of a normal age, mean {AGE_MEAN_KA:g} ka, "
            f"sd {AGE_SD_KA:g} ka (numpy default_rng seed {AGE_SEED}); written by "
            "records/tools/make_two_site_example.py\nage_ka\n"
            + "".join(f"{a:.4f}\n" for a in ages))


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    write_text(OUT / "logic_tree_two_sites.csv", logic_tree_table())
    write_text(OUT / "age_samples_synthetic.csv", age_samples())
