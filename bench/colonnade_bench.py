"""Bench section 13: what a colonnade costs beside its columns run apart.  The shipped
Parthenon stretch without its frieze (four drum columns, three epistyles) under the
same shaking as the columns one by one, each scene simulated the same time without early
stop; the loop's wall time per simulated second of the colonnade over the sum of the
four columns'."""
import dataclasses
import json
from pathlib import Path

from pipeline.scenario import Numerics, run_yade, scene_params, write_scenario
from pipeline.scenario.bodies import ColumnSpec
from pipeline.scenario.colonnade_file import load
from pipeline.scenario.scene_file import Measurement

COLONNADE = "parthenon-north-flank"
LOOP_CLOCK_FILE = "bench_loop.json"


def _loop_wall_s(run_dir, motion, t_max, **scene):
    params = scene_params(numerics=Numerics(rest_duration_s=1e9), motion_duration=motion.duration,
                          t_max=t_max, **scene)
    params = dataclasses.replace(params, early_stop=False,
                                 measure=Measurement(LOOP_CLOCK_FILE, None))
    write_scenario(run_dir, params, motion)
    traj = run_yade(run_dir)
    loop = json.loads((Path(run_dir) / LOOP_CLOCK_FILE).read_text())["loop_wall_s"]
    return {"bodies": sum(len(c["bodies"]) for c in params.columns),
            "time_step_s": params.time_step_s, "simulated_s": traj.simulated_s,
            "loop_wall_s": loop, "wall_per_simulated_s": loop / traj.simulated_s}


def colonnade_cost(work, motion, seconds):
    """The colonnade's and its columns' loop wall time per simulated second under
    ``motion`` for ``seconds`` simulated; ``ratio``: the colonnade's over the sum."""
    colonnade = dataclasses.replace(load(COLONNADE), frieze=())
    whole = _loop_wall_s(work / "colonnade", motion, seconds, colonnade=colonnade)
    apart = [_loop_wall_s(work / c.name, motion, seconds,
                          columns=[ColumnSpec(c.name, "column", c.x, c.y, c.column)])
             for c in colonnade.columns]
    total = sum(a["wall_per_simulated_s"] for a in apart)
    return {"colonnade": COLONNADE + " without its frieze", "simulated_s": seconds,
            "whole": whole, "apart": apart, "apart_wall_per_simulated_s": total,
            "ratio": whole["wall_per_simulated_s"] / total}


def print_colonnade_cost(c):
    print(f"\n13. A colonnade beside its columns apart ({c['colonnade']}, "
          f"{c['simulated_s']:g} s of shaking): {c['whole']['bodies']} bodies at "
          f"{c['whole']['time_step_s']:.2g} s steps take {c['whole']['wall_per_simulated_s']:.1f} "
          f"s of wall per simulated s; its columns one by one {c['apart_wall_per_simulated_s']:.1f}"
          f" s in all (ratio {c['ratio']:.2f})")
