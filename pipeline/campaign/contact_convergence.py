"""The model against the contact stiffness alone (``make contact-convergence``): the rock's
predictions from a shake-table campaign whose grid varies ``kn`` alone, Housner free
rocking of a block and a column, and the twin model's ensembles, per stiffness factor.

``python -m pipeline.campaign.contact_convergence DIR`` reads ``DIR/calibration.csv`` (the
campaign's runs) and the experiment table, and writes ``DIR/convergence.json``: per
stiffness factor (``x1`` the smallest kn of the grid, ``x3``, ``x10``, ...) its kn, the
scores, the number of tests predicted overturned, and how many single predictions equal
those of ``x1``; the same split by PGA below and from ``PGA_SPLIT_G``; the time step
(median, s) and wall time (s) of its runs.

Beside the rock, in the same file: ``free_rocking`` (with ``--free-rocking`` the YADE runs
of :mod:`pipeline.verification.stiffness` are made in ``DIR/free-rocking``, its table kept
in ``DIR/free-rocking/free_rocking.json``; without, that table is reused when there), the
paper's marble block and monolithic column rocking freely at each factor against Housner;
and ``twin``, the twin model's ensembles on one record at each factor
(``DIR/twin-x1``, ``DIR/twin-x3``, ... : ``campaign ensemble --vary kn_factor=F,F``, the
same seed, so member m has the same sampled friction, damping, geometry and rim phase at
every factor): P(toppled) with its Wilson interval, the fall directions' circular mean,
resultant length and spread, how many members keep their outcome of x1 and how far
the falls of those that fell at both turn, the time step and the wall time; and
``rock_restitution`` (with ``--free-rocking``, kept in ``DIR/free-rocking/rock.json``):
the rock of the shake-table part rocking freely in YADE
(:func:`pipeline.verification.contact_map.specimen_measure`: released toward
``ROCK_AZIMUTH_DEG``, the median over three releases) at the part's footprint and
damping per stiffness factor, and at its kn per damping ratio of ``ROCK_DAMPINGS``:
the rocking restitution a damping ratio stands for.  A part that has not run is said and
left out.
"""
import math
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import binomtest

from pipeline.campaign.run_dirs import finished_summary
from pipeline.campaign.shake_table_experiments import EXPERIMENTS, SPECIMEN, load_experiments
from pipeline.files import InputError, ToolError, read_run_json, write_json
from pipeline.outcome.summary import RunSummary
from pipeline.stats.circular import circular_summary
from pipeline.stats.classification import scores
from pipeline.stats.ensemble import wilson_interval
from pipeline.verification.stiffness import free_rocking_table
from pipeline.scenario import ColumnGeometry
from pipeline.verification import contact_map

PGA_SPLIT_G = 0.15
KN = re.compile(r"kn=([0-9.eE+-]+)")
TWIN_DIR = re.compile(r"twin-x([0-9.]+)$")
FREE_ROCKING_FILE = Path("free-rocking") / "free_rocking.json"
ROCK_FILE = Path("free-rocking") / "rock.json"
ROCK_AZIMUTH_DEG = 90.0          # along the table's axis (+x, East), toward the weak side
ROCK_DAMPINGS = (0.0, 0.05, 0.1, 0.36, 1.0)


def _band(rows, reference):
    out = scores(rows["observed"], rows["predicted"])
    same = rows["predicted"].to_numpy() == reference.loc[rows["test"]].to_numpy()
    return {"n": out["n"], "accuracy": out["accuracy"], "accuracy_95": out["accuracy_95"],
            "observed_overturned": int(rows["observed"].sum()),
            "predicted_overturned": int(rows["predicted"].sum()),
            "same_as_x1": int(same.sum())}


def summarise(campaign_dir, experiments=EXPERIMENTS):
    """The summary dict of a kn-only shake-table campaign in ``campaign_dir``."""
    campaign_dir = Path(campaign_dir)
    path = campaign_dir / "calibration.csv"
    if not path.is_file():
        raise InputError(f"{path}: not found (run the shake-table campaign first)")
    runs = pd.read_csv(path, dtype={"test": str})
    runs["kn"] = [float(KN.search(label).group(1)) if KN.search(label) else None
                  for label in runs["grid_point"]]
    if runs["kn"].isna().any() or runs["grid_point"].str.replace(KN, "", regex=True).nunique() != 1:
        raise InputError(f"{path}: the grid must vary kn alone")
    pga = load_experiments(experiments).set_index("test")["pga_g"]
    runs["pga_g"] = pga.loc[runs["test"]].to_numpy()
    stiffnesses = sorted(runs["kn"].unique())
    reference = runs[runs["kn"] == stiffnesses[0]].set_index("test")["predicted"]
    factors = {}
    for kn in stiffnesses:
        rows = runs[runs["kn"] == kn]
        if set(rows["test"]) != set(reference.index):
            raise InputError(f"{path}: kn {kn:g} was not run on the same tests as kn "
                             f"{stiffnesses[0]:g} (an unfinished campaign?)")
        factor = f"x{kn / stiffnesses[0]:.3g}"
        factors[factor] = {"kn": kn, **_band(rows, reference),
                           "pga_below": _band(rows[rows["pga_g"] < PGA_SPLIT_G], reference),
                           "pga_from": _band(rows[rows["pga_g"] >= PGA_SPLIT_G], reference),
                           **_cost(campaign_dir, rows.get("run_id"))}
    _relative_cost(factors)
    return {"grid_point": runs["grid_point"].iloc[0], "pga_split_g": PGA_SPLIT_G,
            "tests": sorted(reference.index), "factors": factors}


def _cost(campaign_dir, run_ids):
    """time_step_s (median) and wall_s (mean per run, and total) of the finished runs."""
    done = [] if run_ids is None else [finished_summary(campaign_dir, r) for r in run_ids]
    return cost([s.time_step_s for s in done if s is not None and s.simulated],
                [s.wall_s for s in done if s is not None])


def cost(time_steps, walls):
    """What a factor's runs cost: the median time step (s) of those YADE ran, the mean and
    total wall time (s) per run; None where no run is known."""
    steps = [s for s in time_steps if s is not None]
    return {"time_step_s": float(np.median(steps)) if steps else None,
            "wall_s_per_run": float(np.mean(walls)) if len(walls) else None,
            "wall_s_total": float(np.sum(walls)) if len(walls) else None}


def _relative_cost(factors):
    """Add time_step_vs_x1 and wall_vs_x1 (ratios to the first factor's) to each factor."""
    base = next(iter(factors.values()))
    for row in factors.values():
        for key, ratio in (("time_step_s", "time_step_vs_x1"),
                           ("wall_s_per_run", "wall_vs_x1")):
            known = row.get(key) is not None and base.get(key)
            row[ratio] = row[key] / base[key] if known else None


def twin_summary(members, record=None):
    """The twin model's ensembles at each stiffness factor: ``members`` a table with
    factor (kn / kn at x1), member (>= 0; the same number is the same sampled member at
    every factor), column, toppled, downfall_azimuth_deg, time_step_s and wall_s (of the
    member's run).  Per factor (x1, x3, ...): per column P(toppled) with its Wilson
    interval, the falls' circular mean, resultant length and spread (deg), members with
    the outcome of x1, the exact McNemar test of P against x1's on the same members
    (``p_value_vs_x1``: two-sided binomial on the members that changed, toppling only at
    one factor; 1 when none changed), the median and largest turn (deg) of the falls of
    members that fell at both; and the runs' cost with ratios to x1."""
    members = members[members["member"] >= 0]
    factors = sorted(members["factor"].unique())
    if not factors or factors[0] != 1:
        raise InputError("twin ensembles: the ensemble at kn x1 is needed (twin-x1)")
    reference = members[members["factor"] == 1].set_index(["member", "column"])
    out = {}
    for factor in factors:
        rows = members[members["factor"] == factor]
        columns = {}
        for column, group in rows.groupby("column", sort=True):
            toppled = group["toppled"].astype(bool).to_numpy()
            az = np.where(toppled, group["downfall_azimuth_deg"].to_numpy(float), np.nan)
            stats = circular_summary(az)
            keys = list(zip(group["member"], group["column"]))
            paired = reference.reindex(keys)
            base_toppled = paired["toppled"].astype(bool).to_numpy()
            known = paired["toppled"].notna().to_numpy()
            both = known & toppled & base_toppled
            turn = np.abs((az[both] - paired["downfall_azimuth_deg"].to_numpy(float)[both]
                           + 180.0) % 360.0 - 180.0)
            fell = bool(toppled.any()) and math.isfinite(stats["mean_deg"])
            only_here = int((known & toppled & ~base_toppled).sum())
            only_x1 = int((known & ~toppled & base_toppled).sum())
            changed = only_here + only_x1
            columns[column] = {
                "members": int(toppled.size), "toppled": int(toppled.sum()),
                "p_toppled": float(toppled.mean()),
                "p_toppled_ci95": wilson_interval(int(toppled.sum()), int(toppled.size)),
                "mean_downfall_azimuth_deg": float(stats["mean_deg"]) if fell else None,
                "resultant_length": float(stats["resultant_length"]) if toppled.any()
                else None,
                "circular_std_deg": float(stats["circular_std_deg"]) if toppled.any()
                else None,
                "same_outcome_as_x1": int((toppled[known] == base_toppled[known]).sum()),
                "paired_with_x1": int(known.sum()),
                "toppled_only_here": only_here, "toppled_only_at_x1": only_x1,
                "p_value_vs_x1": float(binomtest(min(only_here, only_x1), changed).pvalue)
                if changed else 1.0,
                "fell_at_both": int(both.sum()),
                "median_turn_vs_x1_deg": float(np.median(turn)) if turn.size else None,
                "max_turn_vs_x1_deg": float(turn.max()) if turn.size else None}
        runs = rows.drop_duplicates("member")
        out[f"x{factor:g}"] = {"kn_factor": float(factor), "members": int(len(runs)),
                               "columns": columns,
                               **cost(runs["time_step_s"].tolist(), runs["wall_s"].tolist())}
    _relative_cost(out)
    return {"record": record, "factors": out}


def load_twin(campaign_dir):
    """The members of the twin ensembles ``campaign_dir/twin-x*`` (one table for
    :func:`twin_summary`) and their record; (None, None) when none has run."""
    frames, records = [], set()
    for sub in sorted(Path(campaign_dir).glob("twin-x*")):
        match = TWIN_DIR.search(sub.name)
        path = sub / "members.csv"
        if match is None or not path.is_file():
            continue
        frame = pd.read_csv(path)
        frame["factor"] = float(match.group(1))
        summaries = [RunSummary.load(sub / run_dir / "summary.json")
                     for run_dir in frame["run_dir"]]
        frame["time_step_s"] = [s.time_step_s if s.simulated else None for s in summaries]
        frame["wall_s"] = [s.wall_s for s in summaries]
        records |= set(frame["record_id"])
        frames.append(frame)
    if not frames:
        return None, None
    if len(records) != 1:
        raise InputError(f"{campaign_dir}: the twin ensembles ran different records "
                         f"({', '.join(sorted(records))}); one record at every factor")
    return pd.concat(frames, ignore_index=True), records.pop()


def _grid_point(label):
    """{name: value} of a campaign's grid-point label ("name=v, name=v")."""
    return {name.strip(): float(value) for name, _, value in
            (item.partition("=") for item in label.split(",")) if name.strip()}


def rock_restitution(rock, specimen=None, log=print):
    """The rock's rocking restitution in YADE at the rock part's footprint and damping
    per stiffness factor, and at its x1 kn per damping ratio (ROCK_DAMPINGS and its
    own); Housner's for a block of its critical angle beside (1 - 1.5 sin^2 alpha)."""

    point = {k: v for k, v in _grid_point(rock["grid_point"]).items()
             if k not in ("kn", "rotate_deg")}
    description = ColumnGeometry.load(specimen or SPECIMEN).to_dict()
    if "footprint_tolerance_m" in point:
        description["footprint_tolerance_m"] = point.pop("footprint_tolerance_m")
    geometry = ColumnGeometry.from_dict(description)
    damping = point.pop("damping")
    options = {k: v for k, v in point.items() if k in ("mu_s", "mu_k")}

    def measured(kn, d):
        value = contact_map.specimen_measure(geometry, kn, ROCK_AZIMUTH_DEG, **options)[0](d)
        log(f"rock free rocking: kn {kn:g}, damping {d:g}: restitution {value:.4f}")
        return value

    first = min(r["kn"] for r in rock["factors"].values())
    alpha = math.radians(geometry.critical_angle_along_deg(ROCK_AZIMUTH_DEG))
    return {"specimen": geometry.name, "azimuth_deg": ROCK_AZIMUTH_DEG,
            "footprint_tolerance_m": description.get("footprint_tolerance_m"),
            "damping": damping, "friction": options,
            "housner_block_restitution": 1.0 - 1.5 * math.sin(alpha) ** 2,
            "critical_angle_along_deg": math.degrees(alpha),
            "factors": {f: {"kn": r["kn"], "restitution": measured(r["kn"], damping)}
                        for f, r in rock["factors"].items()},
            "by_damping": [{"damping": d, "restitution": measured(first, d)}
                           for d in sorted({*ROCK_DAMPINGS, damping})]}


def summarise_all(campaign_dir, free_rocking=False, experiments=EXPERIMENTS, log=print):
    """convergence.json's content: the rock's part (:func:`summarise`, when
    ``calibration.csv`` is there), ``free_rocking`` (run now when ``free_rocking``, else
    the table kept from an earlier run) and ``twin`` (:func:`twin_summary`); a part not
    run is said through ``log`` and left out; InputError when no part has run."""
    campaign_dir = Path(campaign_dir)
    out = {}
    if (campaign_dir / "calibration.csv").is_file():
        out.update(summarise(campaign_dir, experiments))
    else:
        log(f"rock: not run ({campaign_dir / 'calibration.csv'} not found)")
    kept = campaign_dir / FREE_ROCKING_FILE
    if free_rocking:
        out["free_rocking"] = free_rocking_table(kept.parent, log=log)
        write_json(kept, out["free_rocking"])
    elif kept.is_file():
        out["free_rocking"] = read_run_json(kept, "free-rocking table")[1]
    else:
        log(f"free rocking: not run (--free-rocking runs it into {kept.parent})")
    kept_rock = campaign_dir / ROCK_FILE
    if free_rocking and "factors" in out:
        out["rock_restitution"] = rock_restitution(out, log=log)
        write_json(kept_rock, out["rock_restitution"])
    elif kept_rock.is_file():
        out["rock_restitution"] = read_run_json(kept_rock, "rock free-rocking table")[1]
    members, record = load_twin(campaign_dir)
    if members is not None:
        out["twin"] = twin_summary(members, record)
    else:
        log(f"twin model: not run (no ensemble in {campaign_dir / 'twin-x1'})")
    if not out:
        raise InputError(f"{campaign_dir}: nothing to summarise (run make contact-convergence)")
    return out


def table_lines(summary):
    """The short table of convergence.json: one line per part and factor."""
    lines = []
    for factor, row in summary.get("factors", {}).items():
        lines.append(f"rock {factor} (kn {row['kn']:g}): accuracy {row['accuracy']:.3f} "
                     f"[{row['accuracy_95'][0]:.3f}, {row['accuracy_95'][1]:.3f}] on "
                     f"{row['n']}, {row['predicted_overturned']} predicted overturned "
                     f"({row['observed_overturned']} observed), {row['same_as_x1']} as x1; "
                     f"PGA < {PGA_SPLIT_G:g} g: {row['pga_below']['predicted_overturned']} of "
                     f"{row['pga_below']['n']} predicted overturned "
                     f"({row['pga_below']['observed_overturned']} observed)"
                     + _cost_text(row))
    for body, table in summary.get("free_rocking", {}).items():
        for factor, row in table["factors"].items():
            lines.append(f"free rocking {body} {factor} (kn {row['kn']:g}): restitution "
                         f"{row['restitution']:.4f} (Housner {table['housner_restitution']:.4f}"
                         f"; per impact " + " ".join(f"{e:.4f}" for e in
                                                    row["restitution_per_impact"])
                         + f"), impact times within "
                         f"{100 * row['max_rel_error_impact_times_housner']:.1f} % of Housner's, "
                         f"{row['max_abs_impact_time_minus_x1_s'] * 1e3:.1f} ms of x1's"
                         + _cost_text({**row, "wall_s_per_run": row["wall_s"]}))
        for entry in table.get("at_damping", []):
            lines.append(f"free rocking {body} at damping {entry['damping']:g}: restitution "
                         + ", ".join(f"{factor} {row['restitution']:.4f}"
                                     for factor, row in entry["factors"].items()))
    rock = summary.get("rock_restitution")
    if rock:
        lines.append(f"free rocking {rock['specimen']} (damping {rock['damping']:g}): restitution "
                     + ", ".join(f"{f} {r['restitution']:.4f}" for f, r in rock["factors"].items())
                     + "; at x1 by damping " + ", ".join(
                         f"{r['damping']:g}: {r['restitution']:.4f}" for r in rock["by_damping"])
                     + f" (Housner's block of {rock['critical_angle_along_deg']:.1f} deg: "
                     f"{rock['housner_block_restitution']:.4f})")
    twin = summary.get("twin")
    for factor, row in (twin or {}).get("factors", {}).items():
        parts = []
        for column, c in row["columns"].items():
            ci = c["p_toppled_ci95"]
            direction = "" if c["mean_downfall_azimuth_deg"] is None else (
                f", falls {c['mean_downfall_azimuth_deg']:.0f} deg (R "
                f"{c['resultant_length']:.2f})")
            parts.append(f"{column} P {c['p_toppled']:.2f} [{ci[0]:.2f}, {ci[1]:.2f}]"
                         f"{direction}, {c['same_outcome_as_x1']}/{c['paired_with_x1']} as x1"
                         f" (McNemar p {c['p_value_vs_x1']:.2f})")
        lines.append(f"twin {twin['record']} {factor} ({row['members']} members): "
                     + "; ".join(parts) + _cost_text(row))
    return lines


def _cost_text(row):
    if row.get("time_step_s") is None:
        return ""
    ratio = "" if row.get("time_step_vs_x1") is None else (
        f" (x{row['time_step_vs_x1']:.2f}), wall {row['wall_s_per_run']:.1f} s per run "
        f"(x{row['wall_vs_x1']:.2f})" if row.get("wall_vs_x1") is not None else "")
    return f"; time step {row['time_step_s']:.3g} s{ratio}"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    free_rocking = "--free-rocking" in argv
    rest = [a for a in argv if a != "--free-rocking"]
    if len(rest) != 1 or rest[0].startswith("-"):
        print("usage: python -m pipeline.campaign.contact_convergence CAMPAIGN_DIR "
              "[--free-rocking]", file=sys.stderr)
        return 2
    try:
        summary = summarise_all(rest[0], free_rocking=free_rocking)
    except ToolError as exc:              # bad input, or a YADE run that failed
        print(f"error: {exc}", file=sys.stderr)
        return 1
    write_json(Path(rest[0]) / "convergence.json", summary)
    for line in table_lines(summary):
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
