"""The ``contact`` command's workflow: the rocking coefficient of restitution that
reproduces a recorded free-rocking decay of a block, a column or a scanned rock, written
to a contact file (JSON); with ``damping_map`` also the contact damping that gives it in
YADE (:mod:`pipeline.verification.contact_map`) and the damping interval of its standard
error.  The options are :class:`ContactOptions` fields (the command line builds their
flags), every one checked when the options are made, before any work.

The decay file is a CSV with a header: ``time_s`` and ``tilt_rad`` or ``tilt_deg`` (the
block's tilt in its rocking plane, signed).
"""
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import paper
from pipeline.files import InputError, write_json
from pipeline.scenario.parameters import check_fields, param
from pipeline.userfiles import DATA_FILE_BYTES, read_user_text
from pipeline.scenario import Block, ColumnGeometry, Contact, Numerics
from pipeline.rocking.decay import fit_free_rocking
from pipeline.verification.contact_map import _scene, equivalent_block, weakest_azimuth
from pipeline.verification import contact_map

MAX_ROWS = 1_000_000
TILT_COLUMNS = {"tilt_rad": 1.0, "tilt_deg": math.pi / 180.0}


@dataclass(frozen=True)
class ContactOptions:
    """What ``contact`` is asked (see ``python -m pipeline contact --help``)."""
    free_rocking: Path = param(None, "", "recorded decay: columns time_s and tilt_rad or "
                               "tilt_deg", flag="--free-rocking", metavar="CSV",
                               optional="--frequency-hz instead")
    frequency_hz: float = param(None, "Hz", "instead of a record: the rocking frequency (full "
                                "cycles per s) at the amplitudes whose ratios "
                                "--amplitude-ratio gives", 0.01, 100.0, "--frequency-hz",
                                metavar="HZ", optional="--free-rocking instead")
    amplitude_ratio: str = param(None, "", "ratios of successive amplitudes (the next over "
                                 "the previous), in (0, 1)", flag="--amplitude-ratio",
                                 metavar="R,R", optional=True)
    block: str = param(None, "", "the block's height and width in its rocking plane (m)",
                       flag="--block", metavar="HEIGHT,WIDTH", optional="--column-file instead")
    column_file: str = param(None, "", "instead of --block: the specimen tested, a column "
                             "description (as the monolith of its outline) or a mesh "
                             "specimen (a scanned rock)", flag="--column-file",
                             metavar="NAME_OR_FILE", optional="--block instead")
    azimuth: float = param(None, "", "with --column-file: the direction it was tilted toward "
                           "(deg clockwise from North)", flag="--azimuth", metavar="DEG",
                           optional="its weak side, where its critical angle is smallest")
    damping_map: bool = param(False, "", "also find the contact damping ratio that gives "
                              "this restitution in the YADE model of the block or specimen "
                              "(free-rocking runs, bisection: minutes; measured restitutions "
                              "are cached), and the damping interval of the restitution +- "
                              "its standard error, so that `run --contact-file` and the "
                              "campaigns take the file", flag="--damping-map")
    depth: float = param(None, "m", "the block's depth across the rocking plane",
                         flag="--depth", metavar="M", optional="its width")
    density: float = param(None, "kg/m^3", "the block's density", flag="--density",
                           metavar="KG_M3", optional=f"{paper.MARBLE_DENSITY_KG_M3:g}, the "
                           "paper's marble")
    kn: float = param(None, "N/m", "contact stiffness per point of the map", flag="--kn",
                      metavar="N_M", optional=f"the paper's block {paper.MARBLE_BLOCK_KN_N_M:g}; "
                      f"with --column-file the model's {paper.COLUMN_KN_N_M:g}")
    out: Path = param(Path("contact.json"), "", "contact file written (JSON)", flag="--out")

    def __post_init__(self):
        check_fields(self)
        if (self.block is None) == (self.column_file is None):
            raise InputError("give either --block HEIGHT,WIDTH or --column-file")
        if self.column_file is not None:
            given = [f"--{k}" for k in ("depth", "density") if getattr(self, k) is not None]
            if given:
                raise InputError(f"{', '.join(given)} go(es) with --block: --column-file "
                                 "describes the specimen")
            if self.azimuth is not None and not (math.isfinite(self.azimuth) and
                                                 0.0 <= self.azimuth < 360.0):
                raise InputError(f"--azimuth must be in [0, 360) deg, got {self.azimuth:g}")
        else:
            self._check_block()
        self._check_map()
        self._check_decay()

    def _check_block(self):
        if self.azimuth is not None:
            raise InputError("--azimuth goes with --column-file (a block rocks in its "
                             "width's plane)")
        height, width = self.block_size()
        if not (0.01 <= height <= 30.0 and 0.005 <= width <= 30.0):
            raise InputError(f"--block: height in [0.01, 30] m and width in [0.005, 30] m "
                             f"needed, got {self.block!r}")

    def _check_map(self):
        """The map's block and contact in their ranges; its options only with it."""
        if self.damping_map:
            if self.block is not None:
                height, width = self.block_size()
                Block(height=height, width=width, depth=self.block_depth(width),
                      density=self.block_density())   # ranges
            Contact(kn=self.map_kn())
        else:
            alone = [f"--{k}" for k in ("depth", "density", "kn") if getattr(self, k) is not None]
            if alone:
                raise InputError(f"{', '.join(alone)} go(es) with --damping-map")

    def _check_decay(self):
        """A decay record or a frequency with its amplitude ratios, in range."""
        if (self.free_rocking is None) == (self.frequency_hz is None):
            raise InputError("give either --free-rocking CSV or --frequency-hz with "
                             "--amplitude-ratio")
        if self.frequency_hz is None:
            if self.amplitude_ratio is not None:
                raise InputError("--amplitude-ratio goes with --frequency-hz, not "
                                 "--free-rocking")
            return
        if self.amplitude_ratio is None:
            raise InputError("--frequency-hz needs --amplitude-ratio")
        self.ratios()

    def block_size(self):
        """(height m, width m) of ``--block``."""
        return tuple(_numbers(self.block, "--block HEIGHT,WIDTH", 2))

    def block_depth(self, width):
        return width if self.depth is None else self.depth

    def block_density(self):
        return paper.MARBLE_DENSITY_KG_M3 if self.density is None else self.density

    def map_kn(self):
        """Contact stiffness (N/m per point) of the damping map."""
        return self.kn if self.kn is not None else \
            paper.MARBLE_BLOCK_KN_N_M if self.block is not None else paper.COLUMN_KN_N_M

    def ratios(self):
        """The amplitude ratios of ``--amplitude-ratio``, each in (0, 1)."""
        ratios = _numbers(self.amplitude_ratio, "--amplitude-ratio")
        if not all(0.0 < r < 1.0 for r in ratios):
            raise InputError(f"--amplitude-ratio: ratios in (0, 1) needed (a free-rocking "
                             f"amplitude decays), got {self.amplitude_ratio!r}")
        return ratios


def _numbers(text, what, count=None):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{what}: numbers separated by commas needed, got {text!r}") from None
    if count is not None and len(values) != count:
        raise InputError(f"{what}: {count} numbers needed, got {text!r}")
    if not values or not all(math.isfinite(v) for v in values):
        raise InputError(f"{what}: finite numbers needed, got {text!r}")
    return values


def load_free_rocking(path):
    """(time s, tilt rad) arrays of a decay CSV; one-line InputError otherwise."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"--free-rocking {path}: file not found")
    try:
        frame = pd.read_csv(io.StringIO(read_user_text(path, "--free-rocking",
                                                       DATA_FILE_BYTES)), nrows=MAX_ROWS + 1)
    except (OSError, ValueError, UnicodeDecodeError, pd.errors.ParserError) as exc:
        raise InputError(f"{path.name}: not a readable CSV ({str(exc).splitlines()[0][:100]})"
                         ) from None
    tilt = [c for c in TILT_COLUMNS if c in frame.columns]
    if "time_s" not in frame.columns or len(tilt) != 1:
        raise InputError(f"{path.name}: columns time_s and one of tilt_rad, tilt_deg needed "
                         f"(found {', '.join(map(str, frame.columns))})")
    if len(frame) > MAX_ROWS:
        raise InputError(f"{path.name}: more than {MAX_ROWS:,} rows")
    values = frame[["time_s", tilt[0]]].apply(pd.to_numeric, errors="coerce").to_numpy(float)
    if not np.all(np.isfinite(values)):
        raise InputError(f"{path.name}: time_s and {tilt[0]} must hold numbers in every row")
    return values[:, 0], values[:, 1] * TILT_COLUMNS[tilt[0]]


def fit_contact(options):
    """The contact file's content for ``options`` (:class:`ContactOptions`), written to
    ``options.out``: the restitution fitted to the decay, the block or specimen, and with
    ``damping_map`` the damping that gives it in YADE and its interval.  The bisection's
    lines are printed as it goes; what the result says is the caller's to print."""
    if options.column_file is not None:
        geometry, azimuth, alpha, (height, width) = _specimen(options)
    else:
        height, width = options.block_size()
    if options.frequency_hz is not None:
        ratios = options.ratios()
        fit = fit_free_rocking(height, width, frequency_hz=options.frequency_hz,
                               amplitude_ratios=ratios)
        source = {"frequency_hz": options.frequency_hz, "amplitude_ratios": ratios}
    else:
        t, theta = load_free_rocking(options.free_rocking)
        fit = fit_free_rocking(height, width, t=t, theta=theta)
        source = {"free_rocking": str(options.free_rocking)}
        if fit["rest"] is not None:           # the noise at rest left out: said in the file
            source["at_rest_from_s"], source["swings_at_rest"] = \
                fit["rest"]["from_s"], fit["rest"]["swings"]
    if not 0.0 < fit["restitution"] <= 1.0:
        raise InputError(f"the decay gives a restitution of {fit['restitution']:.3f}, outside "
                         "(0, 1]: amplitudes that grow are not a free-rocking decay")
    result = {"restitution": fit["restitution"], "restitution_sd": fit["restitution_sd"],
              "restitution_se": fit["restitution_se"], "impacts": fit["impacts"],
              "restitution_per_impact": [float(e) for e in fit["restitution_per_impact"]],
              "housner_restitution": fit["housner_restitution"], "source": source}
    if options.block is not None:
        result["block"] = {"height_m": height, "width_m": width}
        geometry = azimuth = None
    else:
        result["specimen"] = {"description": str(options.column_file), "name": geometry.name,
                              "azimuth_deg": azimuth, "critical_angle_deg": math.degrees(alpha),
                              "equivalent_block": {"height_m": height, "width_m": width}}
    if options.damping_map:
        result.update(_damping_map(options, fit, height, width, geometry, azimuth))
    write_json(options.out, result)
    return result


def fitted_what(result):
    """What a contact file's result was fitted for, in words."""
    if "block" in result:
        return "this block"
    return f"{result['specimen']['name']} toward {result['specimen']['azimuth_deg']:g} deg"


def _specimen(options):
    """(geometry, azimuth deg, critical angle rad, (height m, width m) of the equivalent
    block: the same critical angle and distance from the support line to the centre of
    mass) of ``--column-file``."""
    geometry = ColumnGeometry.load(options.column_file)
    _, column = _scene(geometry, Contact(), Numerics())
    azimuth = weakest_azimuth(column) if options.azimuth is None else options.azimuth
    line, _, block = equivalent_block(column, azimuth, geometry.name)
    return geometry, azimuth, line["critical_angle_rad"], block


def _damping_map(options, fit, height, width, geometry, azimuth):
    """The contact file's kn, damping, damping_interval and damping_map: the damping that
    gives the fitted restitution in YADE (free-rocking runs, bisection)."""
    kn = options.map_kn()
    if options.block is not None:
        depth, density = options.block_depth(width), options.block_density()
        measured_at, runs = contact_map.block_measure(height, width, depth, kn, density)
        extra = {"depth_m": depth, "density_kg_m3": density}
        what = "this block"
    else:
        measured_at, measures = contact_map.specimen_measure(geometry, kn, azimuth)
        runs = lambda: measures() * len(contact_map.SPECIMEN_RELEASES)   # noqa: E731
        extra = {"azimuth_deg": azimuth,
                 "release_ratios": list(contact_map.SPECIMEN_RELEASES)}
        what = f"{geometry.name} toward {azimuth:g} deg"
    reach = f"{what} (kn {kn:g} N/m)"
    damping, measured = contact_map.bisect_damping(fit["restitution"], measured_at, reach)
    interval = contact_map.damping_interval(fit["restitution"], fit["restitution_se"],
                                            measured_at, reach)
    return {"kn": kn, "damping": damping, "damping_interval": interval, "damping_map": {
        "measured_restitution": measured, "tolerance": contact_map.RESTITUTION_TOLERANCE,
        "yade_runs": runs(), **extra}}
