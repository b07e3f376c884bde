"""``contact``: the rocking coefficient of restitution that reproduces a recorded
free-rocking decay of a block, a column or a scanned rock, written to a contact file
(JSON); with ``--damping-map`` also the contact damping that gives it in YADE, and the
damping interval of its standard error (the workflow:
:mod:`pipeline.verification.contact_workflow`).

    python -m pipeline contact --free-rocking decay.csv --block 0.40,0.08 --out contact.json
    python -m pipeline contact --frequency-hz 2.5 --amplitude-ratio 0.62,0.60 --block 0.40,0.08
    python -m pipeline contact --free-rocking decay.csv --column-file rock.json --azimuth 90 \
        --damping-map

The decay file is a CSV with a header: ``time_s`` and ``tilt_rad`` or ``tilt_deg`` (the
block's tilt in its rocking plane, signed).
"""
from pipeline.cli._fields import add_arguments, from_args
from pipeline.verification.contact_workflow import ContactOptions, fit_contact, fitted_what

NAME = "contact"
ORDER = 60
HELP = "contact parameters from a free-rocking test of a block (restitution, its uncertainty)"


def setup(p):
    add_arguments(p, ContactOptions)


def run(args):
    options = from_args(ContactOptions, args)
    result = fit_contact(options)
    if "at_rest_from_s" in result["source"]:
        print(f"note: the block is at rest from {result['source']['at_rest_from_s']:.3f} s: "
              f"the {result['source']['swings_at_rest']} swings from there on (the "
              "record's noise about zero, which does not decay) are left out of the fit")
    if options.damping_map:
        _print_damping(result)
    spread = "" if result["restitution_sd"] is None else \
        f" +- {result['restitution_se']:.3f} (standard error; single impacts scatter " \
        f"{result['restitution_sd']:.3f})"
    print(f"restitution {result['restitution']:.3f}{spread} from {result['impacts']} "
          f"impact(s); a rigid block of this {'shape' if 'block' in result else 'critical angle'}"
          f": {result['housner_restitution']:.3f} (Housner)")
    print(f"wrote {options.out}")
    return 0


def _print_damping(result):
    """The damping map's lines: the damping found and its interval."""
    found, interval = result["damping_map"], result["damping_interval"]
    print(f"damping {result['damping']:.3f} per contact at kn {result['kn']:g} N/m gives "
          f"{fitted_what(result)} a restitution of {found['measured_restitution']:.4f} in "
          f"YADE ({found['yade_runs']} free-rocking run(s) made; measured ones are kept in "
          "results/contact/restitution_map.json)")
    if interval is None:
        print("damping interval: none (one impact: no standard error of the restitution)")
    else:
        beyond = f" ({', '.join(interval['clipped'])} end at the reachable range's end)" \
            if interval["clipped"] else ""
        print(f"damping interval {interval['low']:.3f}-{interval['high']:.3f}: the "
              f"restitution {interval['restitution_high']:.4f}-"
              f"{interval['restitution_low']:.4f} (+- its standard error){beyond}")
