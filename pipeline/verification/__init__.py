"""Verification stage: the YADE model against rocking theory, as single checks
(:mod:`.checks`) and as the ``verification`` campaign (specs, worker, summary)."""
import numpy as np

from pipeline.files import write_json
from pipeline.verification.checks import (HOUSNER_DAMPING, MARBLE_BLOCK, PULSE_BLOCK,
                                          SLIDING_MU, verify_housner, verify_sine_pulse,
                                          verify_sliding)

CAMPAIGN_THETA0 = (0.2, 0.4, 0.6, 0.8, 0.95)
CAMPAIGN_DAMPING = (0.36, 1.0)
CAMPAIGN_PULSE_AMPLITUDES = (2.5, 4.0, 5.5, 6.5, 7.0, 7.25, 8.0, 10.0)
CAMPAIGN_PULSE_OMEGAS = (3.0, 5.0, 8.0)


def campaign_specs():
    """Run specs of the verification campaign (theta0/alpha, pulse grid, mu_s)."""
    specs = [{"kind": "housner", "theta0_ratio": r, "damping": z}
             for z in CAMPAIGN_DAMPING for r in CAMPAIGN_THETA0]
    specs += [{"kind": "sine-pulse", "amplitude_ratio": a, "omega_ratio": w}
              for w in CAMPAIGN_PULSE_OMEGAS for a in CAMPAIGN_PULSE_AMPLITUDES]
    specs += [{"kind": "sliding", "mu_s": mu} for mu in SLIDING_MU]
    for spec in specs:
        spec["record"] = spec["kind"]
    return specs


def run_spec(spec, run_dir):
    """Campaign worker: one verification run, result in run_dir/summary.json."""
    if spec["kind"] == "housner":
        result = verify_housner(theta0_ratio=spec["theta0_ratio"], damping=spec["damping"],
                                run_dir=run_dir / "yade")
    elif spec["kind"] == "sine-pulse":
        result = verify_sine_pulse(amplitude_ratio=spec["amplitude_ratio"],
                                   omega_ratio=spec["omega_ratio"], run_dir=run_dir / "yade")
    else:
        result = verify_sliding(mu_values=(spec["mu_s"],), run_dir=run_dir)
    write_json(run_dir / "summary.json", result)


def summarise_campaign(results):
    """Key numbers of the verification campaign."""
    out = {"housner": {}, "sine_pulse": {}, "sliding": {}, "lines": []}
    for z in CAMPAIGN_DAMPING:
        rows = [r for s, r in results if s["kind"] == "housner" and s["damping"] == z]
        if rows:
            out["housner"][str(z)] = {
                "max_rel_error_impact_times": max(r["max_rel_error_impact_times"] for r in rows),
                "max_rel_error_peaks": max(r["max_rel_error_peaks"] for r in rows),
                "effective_restitution": float(np.mean([r["effective_restitution"] for r in rows])),
                "housner_restitution": rows[0]["housner_restitution"],
                "all_passed": all(r["passed"] for r in rows)}
            h = out["housner"][str(z)]
            out["lines"].append(
                f"Housner free rocking, damping {z}: impact times within "
                f"{100 * h['max_rel_error_impact_times']:.1f} %, peaks within "
                f"{100 * h['max_rel_error_peaks']:.1f} % over 5 impacts "
                f"(restitution {h['effective_restitution']:.4f} vs {h['housner_restitution']:.4f})")
    pulses = [r for s, r in results if s["kind"] == "sine-pulse"]
    if pulses:
        agree = sum(r["passed"] for r in pulses)
        modes = sorted({r["yade"]["mode"] for r in pulses})
        out["sine_pulse"] = {"runs": len(pulses), "agree": agree, "modes_seen": modes}
        out["lines"].append(f"One-sine pulse: YADE and the integration agree on mode and "
                            f"direction in {agree}/{len(pulses)} runs; modes seen: {', '.join(modes)}")
    slides = sorted([r["runs"][0] | {"mu_min": r["augusti_sinopoli_mu_min"]}
                     for s, r in results if s["kind"] == "sliding"], key=lambda r: -r["mu_s"])
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
    return out
__all__ = ["HOUSNER_DAMPING", "MARBLE_BLOCK", "PULSE_BLOCK", "SLIDING_MU", "verify_housner",
           "verify_sine_pulse", "verify_sliding", "campaign_specs", "run_spec",
           "summarise_campaign"]
