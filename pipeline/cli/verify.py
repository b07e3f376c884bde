"""``verify``: the YADE block model against analytic rocking theory.

    python -m pipeline verify housner --height 0.4 --width 0.08 --theta0-ratio 0.5
    python -m pipeline verify sine-pulse --height 3.113 --width 0.795 --amplitude-ratio 6.5
    python -m pipeline verify sliding
    python -m pipeline verify one-cosine --period 1.0 --runs 10
    python -m pipeline verify frame --columns 2 --gamma 1.0 --runs 10
"""
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.cli._fields import add_arguments, from_args
from pipeline.cli._verify_options import OPTIONS
from pipeline.files import check_out_file
from pipeline.verification import (CheckResult, check_sliding_mus, verify_housner,
                                   verify_one_cosine, verify_sine_pulse, verify_sliding)
from pipeline.verification.frame import frame_colonnade, verify_frame
from pipeline.verification.one_cosine import check_one_cosine

NAME = "verify"
ORDER = 30
HELP = "verify the YADE model against rocking theory"
TESTS = {"housner": "free rocking of a block (Housner 1963)",
         "sine-pulse": "one-sine pulse overturning (Zhang & Makris 2000)",
         "sliding": "rock-sliding test vs friction (paper Fig. 6)",
         "one-cosine": "smallest overturning amplitude under a one-cosine pulse, 2D block and "
                       "YADE (Makris & Roussos 2000)",
         "frame": "smallest overturning amplitude of columns under a beam (one-cosine pulse), "
                  "rigid frame and YADE (Makris & Vassiliou 2013)"}


def setup(p):
    sub = p.add_subparsers(dest="test", metavar="TEST", required=True)
    for test, text in TESTS.items():
        q = sub.add_parser(test, help=text)
        add_arguments(q, OPTIONS[test])
        q.add_argument("--out", type=Path, default=None, metavar="FILE",
                       help="JSON output (default results/verification/<test>.json)")


def run(args):
    o = from_args(OPTIONS[args.test], args)          # every option checked: before any run
    contact = {k: v for k, v in (("kn", o.kn), ("damping", o.damping)) if v is not None}
    out = args.out or RESULTS_DIR / "verification" / f"{args.test}.json"
    check_out_file(out)
    if args.test == "housner":
        result = verify_housner(o.height, o.width, o.depth, o.theta0_ratio, o.impacts,
                                **contact)
        print(f"impact times within {100 * result['max_rel_error_impact_times']:.2f} %, peaks "
              f"within {100 * result['max_rel_error_peaks']:.2f} % of Housner's equation "
              f"(closed form {100 * result['max_rel_error_peaks_closed_form']:.2f} %); "
              f"restitution {result['effective_restitution']:.3f} vs Housner "
              f"{result['housner_restitution']:.3f}")
    elif args.test == "sine-pulse":
        result = verify_sine_pulse(o.height, o.width, o.depth, o.amplitude_ratio,
                                   o.omega_ratio, **contact)
        print(f"YADE: {result['yade']['mode']} (direction {result['yade']['direction']:+d}, "
              f"{result['yade']['impacts_before_overturning']} impacts); integration: "
              f"{result['integration']['mode']} (direction {result['integration']['direction']:+d})")
    elif args.test == "one-cosine":
        result = _one_cosine(o, contact)
    elif args.test == "frame":
        result = _frame(o, contact)
    else:
        kwargs = {"mu_values": o.mu_s} if o.mu_s else {}
        if o.mu_s:
            check_sliding_mus(o.mu_s)
        result = verify_sliding(theta0_deg=o.theta0_deg, friction=o.friction, **kwargs,
                                **contact)
        for r in result["runs"]:
            print(f"mu_s {r['mu_s']:.3f}: {'pure rocking' if r['pure_rocking'] else 'sliding':>12}"
                  f", slip at impacts {1000 * r['slip_at_impacts_m']:.1f} mm")
        print(f"Augusti & Sinopoli: pure rocking needs mu_s > {result['augusti_sinopoli_mu_min']:.3f}")
    CheckResult(result).save(out)
    print(f"{'PASSED' if result['passed'] else 'FAILED'}; wrote {out}")
    return 0 if result["passed"] else 1


def _one_cosine(o, contact):
    check_one_cosine(o.period, o.height, o.width, o.depth, o.runs, **contact)
    result = verify_one_cosine(o.period, o.height, o.width, o.depth, o.runs, **contact)
    y = result["yade"]
    print(f"2D block overturns from {result['integration']['threshold_g']:.4f} g; YADE stands "
          f"at {y['stands_g']:.4f} g, overturns at {y['overturns_g']:.4f} g ({len(y['runs'])} "
          f"runs); eq. 43: {result['eq43_g']:.4f} g")
    return result


def _frame(o, contact):
    frame_colonnade(o.columns, o.gamma)             # the columns fit under the beam
    result = verify_frame(o.columns, o.gamma, o.period, o.runs, **contact)
    y = result["yade"]
    print(f"rigid frame overturns from {result['integration']['threshold_g']:.4f} g (single "
          f"column {result['single_column_threshold_g']:.4f} g); YADE stands at "
          f"{y['stands_g']:.4f} g, overturns at {y['overturns_g']:.4f} g ({len(y['runs'])} runs)")
    return result
