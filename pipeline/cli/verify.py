"""``verify``: the YADE block model against analytic rocking theory.

    python -m pipeline verify housner --height 0.4 --width 0.08 --theta0-ratio 0.5
    python -m pipeline verify sine-pulse --height 3.113 --width 0.795 --amplitude-ratio 6.5
    python -m pipeline verify sliding
    python -m pipeline verify one-cosine --period 1.0 --runs 10
    python -m pipeline verify frame --columns 2 --gamma 1.0 --runs 10
"""
from pathlib import Path

from pipeline import RESULTS_DIR
from pipeline.files import check_out_file
from pipeline.scenario.parameters import MU_K_OVER_MU_S
from pipeline.verification import (MARBLE_BLOCK, PULSE_BLOCK, SLIDING_BELOW, SLIDING_MU,
                                   CheckResult, check_sliding_mus, verify_housner,
                                   verify_one_cosine, verify_sine_pulse, verify_sliding)
from pipeline.verification.frame import frame_colonnade, verify_frame
from pipeline.verification.one_cosine import (MR_BLOCK, YADE_RUNS, check_block_sizes,
                                              check_one_cosine, check_period, check_runs)

NAME = "verify"
ORDER = 30
HELP = "verify the YADE model against rocking theory"


def setup(p):
    sub = p.add_subparsers(dest="test", metavar="TEST", required=True)
    h = sub.add_parser("housner", help="free rocking of a block (Housner 1963)")
    h.add_argument("--height", type=float, default=MARBLE_BLOCK["height"], help="m (0.40)")
    h.add_argument("--width", type=float, default=MARBLE_BLOCK["width"], help="m (0.08)")
    h.add_argument("--depth", type=float, default=MARBLE_BLOCK["depth"], help="m (0.045)")
    h.add_argument("--theta0-ratio", type=float, default=0.5, help="theta0 / alpha (0.5)")
    h.add_argument("--impacts", type=int, default=5, help="impacts compared (5)")
    s = sub.add_parser("sine-pulse", help="one-sine pulse overturning (Zhang & Makris 2000)")
    s.add_argument("--height", type=float, default=PULSE_BLOCK["height"], help="m (3.113)")
    s.add_argument("--width", type=float, default=PULSE_BLOCK["width"], help="m (0.795)")
    s.add_argument("--depth", type=float, default=PULSE_BLOCK["depth"], help="m (0.5)")
    s.add_argument("--amplitude-ratio", type=float, required=True, help="A / (alpha g)")
    s.add_argument("--omega-ratio", type=float, default=5.0, help="omega / p (5)")
    sl = sub.add_parser("sliding", help="rock-sliding test vs friction (paper Fig. 6)")
    sl.add_argument("--mu-s", type=float, nargs="+", default=None,
                    help=f"static friction values, one at least at or below {SLIDING_BELOW:g} x "
                    f"the Augusti & Sinopoli limit (default: {max(SLIDING_MU):g} down to "
                    f"{min(SLIDING_MU):g})")
    sl.add_argument("--theta0-deg", type=float, default=10.0, help="initial tilt (10 deg)")
    sl.add_argument("--friction", choices=["switch", "static"], default="switch",
                    help=f"switch: mu_s sticking, mu_k = {MU_K_OVER_MU_S:.3g} mu_s sliding "
                    "(default); "
                    "static: mu_s only, to see the effect of the kinetic coefficient")
    c = sub.add_parser("one-cosine", help="smallest overturning amplitude under a one-cosine "
                       "pulse, 2D block and YADE (Makris & Roussos 2000)")
    c.add_argument("--height", type=float, default=MR_BLOCK["height"], help="m (3.0)")
    c.add_argument("--width", type=float, default=MR_BLOCK["width"], help="m (1.0)")
    c.add_argument("--depth", type=float, default=MR_BLOCK["depth"], help="m (1.0)")
    c.add_argument("--period", type=float, default=1.0, help="pulse period T_p, s (1.0)")
    c.add_argument("--runs", type=int, default=YADE_RUNS, help=f"YADE runs ({YADE_RUNS})")
    f = sub.add_parser("frame", help="smallest overturning amplitude of columns under a beam "
                       "(one-cosine pulse), rigid frame and YADE (Makris & Vassiliou 2013)")
    f.add_argument("--columns", type=int, default=2, help="columns under the beam (2)")
    f.add_argument("--gamma", type=float, default=1.0,
                   help="beam mass over the columns' mass (1.0)")
    f.add_argument("--period", type=float, default=1.0, help="pulse period T_p, s (1.0)")
    f.add_argument("--runs", type=int, default=YADE_RUNS, help=f"YADE runs ({YADE_RUNS})")
    for q in (h, s, sl, c, f):
        q.add_argument("--kn", type=float, default=None, help="face contact stiffness N/m")
        q.add_argument("--damping", type=float, default=None,
                       help="contact damping ratio (housner: 1.0, critical; others: 0.36)")
        q.add_argument("--out", type=Path, default=None, metavar="FILE",
                       help="JSON output (default results/verification/<test>.json)")


def run(args):
    contact = {k: v for k, v in (("kn", args.kn), ("damping", args.damping)) if v is not None}
    out = args.out or RESULTS_DIR / "verification" / f"{args.test}.json"
    check_out_file(out)
    if args.test in ("housner", "sine-pulse"):
        check_block_sizes(args.height, args.width, args.depth)
    if args.test == "housner":
        result = verify_housner(args.height, args.width, args.depth, args.theta0_ratio,
                                args.impacts, **contact)
        print(f"impact times within {100 * result['max_rel_error_impact_times']:.2f} %, peaks "
              f"within {100 * result['max_rel_error_peaks']:.2f} % of Housner's equation "
              f"(closed form {100 * result['max_rel_error_peaks_closed_form']:.2f} %); "
              f"restitution {result['effective_restitution']:.3f} vs Housner "
              f"{result['housner_restitution']:.3f}")
    elif args.test == "sine-pulse":
        result = verify_sine_pulse(args.height, args.width, args.depth, args.amplitude_ratio,
                                   args.omega_ratio, **contact)
        print(f"YADE: {result['yade']['mode']} (direction {result['yade']['direction']:+d}, "
              f"{result['yade']['impacts_before_overturning']} impacts); integration: "
              f"{result['integration']['mode']} (direction {result['integration']['direction']:+d})")
    elif args.test == "one-cosine":
        result = _one_cosine(args, contact)
    elif args.test == "frame":
        result = _frame(args, contact)
    else:
        kwargs = {"mu_values": tuple(args.mu_s)} if args.mu_s else {}
        if args.mu_s:
            check_sliding_mus(args.mu_s)
        result = verify_sliding(theta0_deg=args.theta0_deg, friction=args.friction, **kwargs,
                                **contact)
        for r in result["runs"]:
            print(f"mu_s {r['mu_s']:.3f}: {'pure rocking' if r['pure_rocking'] else 'sliding':>12}"
                  f", slip at impacts {1000 * r['slip_at_impacts_m']:.1f} mm")
        print(f"Augusti & Sinopoli: pure rocking needs mu_s > {result['augusti_sinopoli_mu_min']:.3f}")
    CheckResult(result).save(out)
    print(f"{'PASSED' if result['passed'] else 'FAILED'}; wrote {out}")
    return 0 if result["passed"] else 1


def _one_cosine(args, contact):
    check_one_cosine(args.period, args.height, args.width, args.depth, args.runs, **contact)
    result = verify_one_cosine(args.period, args.height, args.width, args.depth, args.runs,
                               **contact)
    y = result["yade"]
    print(f"2D block overturns from {result['integration']['threshold_g']:.4f} g; YADE stands "
          f"at {y['stands_g']:.4f} g, overturns at {y['overturns_g']:.4f} g ({len(y['runs'])} "
          f"runs); eq. 43: {result['eq43_g']:.4f} g")
    return result


def _frame(args, contact):
    check_period(args.period)
    check_runs(args.runs)
    frame_colonnade(args.columns, args.gamma)       # columns and gamma checked
    result = verify_frame(args.columns, args.gamma, args.period, args.runs, **contact)
    y = result["yade"]
    print(f"rigid frame overturns from {result['integration']['threshold_g']:.4f} g (single "
          f"column {result['single_column_threshold_g']:.4f} g); YADE stands at "
          f"{y['stands_g']:.4f} g, overturns at {y['overturns_g']:.4f} g ({len(y['runs'])} runs)")
    return result
