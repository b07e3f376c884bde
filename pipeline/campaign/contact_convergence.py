"""The rock's predictions against the contact stiffness: a shake-table campaign whose grid
varies ``kn`` alone (``make contact-convergence``) summarised per stiffness factor.

``python -m pipeline.campaign.contact_convergence DIR`` reads ``DIR/calibration.csv`` (the
campaign's runs) and the experiment table, and writes ``DIR/convergence.json``: per
stiffness factor (``x1`` the smallest kn of the grid, ``x3``, ``x10``, ...) its kn, the
scores, the number of tests predicted overturned, and how many single predictions equal
those of ``x1``; the same split by PGA below and from ``PGA_SPLIT_G``.
"""
import re
import sys
from pathlib import Path

import pandas as pd

from pipeline.campaign.shake_table import EXPERIMENTS, load_experiments
from pipeline.files import InputError, write_json
from pipeline.stats.classification import scores

PGA_SPLIT_G = 0.15
KN = re.compile(r"kn=([0-9.eE+-]+)")


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
                           "pga_from": _band(rows[rows["pga_g"] >= PGA_SPLIT_G], reference)}
    return {"grid_point": runs["grid_point"].iloc[0], "pga_split_g": PGA_SPLIT_G,
            "tests": sorted(reference.index), "factors": factors}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python -m pipeline.campaign.contact_convergence CAMPAIGN_DIR",
              file=sys.stderr)
        return 2
    try:
        summary = summarise(argv[0])
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    write_json(Path(argv[0]) / "convergence.json", summary)
    for factor, row in summary["factors"].items():
        print(f"{factor} (kn {row['kn']:g}): accuracy {row['accuracy']:.3f} on {row['n']}, "
              f"{row['predicted_overturned']} predicted overturned "
              f"({row['observed_overturned']} observed), {row['same_as_x1']} as x1; PGA < "
              f"{PGA_SPLIT_G:g} g: {row['pga_below']['predicted_overturned']} of "
              f"{row['pga_below']['n']} predicted overturned "
              f"({row['pga_below']['observed_overturned']} observed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
