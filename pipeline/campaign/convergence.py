"""The ``convergence`` campaign: is the model converged, judged on distributions?

A single run of a chaotic system moves with any change of the numerics (``make bench``
shows one fall turning by 2.6-60 deg with the rim points), so convergence is asked of
what the project reports: an ensemble's P(toppled) and distribution of fall directions.
For each record (default ``DEFAULT_RECORDS``: two records where every member of both
columns falls and one where about half of them fall, so that P(toppled) is put to the
test as well as the directions) the twin model's ensemble (the ``ensemble`` campaign's
sampled friction, damping, stiffness, tolerances, tilt, offsets and rim phase) runs at
each of
``VARIANTS``: the defaults (16 rim points, time step factor 0.3 or the stability limit
at the member's damping, 0.19-0.3), 32 and 64 rim points, and time step factor 0.15.
Each variant samples its own members (seed + its index): the samples are independent,
as the two-sample tests assume.

Against the defaults, per record and column: P(toppled) by Fisher's exact test, the
fall directions by Kuiper's two-sample test (:func:`pipeline.stats.ensemble.
compare_ensembles`); a difference is called when Holm's correction over all the
comparisons rejects at 5 %.  Where every member of every variant fell (or none did),
P(toppled) is not put to the test: ``p_toppled_untested`` names those records and
columns.  Outputs: ``convergence.json`` (every number, the tests'
p-values, the verdict and the CPU time per member of each variant), ``convergence.csv``
and ``convergence.png``.
"""
from dataclasses import dataclass
import logging
import math
from pathlib import Path

import numpy as np

from pipeline.campaign import Campaign, register
from pipeline.campaign.options import CampaignOptions
from pipeline.scenario.parameters import param
from pipeline.campaign.run_dirs import finished_runs
from pipeline.campaign.runs import column_specs, run_column_spec
from pipeline.simulate import run_code_version
from pipeline.campaign.ensemble_members import (DEFAULT_SEED, ENSEMBLE_RANGES, check_seed,
                                                sample_batches)
from pipeline.campaign.tables import collect
from pipeline.constants import RIM_POINTS
from pipeline.files import InputError, write_csv, write_json
from pipeline.stats.circular import circular_summary
from pipeline.stats.ensemble import compare_ensembles, holm_reject, wilson_interval
from pipeline.campaign.tags import ConvergenceTags
import pandas as pd

log = logging.getLogger(__name__)

DEFAULT_RECORDS = ("RC-CCC", "NF04", "RC-CLC")
DEFAULT_MEMBERS = 32
VARIANTS = {                 # name: numerics of every member (the defaults: none given)
    "default": {},
    "rim 32": {"rim_points": 32},
    "rim 64": {"rim_points": 64},
    "dt 0.15": {"dt_factor": 0.15},
}
REFERENCE = "default"
ALPHA = 0.05                 # family-wise level of Holm's correction


def variant_ranges(numerics):
    """The ensemble's ranges with the rim phase over one spacing of this variant's rim."""
    points = numerics.get("rim_points", RIM_POINTS)
    return dict(ENSEMBLE_RANGES, rim_phase_deg=(0.0, 360.0 / points, "uniform"))


def convergence_specs(records, campaign_dir, members=DEFAULT_MEMBERS, seed=DEFAULT_SEED):
    """Specs of ``members`` twin-model members per record and variant (variant k sampled
    with seed + k)."""
    records = list(records or DEFAULT_RECORDS)
    runs, tags = [], []
    for k, (name, numerics) in enumerate(VARIANTS.items()):
        params = sample_batches(members, members, seed + k, variant_ranges(numerics))
        for record in records:
            for m, p in enumerate(params):
                runs.append((record, {**p, **numerics}))
                tags.append((name, m))
    return column_specs(runs, campaign_dir,
                        [ConvergenceTags(name, m, seed) for name, m in tags],
                        keep_trajectory=False)


def convergence_outputs(specs, campaign_dir, failures, animations, figures=True):
    campaign_dir = Path(campaign_dir)
    runs, _ = collect(specs, "convergence", campaign_dir)
    if runs.empty:
        return {"code_version": run_code_version(), "figures": []}
    variant_of = {s.run_id: s.tags.variant for s in specs}
    runs.insert(1, "variant", runs["run_id"].map(variant_of))
    write_csv(campaign_dir / "members.csv", runs)
    result = compare_variants(runs, wall_per_member(specs, campaign_dir))
    write_csv(campaign_dir / "convergence.csv", _rows(result))
    write_json(campaign_dir / "convergence.json", result)
    log.info(result["verdict"])
    written = []
    if figures:
        from pipeline.figures.ensemble import plot_convergence  # lazy: matplotlib, not imported by a run or after Ctrl-C
        written.append(plot_convergence(runs, result, campaign_dir))
    return {"code_version": run_code_version(), "verdict": result["verdict"],
            "figures": [str(Path(p).relative_to(campaign_dir)) for p in written]}


def wall_per_member(specs, campaign_dir):
    """{variant: mean wall time (s) of its finished YADE runs} from their summary.json."""
    times = {}
    for spec, summary in finished_runs(campaign_dir, specs):
        times.setdefault(spec.tags.variant, []).append(summary.wall_s)
    return {name: float(np.mean(times[name])) for name in VARIANTS if name in times}


def compare_variants(runs, cost_per_member=None):
    """Every variant's P(toppled) and fall directions against the defaults' (see the
    module docstring); ``cost_per_member``: {variant: wall s per member}."""
    rows = []
    for (record_id, column), group in runs.groupby(["record_id", "column"], sort=True):
        ref = group[group["variant"] == REFERENCE]
        for name in VARIANTS:
            sub = group[group["variant"] == name]
            if sub.empty:
                continue
            t = sub["toppled"].astype(bool).to_numpy()
            az = np.where(t, sub["downfall_azimuth_deg"].to_numpy(float), np.nan)
            mean = circular_summary(az)
            row = {"record": record_id, "column": column, "variant": name,
                   "members": int(t.size), "toppled": int(t.sum()),
                   "p_toppled": float(t.mean()), "p_toppled_ci95": wilson_interval(t.sum(), t.size),
                   "mean_downfall_azimuth_deg": None if not t.any() or not math.isfinite(
                       mean["mean_deg"]) else mean["mean_deg"],
                   "resultant_length": None if not t.any() else mean["resultant_length"]}
            if name != REFERENCE and not ref.empty:
                rt = ref["toppled"].astype(bool).to_numpy()
                raz = np.where(rt, ref["downfall_azimuth_deg"].to_numpy(float), np.nan)
                row.update(compare_ensembles(rt, raz, t, az))
            rows.append(row)
    tests = [(i, key) for i, r in enumerate(rows) for key in ("fisher_p", "kuiper_p")
             if key in r]
    reject = holm_reject([rows[i][key] for i, key in tests], ALPHA)
    for (i, key), r in zip(tests, reject):
        rows[i][key.replace("_p", "_differs")] = r
    differ = [f"{r['record']} {r['column']} {r['variant']}" for r in rows
              if r.get("fisher_differs") or r.get("kuiper_differs")]
    cost_per_member = cost_per_member or {}
    n_tests = sum(r is not None for r in reject)
    # where every setting's members all fell (or all stood), Fisher's test cannot fail
    untested = sorted({f"{r['record']} {r['column']}" for r in rows} - {
        f"{r['record']} {r['column']}" for r in rows if 0.0 < r["p_toppled"] < 1.0})
    verdict = (f"convergence: {n_tests} comparisons with the defaults (Fisher's exact test on "
               f"P(toppled), Kuiper's test on the fall directions, Holm at {ALPHA:g}): "
               + ("none differs" if not differ else "differs: " + "; ".join(differ)))
    return {"reference": REFERENCE, "variants": VARIANTS, "alpha": ALPHA,
            "comparisons": n_tests, "differing": differ, "verdict": verdict,
            "p_toppled_untested": untested,
            "wall_s_per_member": cost_per_member,
            "cost_vs_default": {k: v / cost_per_member[REFERENCE] for k, v in
                                cost_per_member.items()} if REFERENCE in cost_per_member
            else {}, "rows": rows}


def _rows(result):
    frame = pd.DataFrame(result["rows"])
    for key in ("p_toppled_ci95", "falls"):
        if key in frame:
            frame[key] = frame[key].map(lambda v: v if not isinstance(v, list) else
                                        " ".join(f"{x:g}" for x in v))
    return frame


@dataclass(frozen=True)
class ConvergenceOptions(CampaignOptions):
    members: int = param(DEFAULT_MEMBERS, "", "members per record and variant", 2, 10000,
                         flag="--members")
    seed: int = param(DEFAULT_SEED, "", "seed of the first variant's Latin hypercube "
                      "(variant k: seed + k)", flag="--seed")

    def check(self):
        if check_seed(self.seed) + len(VARIANTS) > 2 ** 63:
            raise InputError(f"--seed must be below 2^63 - {len(VARIANTS)} (variant k: "
                             "seed + k)")


register(Campaign("convergence", "the model's convergence judged on ensembles: P(toppled) and "
                  "fall directions at 16, 32, 64 rim points and time step factor 0.15",
                  convergence_specs, run_column_spec, convergence_outputs, label="members",
                  options=ConvergenceOptions))
