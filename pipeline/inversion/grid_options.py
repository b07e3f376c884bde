"""The ``invert`` command's grid options, declared as
:func:`~pipeline.scenario.parameters.param` fields (the command builds their flags): the
preset (``--grid``), the forward table's grid and the candidates and prior; each option
left unset takes the preset's value (:mod:`pipeline.inversion.presets`, their one home),
and what the help says of it comes from there.  Checked on creation, before any work."""
import dataclasses
import math
from dataclasses import dataclass

from pipeline.files import InputError
from pipeline.inversion.candidates import MAX_GR_B, MAX_RADIUS_KM
from pipeline.inversion.grid import (DEPTH_KM, DISTANCE_KM, DURATION_S, FMAX_HZ, MAGNITUDE,
                                     MAX_AZIMUTH_STEP_DEG, MECHANISMS, MEMBERS,
                                     parse_mechanisms)
from pipeline.inversion.presets import PRESETS
from pipeline.scenario.parameters import check_fields, param


def _text(value):
    """A preset's value as the options take it: numbers by :g, lists apart by commas (a
    mechanism by its name)."""
    if isinstance(value, tuple):
        return ",".join(v[0] if isinstance(v, tuple) else _text(v) for v in value)
    return str(value) if isinstance(value, int) else f"{value:g}"


def _preset(part, attribute):
    """What an option left unset means: the preset's value of ``attribute`` of its
    ``part`` (table or candidates), each preset's stated."""
    values = {name: _text(getattr(getattr(p, part), attribute)) for name, p in PRESETS.items()}
    if len(set(values.values())) == 1:
        return f"the --grid preset's ({next(iter(values.values()))} in each)"
    return "the --grid preset's (" + "; ".join(f"{k} {v}" for k, v in values.items()) + ")"


def _commas(declared):
    """A tuple field given as one flag of values apart by commas (``--depths 6,12``)."""
    return dataclasses.field(default=declared.default,
                             metadata={**declared.metadata, "commas": True})


def _table(attribute, *args, **kwargs):
    return param(None, *args, **kwargs, optional=_preset("table", attribute))


def _candidates(attribute, *args, **kwargs):
    return param(None, *args, **kwargs, optional=_preset("candidates", attribute))


def _quick_help():
    quick = PRESETS["quick"]
    table, candidates = quick.table, quick.candidates
    return (f"coarse smoke run (a few minutes), --grid quick: {len(table.slices())} slices, "
            f"rings {_text(table.distances_km)} km every {table.azimuth_step_deg:g} deg, "
            f"{table.members} members, {table.duration_s:g} s motions to {table.fmax_hz:g} "
            f"Hz; candidates within {candidates.radius_km:g} km, strike every "
            f"{candidates.strike_step_deg:g} deg")


@dataclass(frozen=True)
class GridOptions:
    """The forward table's grid and the candidate sources: a preset, and the options that
    override it."""
    quick: bool = param(False, "", _quick_help(), flag="--quick")
    grid: str = param(None, "", "forward-grid and candidates preset (the demo machine ran "
                      "'demo'); the options below override it", flag="--grid",
                      choices=tuple(sorted(PRESETS)),
                      optional="full; --quick: quick; --member-study: study")
    mechanisms: tuple[str, ...] = _commas(_table(
        "mechanisms", "", "comma-separated, of " + ", ".join(
            f"{k} (dip {v[0]:g}, rake {v[1]:g})" for k, v in MECHANISMS.items())
        + " or NAME:DIP:RAKE", flag="--mechanisms", metavar="LIST"))
    depths: tuple[float, ...] = _commas(_table(
        "depths_km", "km", "hypocentre depths", *DEPTH_KM, "--depths", low_open=True,
        metavar="KM,KM"))
    magnitudes: tuple[float, ...] = _commas(_table(
        "magnitudes", "", "moment magnitudes", *MAGNITUDE, "--magnitudes", metavar="MW,MW"))
    distances: tuple[float, ...] = _commas(_table(
        "distances_km", "km", "table rings: epicentral distances", *DISTANCE_KM,
        "--distances", low_open=True, metavar="KM,KM"))
    azimuth_step: float = _table("azimuth_step_deg", "deg", "table node spacing in azimuth "
                                 "from strike (divides 360)", 0.0, MAX_AZIMUTH_STEP_DEG,
                                 "--azimuth-step", low_open=True, metavar="DEG")
    members: int = _table("members", "", "ensemble members per node (besides the nominal run "
                          "of the grids that make one)", *MEMBERS, "--members")
    seed: int = _table("seed", "", "Latin-hypercube seed", 0, 2 ** 63, "--seed",
                       high_open=True)
    fmax: float = _table("fmax_hz", "Hz", "synthetics up to this frequency", *FMAX_HZ,
                         "--fmax", metavar="HZ")
    duration: float = _table("duration_s", "s", "motion duration", *DURATION_S, "--duration",
                             metavar="S")
    radius: float = _candidates("radius_km", "km", "epicentres within this distance of a "
                                "site and within the forward table's last ring of every site",
                                0.0, MAX_RADIUS_KM, "--radius", low_open=True, metavar="KM")
    step: float = _candidates("step_km", "km", "epicentre grid spacing (at most half the "
                              "radius)", 0.0, None, "--step", low_open=True, metavar="KM")
    strike_step: float = _candidates("strike_step_deg", "deg", "strikes sampled every DEG "
                                     "from 0 (divides 360)", 0.0, 360.0, "--strike-step",
                                     low_open=True, metavar="DEG")
    mechanism_prior: str = param(None, "", "prior weights of the mechanisms",
                                 flag="--mechanism-prior", metavar="NAME=W,...",
                                 optional="equal")
    gr_b: float = param(None, "", "Gutenberg-Richter prior on magnitude, 10^(-B M)", 0.0,
                        MAX_GR_B, "--gr-b", metavar="B", optional="uniform")

    def __post_init__(self):
        if self.quick and self.grid not in (None, "quick"):
            raise InputError("--quick is --grid quick: give one of them")
        check_fields(self)
        if self.mechanisms:
            parse_mechanisms(self.mechanisms)
        if self.mechanism_prior is not None:
            mechanism_weights(self.mechanism_prior)

    def grids(self, member_study=False):
        """(preset name, TableGrid, CandidateGrid): the preset's, with the options given;
        InputError where they do not fit together."""
        name = "quick" if self.quick else (
            self.grid or ("study" if member_study else "full"))
        preset = PRESETS[name]
        mechanisms = parse_mechanisms(self.mechanisms) if self.mechanisms else None
        table = preset.table.replace(
            mechanisms=mechanisms, depths_km=self.depths or None,
            magnitudes=self.magnitudes or None, distances_km=self.distances or None,
            azimuth_step_deg=self.azimuth_step, members=self.members, seed=self.seed,
            fmax_hz=self.fmax, duration_s=self.duration)
        given = {k: v for k, v in (("radius_km", self.radius), ("step_km", self.step),
                                   ("strike_step_deg", self.strike_step)) if v is not None}
        candidates = dataclasses.replace(
            preset.candidates, **given,
            mechanisms=None if mechanisms is None else tuple(m[0] for m in mechanisms),
            depths_km=self.depths or None, magnitudes=self.magnitudes or None,
            mechanism_prior=None if self.mechanism_prior is None else
            mechanism_weights(self.mechanism_prior), gr_b=self.gr_b)
        return name, table, candidates


def mechanism_weights(text):
    """{mechanism name: prior weight} of ``NAME=W,...``: weights finite, >= 0, one > 0."""
    out = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"--mechanism-prior {item!r}: expected NAME=WEIGHT") from None
        if not (math.isfinite(out[name.strip()]) and out[name.strip()] >= 0):
            raise InputError(f"--mechanism-prior {item!r}: weights must be >= 0")
    if not any(out.values()):
        raise InputError("--mechanism-prior: at least one weight must be positive")
    return out
