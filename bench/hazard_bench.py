"""Bench section 14: what the hazard side costs at the size of a study of rocks.

1. ``constrain`` of 500 branches at 10 sites (a plain table: power-law curves, the
   exponent and the rate at 0.1 g drawn per branch and site, seed 1), 20 specimens, two
   at each site, each with its own pulse-grid fragility (cells over PGA x PGV/PGA, P from
   a logistic surface, 16 runs a cell, 4 parameter sets: the heaviest fragility to
   evaluate) and its own uncertain age (Monte Carlo over ages), 400 draws: the command's
   wall and CPU seconds, in process, the files written to a temporary directory;
2. a joint hazard of PGA and PGV of 50 x 50 levels (one scenario's, in closed form)
   integrated against a logistic surface once per branch for 500 branches: the wall
   seconds in all and per branch.

Units: seconds; PGA in m/s^2 and g, PGV in m/s."""
import json
import math
import os
import time

import numpy as np

from pipeline.cli import main as pipeline_main
from pipeline.constants import STANDARD_GRAVITY as G
from pipeline.hazard.fragility import Logistic
from pipeline.hazard.joint_survival import joint_overturning_rate, scenario_cell_rates

BRANCHES, SITES, PER_SITE, DRAWS = 500, 10, 2, 400
GRID_PGA_G = (0.05, 0.087, 0.15, 0.26, 0.46, 0.8)
GRID_RATIO_S = (0.1, 0.4, 0.7, 1.0)
MRD_LEVELS = 50


def _tree(path, rng):
    """A plain logic-tree table: BRANCHES branches of equal weight at SITES sites."""
    levels = np.geomspace(0.01, 2.0, 20)
    rows = ["branch,weight,pga_g,annual_rate_per_yr,site"]
    for b in range(BRANCHES):
        for s in range(SITES):
            k, r01 = rng.uniform(2.0, 3.5), 10 ** rng.uniform(-3.5, -2.0)
            rows += [f"b{b},{1 / BRANCHES!r},{x:.6g},{r01 * (x / 0.1) ** -k:.6g},{s}"
                     for x in levels]
    path.write_text("\n".join(rows) + "\n")


def _grid(path, median_g):
    """A pulse-grid fragility.json (as ``campaign fragility --pulses`` writes it) with P
    from a logistic surface of median ``median_g`` at PGV/PGA 0.3 s."""
    b1, b2 = 4.0, 1.5
    b0 = -b1 * math.log(median_g * G) - b2 * math.log(0.3)
    cells = []
    for a in GRID_PGA_G:
        for r in GRID_RATIO_S:
            k = round(16 / (1 + math.exp(-(b0 + b1 * math.log(a * G) + b2 * math.log(r)))))
            cells.append({"pga_g": a, "pgv_pga_s": r, "n": 16, "overturned": k, "P": k / 16,
                          "P_per_set": [k / 16] * 4, "sets": [0, 1, 2, 3]})
    model = {"cells": cells, "logistic": {"coefficients": {"b0": b0, "b1": b1, "b2": b2},
                                          "se": {"b0": 0.1, "b1": 0.1, "b2": 0.1},
                                          "cov": None}}
    path.write_text(json.dumps({"mode": "pulses", "specimen": f"bench rock {median_g:g} g",
                                "pulse_grid": {"pga_g": list(GRID_PGA_G),
                                               "pgv_pga_s": list(GRID_RATIO_S), "members": 4,
                                               "models": {"monolithic": model},
                                               "block2d": {"alpha_rad": math.atan(0.1),
                                                           "uplift_g": 0.1}}}))


def constrain_at_size(work):
    """Section 14.1: the command's wall and CPU seconds (see the module)."""
    rng = np.random.default_rng(1)
    _tree(work / "tree.csv", rng)
    argv = ["constrain", "--logic-tree", str(work / "tree.csv"), "--draws", str(DRAWS),
            "--magnitude", "6.5", "--distance-km", "20", "--out", str(work / "constrain")]
    n = SITES * PER_SITE
    for j in range(n):
        _grid(work / f"rock{j}.json", 0.2 + 0.02 * j)
        argv += ["--fragility", str(work / f"rock{j}.json"), "--specimen-site",
                 str(j // PER_SITE), "--age-ka", f"{10 + j:g}", "--age-sd-ka", "2"]
    wall, cpu = time.perf_counter(), time.process_time()
    code = pipeline_main(argv)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return {"branches": BRANCHES, "sites": SITES, "specimens": n, "draws": DRAWS,
            "fragility": "pulse grid, 6 x 4 cells, 4 parameter sets", "exit": code,
            "wall_s": wall, "cpu_s": cpu, "cores": os.cpu_count(),
            "load_average": os.getloadavg()[0]}


def mrd_per_branch(work=None):
    """Section 14.2: a 50 x 50 joint hazard integrated once per branch, 500 times."""
    pga = np.geomspace(0.001, 4.0, MRD_LEVELS) * G
    pgv = np.geomspace(1e-4, 2.0, MRD_LEVELS)
    surface = Logistic((-1.0, 3.0, 1.5))
    rates = [scenario_cell_rates(pga, pgv, 0.01 * (1 + b / BRANCHES), math.log(0.5), 0.6,
                                 math.log(0.05), 0.6, 0.654) for b in range(BRANCHES)]
    wall = time.perf_counter()
    total = sum(joint_overturning_rate(pga, pgv, r, surface.probability).rate_per_yr
                for r in rates)
    wall = time.perf_counter() - wall
    return {"levels": MRD_LEVELS, "branches": BRANCHES, "wall_s": wall,
            "per_branch_ms": 1000 * wall / BRANCHES, "mean_rate_per_yr": total / BRANCHES}


def hazard_cost(work):
    """Section 14: both parts."""
    return {"constrain": constrain_at_size(work), "mrd_per_branch": mrd_per_branch()}


def print_hazard_cost(h):
    c, m = h["constrain"], h["mrd_per_branch"]
    print(f"\n14. Hazard at a study's size: constrain of {c['branches']} branches, "
          f"{c['specimens']} specimens at {c['sites']} sites, {c['draws']} draws "
          f"({c['fragility']}): {c['wall_s']:.1f} s wall, {c['cpu_s']:.1f} s CPU "
          f"(exit {c['exit']}, load average {c['load_average']:.1f} on {c['cores']} cores); "
          f"a {m['levels']} x {m['levels']} rate density per branch: "
          f"{m['per_branch_ms']:.1f} ms, {m['wall_s']:.2f} s for {m['branches']} branches")
