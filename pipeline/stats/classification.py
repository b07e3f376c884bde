"""Predicted against observed yes/no outcomes (overturned or not): the scores the
precariously-balanced-rock community reports, and rates per bin of ground motion."""
import math

import numpy as np

from pipeline.stats.ensemble import wilson_interval


def scores(observed, predicted):
    """Accuracy, precision, recall, F1 and the confusion table of boolean sequences.
    Undefined ratios (no predicted or no observed overturn) are None."""
    obs = np.asarray(observed, bool)
    pred = np.asarray(predicted, bool)
    if obs.shape != pred.shape:
        raise ValueError("observed and predicted differ in length")
    tp = int((obs & pred).sum())
    tn = int((~obs & ~pred).sum())
    fp = int((~obs & pred).sum())
    fn = int((obs & ~pred).sum())
    n = tp + tn + fp + fn
    precision = tp / (tp + fp) if tp + fp else None
    recall = tp / (tp + fn) if tp + fn else None
    f1 = (2 * precision * recall / (precision + recall)
          if precision is not None and recall is not None and precision + recall else None)
    accuracy = (tp + tn) / n if n else None
    low, high = wilson_interval(tp + tn, n) if n else (None, None)
    return {"n": n, "accuracy": accuracy, "accuracy_95": [low, high],
            "precision": precision, "recall": recall, "f1": f1,
            "confusion": {"overturned_predicted_overturned": tp,
                          "overturned_predicted_standing": fn,
                          "standing_predicted_overturned": fp,
                          "standing_predicted_standing": tn}}


def binned_rates(x, y, outcome, x_edges, y_edges):
    """Rate of ``outcome`` (booleans, NaN = unknown) per bin of x and y: (rate, count),
    arrays of shape (len(x_edges) - 1, len(y_edges) - 1); rate NaN where count is 0."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    out = np.asarray(outcome, float)
    known = np.isfinite(out)
    count, _, _ = np.histogram2d(x[known], y[known], [x_edges, y_edges])
    hits, _, _ = np.histogram2d(x[known], y[known], [x_edges, y_edges], weights=out[known])
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(count > 0, hits / np.maximum(count, 1), math.nan)
    return rate, count.astype(int)
