"""Verification stage: the YADE model against rocking theory, as single checks
(:mod:`.checks`) and as the ``verification`` campaign (specs, worker, summary)."""
from pathlib import Path

import numpy as np

from pipeline.verification.check import KINDS, Check, CheckResult
from pipeline.verification.checks import (HOUSNER_DAMPING, MARBLE_BLOCK, PULSE_BLOCK,
                                          SLIDING_BELOW, SLIDING_MU, check_sliding_mus,
                                          verify_housner, verify_sine_pulse, verify_sliding)
from pipeline.verification.frame import (FRAME_COLUMNS, FRAME_GAMMAS, FRAME_PERIOD_S,
                                         summarise_frames)
from pipeline.verification.one_cosine import (YADE_PERIODS_S, summarise_one_cosine,
                                              verify_one_cosine)

CAMPAIGN_THETA0 = (0.2, 0.4, 0.6, 0.8, 0.95)
CAMPAIGN_DAMPING = (0.36, 1.0)
CAMPAIGN_PULSE_AMPLITUDES = (2.5, 4.0, 5.5, 6.5, 7.0, 7.25, 8.0, 10.0)
CAMPAIGN_PULSE_OMEGAS = (3.0, 5.0, 8.0)


def campaign_checks(code_version):
    """The verification campaign's :class:`Check` s (theta0/alpha x damping, the pulse
    grid, mu_s, the one-cosine pulse's periods, the rocking frames), their run ids from
    ``code_version``."""
    settings = [("housner", {"theta0_ratio": r, "damping": z})
                for z in CAMPAIGN_DAMPING for r in CAMPAIGN_THETA0]
    settings += [("sine-pulse", {"amplitude_ratio": a, "omega_ratio": w})
                 for w in CAMPAIGN_PULSE_OMEGAS for a in CAMPAIGN_PULSE_AMPLITUDES]
    settings += [("sliding", {"mu_s": mu}) for mu in SLIDING_MU]
    settings += [("one-cosine", {"period_s": t}) for t in YADE_PERIODS_S]
    settings += [("frame", {"n_columns": n, "gamma": g, "period_s": FRAME_PERIOD_S})
                 for n in FRAME_COLUMNS for g in FRAME_GAMMAS]
    return [Check.create(kind, code_version, **setting) for kind, setting in settings]


def run_check(spec, run_dir):
    """Campaign worker: the check ``spec`` describes (a :class:`Check` or its flat dict),
    its :class:`CheckResult` in run_dir/summary.json."""
    check = spec if isinstance(spec, Check) else Check.from_dict(spec)
    check.run(run_dir).save(Path(run_dir) / "summary.json")


def summarise_campaign(results):
    """Key numbers of the verification campaign from its (:class:`Check`,
    :class:`CheckResult`) pairs."""
    out = {"housner": {}, "sine_pulse": {}, "sliding": {}, "lines": []}
    for z in CAMPAIGN_DAMPING:
        rows = [r for s, r in results if s.kind == "housner" and s["damping"] == z]
        if rows:
            out["housner"][str(z)] = {
                "max_rel_error_impact_times": max(r["max_rel_error_impact_times"] for r in rows),
                "max_rel_error_peaks": max(r["max_rel_error_peaks"] for r in rows),
                "effective_restitution": float(np.mean([r["effective_restitution"] for r in rows])),
                "housner_restitution": rows[0]["housner_restitution"],
                "all_passed": all(r.passed for r in rows)}
            h = out["housner"][str(z)]
            out["lines"].append(
                f"Housner free rocking, damping {z}: impact times within "
                f"{100 * h['max_rel_error_impact_times']:.1f} %, peaks within "
                f"{100 * h['max_rel_error_peaks']:.1f} % over 5 impacts "
                f"(restitution {h['effective_restitution']:.4f} vs {h['housner_restitution']:.4f})")
    pulses = [r for s, r in results if s.kind == "sine-pulse"]
    if pulses:
        agree = sum(r.passed for r in pulses)
        modes = sorted({r["yade"]["mode"] for r in pulses})
        out["sine_pulse"] = {"runs": len(pulses), "agree": agree, "modes_seen": modes}
        out["lines"].append(f"One-sine pulse: YADE and the integration agree on mode and "
                            f"direction in {agree}/{len(pulses)} runs; modes seen: {', '.join(modes)}")
    slides = sorted([r["runs"][0] | {"mu_min": r["augusti_sinopoli_mu_min"]}
                     for s, r in results if s.kind == "sliding"], key=lambda r: -r["mu_s"])
    if slides:
        rocking_mu = [r["mu_s"] for r in slides if r["pure_rocking"]]
        sliding_mu = [r["mu_s"] for r in slides if not r["pure_rocking"]]
        out["sliding"] = {"lowest_mu_pure_rocking": min(rocking_mu, default=None),
                          "highest_mu_sliding": max(sliding_mu, default=None),
                          "augusti_sinopoli_mu_min": slides[0]["mu_min"]}
        out["lines"].append(
            f"Rock-sliding: pure rocking down to mu_s = {out['sliding']['lowest_mu_pure_rocking']}, "
            f"sliding from {out['sliding']['highest_mu_sliding']}; Augusti & Sinopoli (eq 8): "
            f"{slides[0]['mu_min']:.3f}")
    frames = [r for s, r in results if s.kind == "frame"]
    if frames:
        out["frame"] = summarise_frames(frames)
        out["lines"] += out["frame"]["lines"]
    cosines = [r for s, r in results if s.kind == "one-cosine"]
    if cosines:
        out["one_cosine"] = summarise_one_cosine(cosines)
        out["lines"] += out["one_cosine"]["lines"]
    return out


__all__ = ["HOUSNER_DAMPING", "MARBLE_BLOCK", "PULSE_BLOCK", "SLIDING_BELOW", "SLIDING_MU",
           "check_sliding_mus", "verify_housner", "verify_sine_pulse", "verify_sliding",
           "verify_one_cosine", "KINDS",
           "Check", "CheckResult", "campaign_checks", "run_check", "summarise_campaign"]
