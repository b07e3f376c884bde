"""``--column-file`` on ``run`` and on the campaigns: one definition of the option and its
help text, and what the campaigns do with a column description.

With a description, a campaign runs the described column in the drums' place and a
monolith of its outline in the monolith's (``run_column_spec``, like ``run --column
both``).  The description goes into each run's parameters as a dict, so the content-keyed
run ids tell it apart, and into ``campaign.json`` (``column_file``) and the tables
(``description``).  Without ``--column-file`` nothing of this touches a run's
parameters: run ids and caches stay as they were.

What a campaign varies and the description fixes:

- slenderness: :func:`at_slenderness` scales every block height by one factor so that
  the column's overall height over its base width (the bottom face's diameter or
  smaller side) takes each h/d of the sweep; diameters, offsets and tilts stay;
- ensemble: :func:`perturbed` applies the sampled height and diameter tolerances to
  every block, adds the sampled out-of-plumb tilt (a vector sum with the described
  tilt) to every block that is not joined, and moves every block above the first that
  is not joined by the sampled drum offset (added to the described offset);
- fragility: the 2D block has the described column's overall height and base width.
"""
import math
from dataclasses import replace

from pipeline import paper
from pipeline.files import InputError
from pipeline.scenario.colonnade_file import load_if_colonnade
from pipeline.scenario.colonnade_file import to_dict as colonnade_to_dict
from pipeline.scenario.column_format import example_names
from pipeline.scenario.geometry import ColumnGeometry

STIFFNESS_CHOICES = ("matched", "paper")


def column_file_help(many=False):
    """Help text of ``--column-file`` (without what a command adds)."""
    what = ("comma-separated column descriptions" if many else
            "the column as found, from a description")
    return (f"{what} (JSON, or YAML with PyYAML; docs/columns-and-model.md) or "
            + ("shipped examples" if many else "a shipped example") + " by name ("
            + ", ".join(example_names()) + ")")


COLONNADE_CAMPAIGNS = "run, campaign records, friction, synthetic and ensemble"


def description(column_file, meshes=False, colonnades=False):
    """The validated description dict of a shipped example's name, a file or a dict;
    None for None; a colonnade's dict (:func:`pipeline.scenario.colonnade_file.to_dict`,
    every column written out) when ``colonnades``.  InputError (one line) for an unknown
    name, a missing file or a description that does not validate, for a mesh specimen
    unless ``meshes`` (a campaign that scales or perturbs blocks cannot take one) and for
    a colonnade unless ``colonnades``."""
    if column_file is None:
        return None
    colonnade = (load_if_colonnade(column_file) if isinstance(column_file, (dict, str))
                 else None)
    if colonnade is not None:
        if colonnades:
            return colonnade_to_dict(colonnade)
        raise InputError(f"--column-file {colonnade.name}: a colonnade; this command takes "
                         f"one column (colonnades run with {COLONNADE_CAMPAIGNS})")
    if isinstance(column_file, dict):
        data = ColumnGeometry.from_dict(column_file).to_dict()
    elif not isinstance(column_file, str) or not column_file.strip():
        raise InputError(f"--column-file needs a shipped example's name or a file, got "
                         f"{column_file!r}")
    else:
        data = ColumnGeometry.load(column_file.strip()).to_dict()
    if "mesh" in data and not meshes:
        raise InputError(f"--column-file {data['name']}: a mesh specimen; this command scales "
                         "or perturbs the blocks of a column description (mesh specimens run "
                         "with run, campaign records, friction, synthetic, columns and "
                         "shake-table)")
    return data


def check_stiffness(stiffness):
    """``--stiffness``: matched or paper (None, not given: matched)."""
    if stiffness is not None and stiffness not in STIFFNESS_CHOICES:
        raise InputError(f"--stiffness must be matched or paper, got {stiffness!r}")


def column_kn(data, stiffness="matched"):
    """Contact stiffness per point (N/m) for a description: the campaign ``columns`` rule
    (:func:`matched_kn`, for a colonnade the largest over its columns; also for
    ``stiffness`` None) or the paper's kn."""
    check_stiffness(stiffness)
    if stiffness == "paper":
        return paper.COLUMN_KN_N_M
    colonnade = load_if_colonnade(data)
    if colonnade is not None:
        return max(matched_kn(c.column) for c in colonnade.columns)
    return matched_kn(ColumnGeometry.from_dict(data))


def slenderness_of(data):
    """Overall height over base width of a description."""
    g = ColumnGeometry.from_dict(data)
    return g.height / g.base_width


def _name(data, suffix):
    return f"{data['name'][:80 - len(suffix)]}{suffix}"


def at_slenderness(data, hd):
    """The description with every block height multiplied by hd / (its height / base
    width), so that its overall h/d is ``hd``; validated (InputError when the scaled
    column breaks a limit of the format, e.g. a block above 30 m)."""
    factor = hd / slenderness_of(data)
    blocks = [{**b, "height": round(b["height"] * factor, 9)} for b in data["blocks"]]
    scaled = {**data, "name": _name(data, f" at h/d {hd:g}"), "blocks": blocks}
    try:
        return ColumnGeometry.from_dict(scaled).to_dict()
    except InputError as exc:
        raise InputError(f"--column-file {data['name']} scaled to h/d {hd:g}: {exc}") from None


HORIZONTAL_SIZES = ("bottom_diameter", "top_diameter", "width", "depth")


def perturbed(data, height_factor=1.0, diameter_factor=1.0, tilt_deg=0.0,
              tilt_azimuth_deg=0.0, max_offset_m=0.0, rng=None):
    """An ensemble member of a description: block heights x ``height_factor``, diameters,
    widths and depths x ``diameter_factor``, the tilt vector (tilt_deg toward
    tilt_azimuth_deg) added to every block's that is not joined, and every block above
    the first that is not joined moved by up to ``max_offset_m`` in a random direction
    (``rng``), added to its described offset.  Not validated (the caller does)."""
    tx = tilt_deg * math.sin(math.radians(tilt_azimuth_deg))
    ty = tilt_deg * math.cos(math.radians(tilt_azimuth_deg))
    blocks = []
    for k, raw in enumerate(data["blocks"]):
        b = dict(raw)
        b["height"] = round(b["height"] * height_factor, 9)
        for key in HORIZONTAL_SIZES:
            if key in b:
                b[key] = round(b[key] * diameter_factor, 9)
        if not b.get("joined"):
            if tilt_deg > 0:
                t0, a0 = b.get("tilt_deg", 0.0), math.radians(b.get("tilt_azimuth_deg", 0.0))
                x, y = t0 * math.sin(a0) + tx, t0 * math.cos(a0) + ty
                b["tilt_deg"] = round(math.hypot(x, y), 6)
                b["tilt_azimuth_deg"] = round(math.degrees(math.atan2(x, y)) % 360.0, 6)
            if k > 0 and max_offset_m > 0:
                r, a = max_offset_m * rng.random(), 2 * math.pi * rng.random()
                east, north = b.get("offset_m", [0.0, 0.0])
                b["offset_m"] = [round(east + r * math.sin(a), 9),
                                 round(north + r * math.cos(a), 9)]
        blocks.append(b)
    return {**data, "name": _name(data, " (ensemble member)"), "blocks": blocks}


def mark(specs, data):
    """Name the description in each spec (``description``; outputs and tables show it)."""
    if data is None:
        return specs
    return [replace(s, column_description=data) for s in specs]


def summary_entry(specs):
    """``{"column_file": description}`` for campaign.json when the specs carry one."""
    for spec in specs:
        if spec.column_description is not None:
            return {"column_file": spec.column_description}
    return {}


def runs_colonnade(specs):
    """Whether the specs run a colonnade (its description in ``column_description``)."""
    return any(s.column_description is not None and "stylobate" in s.column_description
               for s in specs)


def paper_rocking_hz():
    """Frequency (Hz) at which the paper's column, as one stone, rocks on its contact
    springs with the paper's kn (:meth:`ColumnGeometry.contact_rocking_hz`)."""
    reference = ColumnGeometry.monolith(paper.COLUMN_HEIGHT_M,
                                        paper.COLUMN_HEIGHT_M / paper.COLUMN_HD,
                                        paper.MARBLE_DENSITY_KG_M3)
    return reference.contact_rocking_hz(paper.COLUMN_KN_N_M)


def matched_kn(geometry):
    """Contact stiffness per point (N/m) that lets a column rock on its contact springs no
    slower than the paper's column does with the paper's kn (:func:`paper_rocking_hz`):
    the paper's kn for columns of its size, more for heavier ones (kn scales with the
    square of the frequency), rounded to two significant digits."""
    ratio = (paper_rocking_hz() / geometry.contact_rocking_hz(paper.COLUMN_KN_N_M)) ** 2
    kn = paper.COLUMN_KN_N_M * max(1.0, ratio)
    return float(f"{kn:.2g}")
