"""The checks of the age options of ``survival`` and ``constrain`` (declared in
:mod:`pipeline.assessment.options`): one kind of age, its companions, an interval the
right way up."""
from pipeline.files import InputError

AGE_VALUES = {"--age-ka": lambda o: ("--age-ka", o.age_ka),
               "--age-min-ka": lambda o: ("--age-min-ka", o.age_min_ka),
               "--age-range-ka": lambda o: ("--age-range-ka", o.age_range_ka),
               "--age-samples": lambda o: ("--age-samples", o.age_samples)}


def age_kinds(options):
    """The age flags given (one kind of age is asked for)."""
    return [flag for flag, value in (("--age-ka", options.age_ka),
                                     ("--age-min-ka", options.age_min_ka),
                                     ("--age-range-ka", options.age_range_ka),
                                     ("--age-samples", options.age_samples))
            if value is not None and value != ()]


def check_age_kinds(options, given):
    """One kind of age; --age-sd-ka with --age-ka only, --age-column with --age-samples;
    an interval the right way up."""
    if len(given) > 1:
        raise InputError(f"give one kind of age: {' or '.join(given)}, not both")
    sd = options.age_sd_ka
    if "--age-ka" not in given and sd not in (0.0, (0.0,)):
        raise InputError("--age-sd-ka applies with --age-ka")
    if given == ["--age-samples"] and options.age_column is None:
        raise InputError("--age-samples needs --age-column (the column holding the ages)")
    if given != ["--age-samples"] and options.age_column is not None:
        raise InputError("--age-column applies with --age-samples")
    ranges = options.age_range_ka
    for lo, hi in ([ranges] if ranges and not isinstance(ranges[0], tuple) else ranges or ()):
        if hi < lo:
            raise InputError(f"--age-range-ka {lo:g} {hi:g}: the interval is upside down "
                             "(the lower end first)")
        if hi == 0:
            raise InputError("--age-range-ka 0 0: an age of 0 (the upper end above 0)")
