"""Ensembles sized by their error: members are added in Latin-hypercube batches to the
records whose toppling probability (and, where falls gather, mean direction) is not yet
as precise as asked (:func:`run_sized`, the ``ensemble`` campaign's driver)."""
import json
import logging
import math
from pathlib import Path

from pipeline.campaign.executor import RUN_CORE_S
from pipeline.campaign.run_dirs import count_finished
from pipeline.files import write_json
from pipeline.stats.ensemble import wilson_interval

log = logging.getLogger(__name__)


DEFAULT_PRECISION = 0.1       # half-width of P(toppled)'s 95 % interval


DEFAULT_ARC_DEG = 60.0        # width of the mean direction's 95 % interval, where falls gather


DEFAULT_MAX_MEMBERS = 256


CONCENTRATED = {"falls": 5, "resultant_length": 0.5}   # "falls concentrate"


def converged(summary, precision, arc_deg):
    """(bool, why) for one record's summary: every column's P(toppled) interval within
    +-``precision`` and, where falls concentrate, its mean-direction interval under
    ``arc_deg``."""
    for col in summary["columns"]:
        lo, hi = col["p_toppled_ci95"]
        if (hi - lo) / 2 > precision:
            return False, f"{col['column']}: P(toppled) +-{(hi - lo) / 2:.2f}"
        ci = col.get("mean_azimuth_ci95_deg")
        if (col["toppled"] >= CONCENTRATED["falls"] and ci is not None
                and (col["resultant_length"] or 0) >= CONCENTRATED["resultant_length"]):
            width = (ci[1] - ci[0]) % 360.0
            if width > arc_deg:
                return False, f"{col['column']}: mean direction arc {width:.0f} deg"
    return True, "precision reached"


def members_needed(summary, precision, batch, cap, arc_deg=None):
    """Members (whole batches beyond the record's current ones, at most ``cap``, at least
    one batch more) whose P(toppled) Wilson interval would be within +-``precision`` at the
    fractions toppled so far: a record far from its precision gets several batches in one
    round instead of a round per batch; likewise for a mean direction's interval wider
    than ``arc_deg`` where falls gather (its width shrinks as 1 / sqrt(falls))."""
    current = summary["columns"][0]["members"] if summary["columns"] else 0
    need = min(cap, current + batch)
    for col in summary["columns"]:
        p = col["toppled"] / max(col["members"], 1)
        n = current + batch
        while n < cap:
            lo, hi = wilson_interval(round(p * n), n)
            if (hi - lo) / 2 <= precision:
                break
            n += batch
        need = max(need, min(cap, n))
        ci = col.get("mean_azimuth_ci95_deg")
        if (arc_deg is not None and ci is not None and col["toppled"] >= CONCENTRATED["falls"]
                and (col["resultant_length"] or 0) >= CONCENTRATED["resultant_length"]):
            width = (ci[1] - ci[0]) % 360.0     # shrinks as 1 / sqrt(falls)
            if width > arc_deg:
                falls = col["toppled"] * (width / arc_deg) ** 2
                n = current + batch * math.ceil(
                    max(falls / max(p, 1e-9) - current, 1) / batch)
                need = max(need, min(cap, n))
    return need


def write_summaries(campaign_dir, summaries):
    """Each record's ensemble_summary.json (in ``campaign_dir``, or its record's folder when
    there are several) and, for several records, ensemble_summaries.json with all."""
    campaign_dir = Path(campaign_dir)
    for summary in summaries:
        out = campaign_dir if len(summaries) == 1 else campaign_dir / summary["record"]
        write_json(out / "ensemble_summary.json", summary)
    if len(summaries) > 1:
        write_json(campaign_dir / "ensemble_summaries.json", summaries)


def written_summaries(campaign_dir, n_records):
    """The summaries :func:`write_summaries` wrote for a campaign of ``n_records`` records."""
    campaign_dir = Path(campaign_dir)
    path = campaign_dir / ("ensemble_summaries.json" if n_records > 1 else
                           "ensemble_summary.json")
    if not path.exists():
        return []
    data = json.loads(path.read_text())
    return data if n_records > 1 else [data]


def reachable_runs(records, max_members, campaign_dir):
    """The most runs an ensemble sized by its error may make: the nominal run and
    ``max_members`` members on each record, less the runs already finished in
    ``campaign_dir`` (a resumed campaign)."""
    done = count_finished(campaign_dir)
    return max(len(records) * (max_members + 1) - done, 0)


def run_sized(run, records, campaign_dir, options, gate=None):
    """Add members in Latin-hypercube batches of ``options["members"]`` to the records not
    yet converged (:func:`converged`) until all are or ``max_members`` is reached; each
    record's ensemble_summary.json gets ``sizing`` (target, members, why it stopped).
    ``run(options)`` runs the campaign once (its outputs write the summaries, read back
    here with :func:`written_summaries`) and returns its outputs dict.  Before the first
    batch it asks the long-run gate (``gate``) for the runs it may reach: ``max_members``
    and the nominal run on every record (:func:`reachable_runs`)."""
    batch, cap = options["members"], options["max_members"]
    precision, arc = options["precision"], options["arc_deg"]
    if gate is not None:
        runs = reachable_runs(records, cap, campaign_dir)
        gate(f"campaign ensemble (up to {cap} members on each of {len(records)} "
             "record(s))", runs, RUN_CORE_S, "a smaller --max-members or a larger --precision")
    counts = {rec: min(batch, cap) for rec in records}
    while True:
        result = run({**options, "batch": batch, "record_members": dict(counts)})
        summaries = written_summaries(campaign_dir, len(counts))
        pending = {}
        for summary in summaries:
            rec = summary["record_input"]
            ok, why = converged(summary, precision, arc)
            if not ok and counts[rec] < cap:
                pending[rec] = why
            summary["sizing"] = {"precision": precision, "arc_deg": arc, "batch": batch,
                                 "max_members": cap, "members": counts[rec],
                                 "stopped_by": "precision" if ok else "member cap",
                                 "open": None if ok else why}
        if not pending:
            break
        for rec, why in pending.items():
            summary = next(x for x in summaries if x["record_input"] == rec)
            more = members_needed(summary, precision, batch, cap, arc) - counts[rec]
            log.info(f"{rec}: {why} after {counts[rec]} members: adding {more}")
            counts[rec] += more
    write_summaries(campaign_dir, summaries)
    return {**result, "summaries": summaries}
