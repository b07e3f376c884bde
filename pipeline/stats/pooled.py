"""The paper's question pooled over records: does a column fall toward (or away from) the
epicentre?  Every record weighs alike; fall directions relative to the back azimuth (deg),
two-stage percentile bootstrap intervals, and the answer as one sentence."""
import numpy as np

from pipeline.stats.circular import (AWAY_MIN_DEG as AWAY, TOWARD_MAX_DEG as TOWARD,
                                     angle_difference_deg)


NO_RELATION = {"fraction_toward": 0.25, "fraction_away": 0.25, "fraction_transverse": 0.5,
               "radial_alignment": 0.0, "polarity": 0.0}   # falls that ignore the epicentre


def _pooled(toppled, relative):
    """Record-weighted statistics of one (re)sample: lists per record of toppled flags
    (bool arrays) and fall-minus-back-azimuth angles of the falls (deg)."""
    p = float(np.mean([t.mean() for t in toppled]))
    with_falls = [r for r in relative if r.size]
    if not with_falls:
        return {"p_toppled": p, **dict.fromkeys(NO_RELATION)}
    size = [np.abs(angle_difference_deg(r, 0.0)) for r in with_falls]
    rad = [np.radians(r) for r in with_falls]
    return {"p_toppled": p,
            "fraction_toward": float(np.mean([(s <= TOWARD).mean() for s in size])),
            "fraction_away": float(np.mean([(s >= AWAY).mean() for s in size])),
            "fraction_transverse": float(np.mean([((s > TOWARD) & (s < AWAY)).mean()
                                                  for s in size])),
            "radial_alignment": float(np.mean([np.cos(2 * r).mean() for r in rad])),
            "polarity": float(np.mean([np.cos(r).mean() for r in rad]))}


def pooled_answer(toppled, relative_deg, resamples=2000, seed=0, confidence=0.95):
    """The paper's question over records: does a column fall toward (or away from) the
    epicentre?  ``toppled``: per record, the members' toppled flags; ``relative_deg``:
    per record, the members' downfall minus back azimuth (deg; NaN when standing).

    Every record weighs alike (a record's falls share its weight): P(toppled); the
    fractions of falls toward (|diff| <= 45 deg), away (>= 135) and transverse; the
    radial alignment, mean cos(2 diff) (+1 along the epicentre line, -1 across it, 0 no
    relation); the polarity, mean cos(diff) (+1 toward, -1 away).  Intervals: a two-stage
    percentile bootstrap, records drawn with replacement and then each drawn record's
    members, so that they hold both the choice of records and the ensembles' Monte Carlo
    error; ``mc_error``: the bootstrap standard deviation.  ``no_relation``: the values
    of falls that ignore the epicentre; ``differs``: the interval excludes it."""
    toppled = [np.asarray(t, bool) for t in toppled]
    relative = [np.asarray(r, float) for r in relative_deg]
    if not toppled or len(toppled) != len(relative) or any(
            t.size == 0 or t.size != r.size for t, r in zip(toppled, relative)):
        raise ValueError("pooled_answer needs, per record, as many members as directions")
    falls = [r[t & np.isfinite(r)] for t, r in zip(toppled, relative)]
    estimate = _pooled(toppled, falls)
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(resamples):
        picked = rng.integers(0, len(toppled), len(toppled))
        t_draw, f_draw = [], []
        for k in picked:
            members = rng.integers(0, toppled[k].size, toppled[k].size)
            t, r = toppled[k][members], relative[k][members]
            t_draw.append(t)
            f_draw.append(r[t & np.isfinite(r)])
        draws.append(_pooled(t_draw, f_draw))
    tail = 50.0 * (1.0 - confidence)
    out = {"records": len(toppled), "members": int(sum(t.size for t in toppled)),
           "records_with_falls": int(sum(f.size > 0 for f in falls)),
           "falls": int(sum(f.size for f in falls)), "resamples": resamples, "seed": seed,
           "confidence": confidence, "statistics": {}}
    for name, value in estimate.items():
        values = np.array([d[name] for d in draws if d[name] is not None], float)
        ok = value is not None and values.size >= 0.5 * resamples
        ci = [float(v) for v in np.percentile(values, [tail, 100 - tail])] if ok else None
        reference = NO_RELATION.get(name)
        out["statistics"][name] = {
            "estimate": value, "ci95": ci, "mc_error": float(values.std(ddof=1)) if ok else None,
            "no_relation": reference,
            "differs": None if reference is None or ci is None
            else bool(not ci[0] <= reference <= ci[1])}
    return out


QUESTION = ("Do the columns fall toward (or away from) the epicentre?  Hinzen (2009) asked it "
            "of single runs; here every record's ensemble answers, pooled over the records.")


def pooled_summary(runs, resamples=2000):
    """The paper's question over the records of an ensemble campaign that have a back
    azimuth (:func:`pooled_answer` per column: every record
    weighs alike; intervals hold the choice of records and the members' Monte Carlo
    error); None for fewer than two such records."""
    members = runs[(runs["member"] >= 0) & runs["back_azimuth_deg"].notna()]
    records = list(dict.fromkeys(members["record_id"]))
    if len(records) < 2:
        return None
    columns = []
    for column, group in members.groupby("column", sort=True):
        toppled, relative = [], []
        for record_id in records:
            sub = group[group["record_id"] == record_id].sort_values("member")
            t = sub["toppled"].astype(bool).to_numpy()
            toppled.append(t)
            relative.append(np.where(t, angle_difference_deg(
                sub["downfall_azimuth_deg"].to_numpy(float),
                sub["back_azimuth_deg"].to_numpy(float)), np.nan))
        answer = pooled_answer(toppled, relative, resamples=resamples)
        columns.append({"column": column, **answer, "answer": pooled_sentence(answer)})
    return {"question": QUESTION, "records": len(records), "record_ids": records,
            "members_per_record": {r: int((members["record_id"] == r).sum()
                                          / members["column"].nunique()) for r in records},
            "columns": columns}


def pooled_sentence(answer):
    """One sentence: what the pooled fall directions say of the epicentre's direction."""
    st = answer["statistics"]

    def value(name, digits=2):
        s = st[name]
        return (f"{s['estimate']:.{digits}f} [{s['ci95'][0]:.{digits}f}, "
                f"{s['ci95'][1]:.{digits}f}]")

    p = f"P(toppled) {value('p_toppled')} per record"
    if answer["falls"] < 2 or st["polarity"]["ci95"] is None:
        return f"{p}; too few falls to say where they point"
    polar, radial = st["polarity"], st["radial_alignment"]
    if polar["differs"]:
        side = "toward" if polar["estimate"] > 0 else "away from"
        finding = f"falls lean {side} the epicentre (polarity {value('polarity')}, 0: no relation)"
    elif radial["differs"]:
        side = "along" if radial["estimate"] > 0 else "across"
        finding = (f"falls gather {side} the epicentre line, as often toward as away "
                   f"(radial alignment {value('radial_alignment')}, 0: no relation)")
    else:
        finding = (f"the fall directions show no relation to the epicentre's direction "
                   f"(polarity {value('polarity')}, radial alignment "
                   f"{value('radial_alignment')}; 0: no relation)")
    return (f"{p}; {finding}; toward {value('fraction_toward')}, away "
            f"{value('fraction_away')} of the falls (0.25 each without a relation)")
