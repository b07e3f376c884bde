"""The members' ranges chosen out of sample: folds of the calibration tests by date.

A rock is re-seated between test days (it was put back by hand after each overturn, and
the days differ: SP1's August overturned far less often than June-July), so the tests of
one day share a seating another day does not.  The calibration tests' days are cut into
``folds`` blocks of consecutive days with about equal numbers of tests
(:func:`date_folds`; a day is never split), and each candidate's members are scored on
each block alone.  Chosen (:func:`choose_ranges`): the candidate whose worst block scores
best by log-likelihood per test (a proper score); a range that fits some days and is
sure and wrong on others loses to one that holds on every block.  The choice is checked
out of sample by cross-validation: for each block, the same rule applied to the other
blocks chooses, and its choice is scored on the block it did not see, with the block's
reliability diagram (P = 0 and P = 1 bins apart,
:func:`pipeline.stats.forecast.reliability_with_ends`).  A member's run is one run
whatever the fold (its id is its inputs), so the folds cost no run.
"""
import numpy as np
import pandas as pd

from pipeline.files import InputError
from pipeline.stats.forecast import forecast_scores, reliability_with_ends

DEFAULT_FOLDS = 4
CHOICE_RULE = ("each candidate's members on the calibration tests only, scored by "
               "log-likelihood per test on each fold (blocks of consecutive test days); "
               "chosen: the best worst fold (ties: the higher log-likelihood over all "
               "calibration tests, then the lower Brier score, then the first given); "
               "checked by cross-validation (each fold scores the choice the rule makes on "
               "the other folds); frozen, then run and scored on every test")
KEPT = ("log_likelihood_per_test", "brier", "accuracy", "balanced_accuracy")


def date_folds(days, folds):
    """Fold (0 .. folds - 1) of each test from its day: consecutive days in blocks of
    about equal test counts, a day's tests in one block (a day goes to the block its
    middle test falls in).  One-line InputError when the days cannot fill ``folds``."""
    days = pd.Series(pd.to_datetime(pd.Series(list(days))).to_numpy())
    if not (isinstance(folds, (int, np.integer)) and folds >= 1):
        raise InputError(f"--folds must be a whole number >= 1, got {folds!r}")
    counts = days.value_counts().sort_index()
    before = np.cumsum(counts.to_numpy()) - counts.to_numpy()
    block = np.floor(folds * (before + counts.to_numpy() / 2.0) / len(days)).astype(int)
    used = len(set(block))
    if used < folds:
        raise InputError(f"--folds {folds}: the calibration tests' {len(counts)} test day(s) "
                         f"fill only {used} block(s) of about equal size; give fewer folds")
    return days.map(dict(zip(counts.index, block))).to_numpy(int)


def _scores(rows):
    s = forecast_scores(rows["observed"].to_numpy(bool), rows["P"].to_numpy(float),
                        rows["runs"].to_numpy())
    return {"tests": s["n"], **{k: s[k] for k in KEPT}}


def _rank(entry, k):
    return (entry["worst_fold_log_likelihood"], entry["log_likelihood_per_test"],
            -entry["brier"], -k)


def _rule(tried, fold_of, keep):
    """Each candidate's scores on the folds in ``keep``; the index of the chosen."""
    table = []
    for text, rows in tried:
        rows = rows[rows["P"].notna()]
        folds = rows["test"].map(fold_of).to_numpy()
        on = rows[np.isin(folds, keep)]
        per_fold = [s for s in (_scores(on[on["test"].map(fold_of) == f]) for f in keep)
                    if s["tests"]]
        table.append({"ranges": text or None, **_scores(on),
                      "member_runs": int(on["runs"].sum()),
                      "per_fold_log_likelihood": [s["log_likelihood_per_test"]
                                                  for s in per_fold],
                      "worst_fold_log_likelihood": min(s["log_likelihood_per_test"]
                                                       for s in per_fold)})
    best = max(range(len(table)), key=lambda k: _rank(table[k], k))
    return table, best


def choose_ranges(tried, fold_of=None):
    """The candidate with the best worst fold (``fold_of``: {test: fold}; None: one fold,
    the log-likelihood over all tests) and, with two folds or more, the cross-validation
    of that rule: {"rule", "chosen", "candidates", "folds", "cross_validated"}.
    ``tried``: (ranges text, members.csv rows: test, observed, P, runs)."""
    if fold_of is None:
        fold_of = {t: 0 for _, rows in tried for t in rows["test"]}
    every = sorted(set(fold_of.values()))
    table, best = _rule(tried, fold_of, every)
    folds = []
    for f in every if len(every) > 1 else []:
        _, chosen = _rule(tried, fold_of, [g for g in every if g != f])
        rows = tried[chosen][1]
        rows = rows[rows["P"].notna() & (rows["test"].map(fold_of) == f)]
        folds.append({"fold": int(f), "days": _days(rows), "chosen_without": tried[chosen][0]
                      or None, "held_out": _scores(rows),
                      "reliability": reliability_with_ends(
                          rows["observed"].to_numpy(bool), rows["P"].to_numpy(float),
                          rows["runs"].to_numpy())})
    tests = sum(f["held_out"]["tests"] for f in folds)
    cv = (sum(f["held_out"]["log_likelihood_per_test"] * f["held_out"]["tests"]
              for f in folds) / tests) if tests else None
    return {"rule": CHOICE_RULE, "chosen": tried[best][0], "candidates": table,
            "folds": folds, "cross_validated_log_likelihood_per_test": cv}


def _days(rows):
    if "date" not in rows.columns or rows.empty:
        return None
    days = sorted(str(d) for d in rows["date"])
    return [days[0], days[-1]]


def fold_table(choice):
    """The folds' reliability rows as one table (``folds.csv``): fold, its days, the
    choice made without it, and per bin n, mean P, overturned, observed rate, its Wilson
    95 % interval and whether it holds the mean P."""
    out = []
    for f in choice["folds"]:
        for row in f["reliability"]:
            lo, hi = row["observed_ci95"]
            out.append({"fold": f["fold"], "first_day": (f["days"] or [None])[0],
                        "last_day": (f["days"] or [None, None])[1],
                        "ranges": f["chosen_without"] or "default", "bin": row["label"],
                        "n": row["n"], "mean_P": row["mean_forecast"],
                        "mean_P_held": row["mean_forecast_held"],
                        "overturned": row["overturned"], "observed_rate": row["observed_rate"],
                        "ci95_low": lo, "ci95_high": hi, "covers": row["covers"]})
    return pd.DataFrame(out)
