"""The inversion's grid presets (``invert --grid``), each a forward table's grid
(:class:`~pipeline.inversion.grid.TableGrid`) and its candidates'
(:class:`~pipeline.inversion.candidates.CandidateGrid`): the one home of their values.
quick: a smoke run of a few minutes; demo: what ``make invert-demo`` runs on a 2-core
machine (~700 runs); study: the member study's; full: the default of ``invert``."""
from dataclasses import dataclass

from pipeline.inversion.candidates import CandidateGrid
from pipeline.inversion.grid import TableGrid


@dataclass(frozen=True)
class Preset:
    """A forward table's grid and the candidate sources inverted on it."""
    table: TableGrid
    candidates: CandidateGrid


PRESETS = {
    "full": Preset(TableGrid(mechanisms=("strike-slip", "thrust", "normal"),
                             depths_km=(6.0, 12.0), magnitudes=(6.5, 7.0),
                             distances_km=(2.5, 5.0, 10.0, 20.0, 30.0), members=8),
                   CandidateGrid(radius_km=30.0, step_km=1.0, strike_step_deg=30.0)),
    "demo": Preset(TableGrid(members=6),
                   CandidateGrid(radius_km=25.0, step_km=1.0, strike_step_deg=30.0)),
    # the member study (invert --member-study): one mechanism, two magnitudes, 64 members
    # per node (48 for the likelihoods, 16 observed), rings to 20 km: 3,072 runs
    "study": Preset(TableGrid(mechanisms=("strike-slip",), magnitudes=(6.0, 7.0),
                              distances_km=(2.5, 5.0, 10.0, 20.0), azimuth_step_deg=60.0,
                              members=64, nominal=False),
                    CandidateGrid(radius_km=15.0, step_km=1.0, strike_step_deg=30.0)),
    "quick": Preset(TableGrid(distances_km=(2.5, 6.0), azimuth_step_deg=90.0, members=2,
                              nominal=False, fmax_hz=5.0, duration_s=15.0, tail_s=3.0),
                    CandidateGrid(radius_km=12.0, step_km=1.0, strike_step_deg=90.0)),
}
GRIDS = {name: preset.table for name, preset in PRESETS.items()}   # the forward tables'
