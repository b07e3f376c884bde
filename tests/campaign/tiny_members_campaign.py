"""A hand-made finished shake-table members campaign (no YADE): members.csv,
members_runs.csv and each member run's summary.json in the formats the campaign writes."""
import json

import pandas as pd

BASE_WIDTH_M = 0.09
CRITICAL_DEG = 5.0


def member_run(toppled=False, tilt_deg=0.0, base_slip_m=0.0, residual_slide_m=0.0,
               kn=1e8, damping=0.1, mu_s=0.7, footprint_m=0.001, rotate_deg=0.0,
               twist_deg=0.0):
    """One member run's values (angles deg, lengths m, kn N/m)."""
    return {"toppled": toppled, "tilt_deg": tilt_deg, "base_slip_m": base_slip_m,
            "residual_slide_m": residual_slide_m, "kn": kn, "damping": damping,
            "mu_s": mu_s, "footprint_m": footprint_m, "rotate_deg": rotate_deg,
            "twist_deg": twist_deg}


def summary(test, run):
    """A run's summary.json as the campaign writes it (the keys the run's files hold)."""
    damage = {"peak_capital_displacement_m": 0.0, "base_width_m": BASE_WIDTH_M,
              "max_rotation_deg": run["tilt_deg"], "critical_angle_deg": CRITICAL_DEG,
              "joints": [{"lower": "pedestal", "upper": "monolithic[0]",
                          "slide_m": run["residual_slide_m"], "twist_deg": run["twist_deg"]}],
              "toppled": run["toppled"]}
    return {"record": f"{test}.txt",
            "parameters": {"kn": run["kn"], "damping": run["damping"], "mu_s": run["mu_s"],
                           "rotate_deg": run["rotate_deg"],
                           "geometry": {"name": "SP1",
                                        "footprint_tolerance_m": run["footprint_m"]}},
            "columns": [{"column": "monolithic", "toppled": run["toppled"],
                         "max_tilt_deg": run["tilt_deg"], "base_slip_m": run["base_slip_m"],
                         "damage": damage}],
            "start_in_file_s": 0.0}


def write_campaign(directory, tests):
    """Write the campaign of ``tests``: dicts of test, date, split, pga_g, pgv_pga_s,
    observed and runs (a list of :func:`member_run`)."""
    members, runs = [], []
    for t in tests:
        k = sum(r["toppled"] for r in t["runs"])
        n = len(t["runs"])
        members.append({"test": t["test"], "date": t["date"], "split": t["split"],
                        "pga_g": t["pga_g"], "pgv_pga_s": t["pgv_pga_s"],
                        "observed": t["observed"], "runs": n, "overturned": k,
                        "P": k / n if n else None, "ci95_low": 0.0, "ci95_high": 1.0,
                        "single_set_predicted": False})
        for m, run in enumerate(t["runs"]):
            run_id = f"{t['test'].lower()}m{m}"
            (directory / "runs" / run_id).mkdir(parents=True)
            (directory / "runs" / run_id / "summary.json").write_text(
                json.dumps(summary(t["test"], run)))
            runs.append({"test": t["test"], "member": m, "observed": t["observed"],
                         "predicted": run["toppled"], "max_tilt_deg": run["tilt_deg"],
                         "run_id": run_id})
        runs.append({"test": t["test"], "member": -1, "observed": t["observed"],
                     "predicted": False, "max_tilt_deg": 0.0, "run_id": "single"})
    pd.DataFrame(members).to_csv(directory / "members.csv", index=False)
    pd.DataFrame(runs).to_csv(directory / "members_runs.csv", index=False)


def write_member_runs(directory, per_test):
    """The member runs of members.csv rows ``per_test`` (runs, overturned): the first
    ``overturned`` toppled, the others still."""
    write_campaign(directory, [{**row, "runs": [member_run(toppled=j < row["overturned"],
                                                           tilt_deg=90.0 * (j < row["overturned"]))
                                                for j in range(row["runs"])]}
                               for row in per_test.to_dict("records")])
