"""Speed and convergence benchmark of the YADE column model (``make bench``).

One run prints, and writes to results/bench/bench.json (+ convergence.png):

1. engine_timing: YADE's engine timing table (O.timingEnabled, yade.timing.stats())
   for the twin model under band-limited random shaking, each engine's share in %;
2. speed: simulated seconds per wall second (s/s) and microseconds per time step of
   still, shaking, twin (one-sine pulse), drums only and monolith only, without and
   with YADE's start-up (wall time of the same scene run for t_max = 1 ms);
3. after_motion: simulated time after the ground motion ended in a run of the drum
   column under weak (sub-threshold) shaking with the default early stop;
4. peer: the twin model under the same one-sine pulse in MuJoCo (bench/mujoco_twin.py):
   both engines' s/s, their ratio and the downfall azimuths per column;
5. convergence: outcome against the time-step factor and the rim points (strong pulse);
6. parallel: runs per minute with 1 and 2 YADE processes at once, and their ratio;
7. quiet_motion: real records with the motion's quiet parts skipped and simulated,
   simulated and wall seconds and outcomes side by side;
8. two_x: the shaking twin scene with the Python friction switch off (the C++ engines
   alone: the most a C++ static/kinetic friction law could give) beside the default;
   Housner's free-rocking check and a still column at the default numerics;
9. time_step_limit: the table the time-step limit rests on: still twin model and still
   Doric column for 5 s at the largest allowed factor and 1.3x it, several dampings,
   on this machine's libm and on the second libm path;
10. ctrl_c: seconds from Ctrl-C to the exit of a running campaign and of a command
   interrupted during its start-up;
11. rock_fragility_adaptive: SP1's pulse-grid fragility on a grid 0.05 g fine in PGA, the
   adaptive surface (``--adaptive``) beside the full grid of the same cells, members and
   directions, each in a fresh directory: runs (and the adaptive cells by their runs),
   YADE wall time (the runs' own wall times summed), campaign wall time, and their
   P = 0.5 contours (g) side by side with the full grid's Monte Carlo band; the load
   average at the start (wall times grow with what else the machine runs);
12. run_wing: the ``run`` command of this checkout beside that of the revision before the
   fragility wing was typed (RUN_WING_REFERENCE, from ``git archive``), alternating, on a
   pulse record and a long record: command and YADE wall seconds, outcomes, ratios.
13. colonnade: a colonnade beside its columns run apart (``colonnade_bench.py``);
14. hazard: ``constrain`` at a study's size (500 branches, 20 specimens at 10 sites, 400
   draws) and a 50 x 50 rate density of PGA and PGV integrated per branch
   (``hazard_bench.py``; no YADE).

Units: seconds (s), metres, m/s^2; azimuths in degrees clockwise from North.
``--quick`` shortens every run and skips the convergence table (for development);
``--only-rock-fragility`` (section 11), ``--only-run-wing`` (section 12) and
``--only-colonnade`` (section 13) and ``--only-hazard`` (section 14) run one section and
add it to an existing bench.json.
"""
import argparse
import contextlib
import dataclasses
import json
import os
import subprocess
import signal
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

sys.path.insert(0, str(Path(__file__).resolve().parent))       # bench/mujoco_twin.py
sys.path.insert(1, str(Path(__file__).resolve().parent.parent))  # this checkout's pipeline
from pipeline import PROJECT_ROOT as PROJECT, RESULTS_DIR  # noqa: E402
from pipeline.campaign.pulse_summary import contour_difference  # noqa: E402
from pipeline.hazard.fragility.file import read_fragility_file  # noqa: E402
from pipeline.files import save_figure, write_json  # noqa: E402
from pipeline.motion import Motion  # noqa: E402
from pipeline.motion.pulses import one_sine_pulse  # noqa: E402
from pipeline.outcome.columns import (column_outcomes, rotation_from_start_deg,  # noqa: E402
                                      total_energy)
from pipeline.scenario import (Column, Contact, Numerics, RunParams, run_yade, scene_params,  # noqa: E402
                               write_scenario)
from pipeline.scenario.runner import reuse_processes  # noqa: E402
from pipeline.scenario.scene_file import Measurement, SceneFile  # noqa: E402
from pipeline.simulate import can_move  # noqa: E402
from colonnade_bench import colonnade_cost, print_colonnade_cost  # noqa: E402
from hazard_bench import hazard_cost, print_hazard_cost  # noqa: E402

STARTUP_T_MAX_S = 1e-3          # a run this short measures YADE's start-up (s)
PULSE = {"azimuth_deg": 30.0, "amplitude": 5.0, "period": 1.0, "duration": 8.0}   # deg, m/s^2, s, s
STRONG_AMPLITUDE = 8.0          # m/s^2: a pulse both engines topple the same way
SHAKING_PEAK = (3.0, 3.0, 1.5)  # m/s^2 E, N, U: ~0.3 g horizontal
WEAK_PEAK = (1.5, 1.5, 0.75)    # m/s^2: rocks the drum column without toppling it

LOOP_CLOCK_FILE = "bench_loop.json"        # the scene's simulation-loop clock (SceneFile.measure)
ENGINE_TIMING_FILE = "engine_timing.json"  # YADE's engine timing, for the timing run


def shaking_motion(duration_s, peak=SHAKING_PEAK, dt=0.005, seed=1):
    """Band-limited (0.5-8 Hz) random 3-component acceleration scaled to ``peak`` (m/s^2
    per component), integrated to velocity (m/s) and displacement (m); dt in s."""
    from scipy.signal import butter, sosfiltfilt
    rng = np.random.default_rng(seed)
    sos = butter(4, [0.5, 8.0], btype="band", fs=1 / dt, output="sos")
    acc = sosfiltfilt(sos, rng.standard_normal((int(round(duration_s / dt)), 3)), axis=0)
    acc *= np.array(peak) / np.abs(acc).max(axis=0)
    vel = cumulative_trapezoid(acc, dx=dt, axis=0, initial=0)
    disp = cumulative_trapezoid(vel, dx=dt, axis=0, initial=0)
    return Motion(dt, acc, vel, disp, meta={"record_id": f"shaking_{max(peak):g}ms2"})


def pulse(amplitude=PULSE["amplitude"]):
    """The benchmark's one-sine pulse toward N30E (1 s period, 8 s record)."""
    return one_sine_pulse(PULSE["azimuth_deg"], amplitude, PULSE["period"], PULSE["duration"])


def prepare(run_dir, kind="both", motion=None, t_max=None, timing=False, columns=None,
            **numerics):
    """Write a scenario directory; t_max None: motion + tail with the default early stop,
    else exactly t_max simulated seconds (no early stop).  The scene clocks its simulation
    loop; ``timing``: it records YADE's engine timing too; ``columns``: the scene's column
    specs instead of ``Column(kind)``'s."""
    if t_max is not None:
        numerics.setdefault("rest_duration_s", 1e9)
    params = scene_params(columns=columns or Column(kind).specs(), numerics=Numerics(**numerics),
                          motion_duration=0.0 if motion is None else motion.duration,
                          t_max=t_max)
    params = dataclasses.replace(params, early_stop=t_max is None, measure=Measurement(
        LOOP_CLOCK_FILE, ENGINE_TIMING_FILE if timing else None))
    write_scenario(run_dir, params, motion)
    return Path(run_dir)


def run_timed(run_dir):
    """run_yade; the simulation loop's wall and CPU time (s) in traj.extra."""
    traj = run_yade(run_dir)
    traj.extra.update(json.loads((Path(run_dir) / LOOP_CLOCK_FILE).read_text()))
    return traj


def measure_startup(run_dir):
    """YADE's start-up (wall s): the faster of two runs of a scene with t_max 1 ms."""
    return min(run_yade(run_dir).wall_s for _ in range(2))


def rates(traj, startup_s):
    """Speed of a finished run.  Without start-up: simulated s per wall s and per CPU s of
    the simulation loop, us of wall time per step; with start-up: simulated s per wall s
    of the whole run (process start to trajectory written); cpu_pct: the loop's CPU /
    wall time (below 100: it shared its core).  startup_s: a 1 ms run's wall time."""
    sim, loop, cpu = traj.simulated_s, traj.extra["loop_wall_s"], traj.extra["loop_cpu_s"]
    steps = sim / traj.dt
    return {"simulated_s": sim, "wall_s": traj.wall_s, "loop_wall_s": loop, "loop_cpu_s": cpu,
            "startup_s": startup_s, "time_step_s": traj.dt, "steps": int(round(steps)),
            "us_per_step": 1e6 * loop / steps, "sim_s_per_wall_s": sim / loop,
            "sim_s_per_cpu_s": sim / cpu, "sim_s_per_wall_s_with_startup": sim / traj.wall_s,
            "cpu_pct": 100.0 * cpu / loop}


# ---------------------------------------------------------------- 1. engine timing
def engine_timing(work, duration_s):
    """Engine timing of the twin model under ``duration_s`` of shaking: table text,
    per engine exec time (s), calls and share (% of all engines' time)."""
    run_dir = prepare(work / "timing", "both", shaking_motion(duration_s), duration_s, timing=True)
    traj = run_timed(run_dir)
    log = (run_dir / "yade.log").read_text()
    table = log.split("ENGINE TIMING BEGIN\n")[1].split("ENGINE TIMING END")[0].rstrip()
    engines = json.loads((run_dir / ENGINE_TIMING_FILE).read_text())
    total_ns = sum(e["exec_ns"] for e in engines)
    rows = [{"engine": e["engine"], "exec_s": e["exec_ns"] * 1e-9, "calls": e["count"],
             "share_pct": 100.0 * e["exec_ns"] / total_ns, "dead": e["dead"]} for e in engines]
    return {"duration_s": duration_s, "wall_s": traj.wall_s, "engines_total_s": total_ns * 1e-9,
            "loop_wall_s": traj.extra["loop_wall_s"], "loop_cpu_s": traj.extra["loop_cpu_s"],
            "time_step_s": traj.dt, "engines": rows, "table": table}


# ---------------------------------------------------------------- 2. speed
def speed(work, shaking_s):
    """Speed of five scenes, each run for t_max = 1 ms (start-up, twice, the faster counts)
    and for its full duration without early stop: still and shaking for ``shaking_s``
    simulated seconds, the pulse scenes for 8 s.  Returns {"startup_s", "time_step_s" (of
    the twin model, s), "scenes": {label: rates(...) + "cost_vs_still" (us/step ratio)}}."""
    shaking = shaking_motion(shaking_s)
    scenes = {"still": ("both", None, shaking_s, "twin, no motion"),
              "shaking": ("both", shaking, shaking_s, "twin, random shaking ~0.3 g"),
              "twin": ("both", pulse(), PULSE["duration"], "twin, one-sine pulse 5 m/s^2"),
              "drums only": ("drums", pulse(), PULSE["duration"], "7 drums, same pulse"),
              "monolith only": ("monolithic", pulse(), PULSE["duration"], "monolith, same pulse")}
    rows = {}
    for label, (kind, motion, t_max, text) in scenes.items():
        name = label.replace(" ", "_")
        startup = measure_startup(prepare(work / f"{name}_startup", kind, motion, STARTUP_T_MAX_S))
        traj = run_timed(prepare(work / name, kind, motion, t_max))
        rows[label] = {"scene": text, **rates(traj, startup)}
    still = rows["still"]["us_per_step"]
    for row in rows.values():
        row["cost_vs_still"] = row["us_per_step"] / still
    return {"startup_s": rows["twin"]["startup_s"], "time_step_s": rows["twin"]["time_step_s"],
            "scenes": rows}


# ---------------------------------------------------------------- 3. after the motion
def after_motion(work, duration_s):
    """Drum column under ``duration_s`` of weak shaking, default early stop: simulated
    time after the motion ended (s and % of the run)."""
    motion = shaking_motion(duration_s, WEAK_PEAK, seed=2)
    run_dir = prepare(work / "after_motion", "drums", motion)
    traj = run_yade(run_dir)
    out = column_outcomes(traj)[0]
    after = traj.simulated_s - traj.motion_end
    energy = total_energy(traj) - total_energy(traj)[0]     # J above the initial rest
    k_end = np.searchsorted(traj.t, traj.motion_end)
    # body speed (m/s), angular speed x 1 m counting as a speed (the scene's rest check)
    body_speed = np.maximum(np.linalg.norm(traj.vel, axis=2), np.linalg.norm(traj.angvel, axis=2))
    params = SceneFile.read(run_dir)
    return {"column": "drums", "peak_acc_m_s2": list(WEAK_PEAK), "motion_end_s": traj.motion_end,
            "simulated_s": traj.simulated_s, "t_max_s": params.t_max,
            "after_motion_s": after, "after_motion_pct": 100.0 * after / traj.simulated_s,
            "stopped_early": traj.stopped_early, "wall_s": traj.wall_s,
            "toppled": out["toppled"], "max_tilt_deg": out["max_tilt_deg"],
            "energy_at_motion_end_J": float(energy[k_end]), "energy_at_end_J": float(energy[-1]),
            "max_speed_last_s_m_s": float(body_speed[traj.t >= traj.t[-1] - 1.0].max()),
            "campaign_would_run_yade": can_move(motion, params.columns,
                                                Contact(**params.contact))}


# ---------------------------------------------------------------- 4. MuJoCo peer
def peer(work, startup, amplitudes):
    """The twin model under the pulse toward N30E (amplitudes in m/s^2) in YADE and in
    MuJoCo, each with its default early stop (standing bodies at rest for 0.5 s once the
    motion is over or every column has fallen).  startup: YADE's start-up (s).  Speeds are
    simulated s per wall s and per CPU s of the simulation loop (MuJoCo: its stepping
    loop; CPU time includes its model set-up of a few ms)."""
    import mujoco
    import mujoco_twin
    out = {"mujoco_version": mujoco.__version__, "pulses": []}
    for amplitude in amplitudes:
        traj = run_timed(prepare(work / f"peer_{amplitude:g}", "both", pulse(amplitude)))
        yade = rates(traj, startup)
        acc, dt = mujoco_twin.one_sine_pulse(PULSE["azimuth_deg"], amplitude, PULSE["period"],
                                             PULSE["duration"])
        cpu = time.process_time()
        with tempfile.TemporaryDirectory() as cwd, contextlib.chdir(cwd):   # MUJOCO_LOG.TXT
            mj = mujoco_twin.run_twin(acc, dt, PULSE["duration"])
        cpu = time.process_time() - cpu
        mj.update(sim_s_per_cpu_s=mj["sim_s"] / cpu,
                  cpu_pct=100.0 * cpu / (mj["wall_s"] + mj["setup_s"]))
        yade_cols = {c["column"]: c for c in column_outcomes(traj)}
        out["pulses"].append({
            "amplitude_m_s2": amplitude,
            "yade": {k: yade[k] for k in ("sim_s_per_wall_s", "sim_s_per_cpu_s",
                                          "sim_s_per_wall_s_with_startup", "simulated_s",
                                          "wall_s", "time_step_s", "cpu_pct")},
            "mujoco": {k: mj[k] for k in ("sim_s_per_wall_s", "sim_s_per_cpu_s", "sim_s",
                                          "wall_s", "setup_s", "timestep_s", "cpu_pct")},
            "speed_ratio_yade_to_mujoco": yade["sim_s_per_wall_s"] / mj["sim_s_per_wall_s"],
            "cpu_speed_ratio_yade_to_mujoco": yade["sim_s_per_cpu_s"] / mj["sim_s_per_cpu_s"],
            "columns": [{"column": c["column"],
                         "yade_azimuth_deg": yade_cols[c["column"]]["downfall_azimuth_deg"],
                         "mujoco_azimuth_deg": c["downfall_azimuth_deg"],
                         "yade_impact_s": yade_cols[c["column"]]["impact_time_s"],
                         "mujoco_impact_s": c["impact_time_s"]} for c in mj["columns"]]})
    return out


# ---------------------------------------------------------------- 5. convergence
def convergence(work):
    """Outcome of the 5 m/s^2 pulse toward N30E against the time-step factor (the default
    at the paper's damping, its half and its quarter) and the number of rim contact
    points (default early stop)."""
    from pipeline.scenario.time_step import dt_factor_for
    default = dt_factor_for(Contact(), Numerics())
    factors = (default / 4, default / 2, default)
    rows = []
    for key, values in (("dt_factor", factors), ("rim_points", (8, 16, 32))):
        for value in values:
            traj = run_yade(prepare(work / f"{key}_{value}", "both", pulse(), **{key: value}))
            for col in column_outcomes(traj):
                rows.append({"parameter": key, "value": value, "column": col["column"],
                             "toppled": col["toppled"],
                             "downfall_azimuth_deg": col["downfall_azimuth_deg"],
                             "impact_time_s": col["impact_time_s"], "wall_s": traj.wall_s})
    return rows


def plot_convergence(rows, path):
    """Downfall azimuth (deg) against each parameter, one line per column (log x)."""
    from pipeline.figures.style import COLUMN_LABELS, COLUMN_MARKERS, colour, new_figure
    fig, axes = new_figure(1, 2, figsize=(10, 4), layout="constrained")
    for ax, key in zip(axes, ("dt_factor", "rim_points")):
        for column in ("drums", "monolithic"):
            sel = [r for r in rows if r["parameter"] == key and r["column"] == column]
            ax.plot([r["value"] for r in sel],
                    [np.nan if r["downfall_azimuth_deg"] is None else r["downfall_azimuth_deg"]
                     for r in sel], marker=COLUMN_MARKERS[column], color=colour(column),
                    label=COLUMN_LABELS[column])
        values = sorted({r["value"] for r in rows if r["parameter"] == key})
        ax.set_xscale("log")
        ax.set_xticks(values, [f"{v:g}" for v in values])
        ax.minorticks_off()
        ax.set_xlabel({"dt_factor": "time step factor f (dt = f sqrt(m / (16 kn)))",
                       "rim_points": "contact spheres per rim"}[key])
        ax.set_ylabel("downfall azimuth (deg)")
        ax.axhline(PULSE["azimuth_deg"], color="0.5", lw=0.8, ls="--", label="pulse azimuth")
        low, high = ax.get_ylim()
        ax.set_ylim(min(low, PULSE["azimuth_deg"] - 20), max(high, PULSE["azimuth_deg"] + 20))
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("Outcome convergence: one-sine pulse 5 m/s^2, 1 s, toward N30E")
    save_figure(fig, path, dpi=120)


# ---------------------------------------------------------------- 6. parallel runs
@dataclasses.dataclass(frozen=True)
class ParallelTags:
    """A parallel-bench run's tags: simulated time ``t_max`` (s)."""
    t_max: float


def parallel_run(spec, run_dir):
    """Campaign worker of the parallel bench: the twin model under the spec's pulse for
    exactly ``t_max`` s (no early stop); summary.json holds YADE's wall time."""
    traj = run_yade(prepare(run_dir, "both", Motion.load(spec.motion_file),
                            spec.tags.t_max))
    write_json(Path(run_dir) / "summary.json", {"wall_s": traj.wall_s})


def noop_run(spec, run_dir):
    """A campaign worker that runs nothing: the executor's own cost per task."""
    write_json(Path(run_dir) / "summary.json", {"run_id": spec.run_id})


def parallel(work, n_runs, t_max, n_noop=40):
    """Runs per minute of ``n_runs`` twin-model pulse runs (azimuths 0, 30, ... deg,
    ``t_max`` s each, YADE start-up included) through the campaign executor's Dask path,
    a LocalCluster of 1 and 2 single-threaded worker processes on 127.0.0.1
    (``jobs_1``, ``jobs_2``; each task carries its motion and returns the run's files,
    trajectory included; each worker runs its tasks in one YADE process), the same runs
    with the thread executor for comparison (``threads_jobs_N``: a fresh YADE process per
    run; ``threads_reused_jobs_N``: one per thread, as the campaign executor runs them),
    and Dask's overheads: the cluster's start-up until its workers have imported what a campaign's worker imports (``cluster_startup_s``, not in the
    runs per minute), its closing (``cluster_close_s``) and the wall time per task of
    ``n_noop`` tasks that run no YADE on one worker (``task_overhead_ms``)."""
    import importlib

    from distributed import Client

    from pipeline.campaign.dask_client import close_dask, local_cluster
    from pipeline.campaign.dask_worker import run_task
    from pipeline.campaign.dask_worker import WORKER_CODE
    from pipeline.campaign.spec import RunSpec
    from pipeline.scenario import RunParams
    from pipeline.files import code_hash
    out = {"runs": n_runs, "t_max_s": t_max, "executor": "dask",
           "load_average_before": os.getloadavg()[0]}
    motions = [one_sine_pulse(30.0 * k, PULSE["amplitude"], PULSE["period"], t_max).save(
        work / f"parallel_motion_{k}.npz") for k in range(n_runs)]
    specs = [RunSpec(f"parallel_{k}", f"parallel_{k}", str(m), RunParams(), f"parallel_{k}",
                     ParallelTags(t_max)) for k, m in enumerate(motions)]
    code = code_hash(*WORKER_CODE)
    for jobs in (1, 2):
        start = time.perf_counter()
        cluster = local_cluster(jobs)
        client = Client(cluster)
        client.run(importlib.import_module, "pipeline.campaign.definitions")   # as a campaign
        startup = time.perf_counter() - start
        try:
            if jobs == 1:
                start = time.perf_counter()
                client.gather([client.submit(run_task, noop_run,
                                             dataclasses.replace(specs[0], run_id=str(k)),
                                             motions[0].read_bytes(), "/bench", code, "bench",
                                             pure=False) for k in range(n_noop)])
                out["task_overhead_ms"] = 1e3 * (time.perf_counter() - start) / n_noop
            start = time.perf_counter()
            results = client.gather([client.submit(run_task, parallel_run, spec,
                                                   Path(spec.motion_file).read_bytes(),
                                                   str(work / spec.run_id), code, "bench",
                                                   pure=False) for spec in specs])
            wall = time.perf_counter() - start
        finally:
            start = time.perf_counter()
            close_dask(client, cluster)                 # as a campaign closes it
            close = time.perf_counter() - start
        failed = [r["message"] for r in results if r["error"]]
        if failed:
            raise RuntimeError(f"parallel bench: {failed[0]}")
        out[f"jobs_{jobs}"] = {"wall_s": wall, "runs_per_minute": 60.0 * n_runs / wall,
                               "cluster_startup_s": startup, "cluster_close_s": close}
        dirs = [prepare(work / f"parallel_threads{jobs}_{k}", "both", Motion.load(m), t_max)
                for k, m in enumerate(motions)]
        start = time.perf_counter()
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(run_yade, dirs))
        wall = time.perf_counter() - start
        out[f"threads_jobs_{jobs}"] = {"wall_s": wall, "runs_per_minute": 60.0 * n_runs / wall}
        start = time.perf_counter()
        with reuse_processes(), ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(run_yade, dirs))       # as a campaign runs them: one YADE per thread
        wall = time.perf_counter() - start
        out[f"threads_reused_jobs_{jobs}"] = {"wall_s": wall,
                                              "runs_per_minute": 60.0 * n_runs / wall}
    out["scaling_2_vs_1"] = out["jobs_2"]["runs_per_minute"] / out["jobs_1"]["runs_per_minute"]
    out["threads_scaling_2_vs_1"] = (out["threads_jobs_2"]["runs_per_minute"]
                                     / out["threads_jobs_1"]["runs_per_minute"])
    return out


# ---------------------------------------------------------------- 7. quiet motion
QUIET_RECORDS = ("GM20", "NF04", "RC-CCC", "RSN126-GAZLI")   # run-all's ensemble records


def quiet_motion(work, records=QUIET_RECORDS):
    """The twin model under real records, each run twice side by side in 2 threads (one
    YADE process each, as campaigns): skipping the motion's quiet parts (default) and
    simulating the whole motion.  Per record: simulated s, YADE wall s and both
    outcomes per column (toppled, downfall azimuth deg)."""
    from pipeline.records import processed_motion
    from pipeline.simulate import simulate

    def one(task):
        record, mode = task
        motion, _ = processed_motion(record)
        return simulate(motion, work / "quiet" / f"{record}_{mode}",
                        RunParams(numerics=Numerics(quiet_motion=mode)), record=record)

    tasks = [(r, m) for r in records for m in ("skip", "simulate")]
    with reuse_processes(), ThreadPoolExecutor(2) as pool:
        summaries = dict(zip(tasks, pool.map(one, tasks)))
    rows = []
    for record in records:
        row = {"record": record}
        for mode in ("skip", "simulate"):
            s = summaries[(record, mode)]
            row[mode] = {"simulated_s": s.simulated_s, "wall_s": s.wall_s,
                         "window_s": s.simulated_window_s, "motion_end_s": s.motion_end_s,
                         "columns": {c.column: (c.toppled, c.downfall_azimuth_deg)
                                     for c in s.columns}}
        rows.append(row)
    total = {mode: sum(r[mode]["simulated_s"] for r in rows) for mode in ("skip", "simulate")}
    wall = {mode: sum(r[mode]["wall_s"] for r in rows) for mode in ("skip", "simulate")}
    return {"records": rows, "simulated_s": total, "wall_s": wall,
            "simulated_ratio": total["simulate"] / total["skip"],
            "wall_ratio": wall["simulate"] / wall["skip"]}


# ---------------------------------------------------------------- printing
# ---------------------------------------------------------------- 8. what 2x needs
STILL_COLUMN, STILL_S = "doric-peristyle", 0.5      # column file, simulated s
STILL_ROTATION_DEG = 0.01   # tests/scenario/test_column_files.py: a still column stays put


def two_x(work, shaking_s):
    """The shaking twin scene of section 2 (``shaking_s`` simulated s, no early stop) with
    the default numerics and without the friction switch (mu_s only: YADE's C++ engines
    alone), speeds (simulated s per wall s of the loop) and their ratio.  A larger time
    step is not a way to 2x: section 9 shows the stability limit of the time step.
    Then, at the default numerics, the accuracy the tests ask for: Housner's free
    rocking (the verification's marble block, critically damped contacts: the default
    factor at that damping), and STILL_COLUMN on a still pedestal for STILL_S, the
    largest rotation of a body from where it was put (deg) against the still-column
    test's STILL_ROTATION_DEG."""
    from pipeline.verification.checks import verify_housner
    shaking = shaking_motion(shaking_s)
    cases = {"default": {}, "no friction switch": {"friction": "static"}}
    rows = {}
    for label, numerics in cases.items():
        traj = run_timed(prepare(work / f"two_x_{len(rows)}", "both", shaking, shaking_s,
                                 **numerics))
        rows[label] = {"numerics": numerics, **rates(traj, 0.0)}
    base = rows["default"]["sim_s_per_wall_s"]
    for row in rows.values():
        row["x_default"] = row["sim_s_per_wall_s"] / base
    h = verify_housner(run_dir=work / "two_x_housner")
    run_dir = work / "two_x_still"
    params = scene_params(columns=Column("both", column_file=STILL_COLUMN).specs(),
                          motion_duration=0.0, t_max=STILL_S)
    write_scenario(run_dir, params, None)
    accuracy = [{"dt_factor": params.dt_factor, "housner_passed": h["passed"],
                 "housner_refused": None, "housner_tolerance": h["tolerance"],
                 "max_rel_error_impact_times": h["max_rel_error_impact_times"],
                 "max_rel_error_peaks": h["max_rel_error_peaks"],
                 "still_rotation_deg": rotation_from_start_deg(run_yade(run_dir))}]
    return {"shaking_s": shaking_s, "scenes": rows, "accuracy": accuracy,
            "still_column": STILL_COLUMN, "still_s": STILL_S,
            "still_rotation_limit_deg": STILL_ROTATION_DEG,
            "members_per_scene": members_per_scene(work, shaking)}


MEMBERS_PER_SCENE = (1, 2, 4)      # twin members sharing one YADE scene
MEMBER_SPACING_M = 10.0            # North of each other: a fallen column reaches ~4 m


def members_per_scene(work, shaking):
    """One way to twice the members per CPU-hour, measured: n twin members
    (drums and monolith each) in one scene on one pedestal under one motion, spaced
    MEMBER_SPACING_M apart so that they never touch, for the motion's duration (no early
    stop).  Per n: the loop's wall s, wall s per member and members per wall hour
    against one member per scene (``x_one``)."""
    rows = []
    for n in MEMBERS_PER_SCENE:
        specs = [dataclasses.replace(spec, name=f"{spec.name}{k}", y=MEMBER_SPACING_M * k)
                 for k in range(n) for spec in Column("both").specs()]
        traj = run_timed(prepare(work / f"two_x_members_{n}", motion=shaking,
                                 t_max=shaking.duration, columns=specs))
        loop = traj.extra["loop_wall_s"]
        rows.append({"members": n, "time_step_s": traj.dt, "loop_wall_s": loop,
                     "wall_s_per_member": loop / n, "members_per_wall_hour": 3600.0 * n / loop,
                     "cpu_pct": 100.0 * traj.extra["loop_cpu_s"] / loop})
    for row in rows:
        row["x_one"] = row["members_per_wall_hour"] / rows[0]["members_per_wall_hour"]
    return rows


# ---------------------------------------------------------------- 9. time-step limit
STABILITY_DAMPINGS = (0.0, 0.2, 0.36, 0.5, 0.7, 1.0)
STABILITY_RATIOS = (1.0, 1.3)       # factor / the allowed limit at that damping
STABILITY_S = 5.0                   # simulated s on a still pedestal


def time_step_limit(work, seconds):
    """The table the time-step limit rests on: the still twin model and the still Doric
    column (STILL_MODELS) held ``seconds`` on a still pedestal at each damping of
    STABILITY_DAMPINGS, at the largest allowed factor and 1.3x it, on this machine's
    libm and on the second libm path (SECOND_LIBM_TUNABLES); the largest rotation of a
    body from where it was placed (deg).  Two runs at once (no speed is measured)."""
    from pipeline.scenario.time_step import largest_stable_dt_factor
    from pipeline.scenario.runner import SECOND_LIBM_TUNABLES
    from pipeline.verification.checks import STILL_MODELS, still_rotation_deg
    cases = [(z, r, m) for z in STABILITY_DAMPINGS for r in STABILITY_RATIOS
             for m in STILL_MODELS]
    rows = []
    for path in ("native", "second"):
        if path == "second":
            os.environ["GLIBC_TUNABLES"] = SECOND_LIBM_TUNABLES
        try:
            def one(case):
                zeta, ratio, model = case
                factor = ratio * largest_stable_dt_factor(zeta)
                rotation = still_rotation_deg(work / f"limit_{path}_{model}_{zeta}_{ratio}",
                                              model, zeta, factor, seconds)
                return {"libm": path, "damping": zeta, "ratio_to_limit": ratio,
                        "dt_factor": factor, "model": model, "rotation_deg": rotation}
            with ThreadPoolExecutor(max_workers=2) as pool:
                rows += list(pool.map(one, cases))
        finally:
            os.environ.pop("GLIBC_TUNABLES", None)
    return {"seconds": seconds, "rows": rows}


def print_time_step_limit(t):
    print(f"\n9. Time-step limit: largest body rotation (deg) over {t['seconds']:g} s on a still "
          "pedestal, at the allowed factor (x1.0) and 1.3x it; native / second libm path")
    models = sorted({r["model"] for r in t["rows"]})
    head = "".join(f"{m + ' x' + format(k, 'g'):>30}" for m in models for k in STABILITY_RATIOS)
    print(f"   {'damping':>8}{'factor':>8}{head}")
    table = {(r["libm"], r["damping"], r["ratio_to_limit"], r["model"]): r for r in t["rows"]}
    for zeta in sorted({r["damping"] for r in t["rows"]}):
        factor = table[("native", zeta, 1.0, models[0])]["dt_factor"]
        cells = "".join(
            f"{table[('native', zeta, k, m)]['rotation_deg']:>15.4f}"
            f"{table[('second', zeta, k, m)]['rotation_deg']:>15.4f}"
            for m in models for k in STABILITY_RATIOS)
        print(f"   {zeta:>8g}{factor:>8.3f}{cells}")


# ---------------------------------------------------------------- 10. Ctrl-C
def ctrl_c(work, trials=3):
    """Seconds from Ctrl-C (SIGINT) to the exit of a 4-run records campaign (two YADE runs
    going), and of a command interrupted 0.3 s into its start-up; exit status and the
    last line it printed."""
    import signal
    from pipeline.motion.pulses import one_sine_pulse as pulse

    def yade_running(under):
        for pid in filter(str.isdigit, os.listdir("/proc")):
            with contextlib.suppress(OSError):
                if b"run_scene.py" in Path(f"/proc/{pid}/cmdline").read_bytes() and \
                        os.readlink(f"/proc/{pid}/cwd").startswith(str(under)):
                    return True
        return False

    def interrupt(out, args, when):
        proc = subprocess.Popen([sys.executable, "-m", "pipeline", *args], cwd=PROJECT,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        while not when() and time.monotonic() < deadline:
            time.sleep(0.02)
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
        lines = err.strip().splitlines()
        return {"stop_s": time.monotonic() - sent, "exit": proc.returncode,
                "last_line": lines[-1] if lines else ""}

    records = []
    for k in range(4):
        m = pulse(45.0 * k, 5.0, duration=20.0)
        path = work / f"ctrl_c_{k}.npz"
        Motion(m.dt, m.acc, m.vel, m.disp, meta={"record_id": path.stem}).save(path)
        records.append(str(path))
    running = []
    for trial in range(trials):
        out = work / f"ctrl_c_campaign_{trial}"
        running.append(interrupt(out, ["campaign", "records", "--records", ",".join(records),
                                        "--out", str(out), "--jobs", "2", "--animations", "0"],
                                 lambda out=out: yade_running(out)))
    started = time.monotonic()
    startup = interrupt(work / "ctrl_c_startup", ["campaign", "records", "--records", "GM20",
                                                  "--out", str(work / "ctrl_c_startup")],
                        lambda: time.monotonic() - started > 0.3)
    return {"running": running, "startup": startup}


def print_ctrl_c(c):
    times = ", ".join(f"{r['stop_s']:.2f}" for r in c["running"])
    print(f"\n10. Ctrl-C: a running 4-run campaign stops in {times} s (exit "
          f"{sorted({r['exit'] for r in c['running']})}); 0.3 s into start-up: "
          f"{c['startup']['stop_s']:.2f} s, exit {c['startup']['exit']}, "
          f"last line {c['startup']['last_line']!r}")


def fmt(value, spec=".1f"):
    return "-" if value is None else format(value, spec)


def print_timing(t):
    print(f"1. Engine timing: twin model, {t['duration_s']:g} s of random shaking ~0.3 g, "
          f"time step {t['time_step_s'] * 1e6:.0f} us; run {t['wall_s']:.1f} s wall, "
          f"simulation loop {t['loop_wall_s']:.1f} s wall / {t['loop_cpu_s']:.1f} s CPU, "
          f"engines {t['engines_total_s']:.1f} s")
    print(t["table"])
    print(f"{'engine':<24}{'calls':>10}{'time s':>9}{'us/call':>9}{'share %':>9}")
    for e in sorted(t["engines"], key=lambda e: -e["exec_s"]):
        if not e["dead"]:
            print(f"{e['engine']:<24}{e['calls']:>10}{e['exec_s']:9.2f}"
                  f"{1e6 * e['exec_s'] / max(e['calls'], 1):9.1f}{e['share_pct']:9.1f}")


def print_speed(s):
    print(f"\n2. Speed, one core.  Without start-up: simulation loop only; with start-up: the "
          f"whole run; start s: a run of t_max {STARTUP_T_MAX_S * 1e3:g} ms")
    print(f"{'scene':<15}{'what':<30}{'dt us':>7}{'sim s':>7}{'start s':>8}{'us/step':>9}"
          f"{'x still':>8}{'sim s/wall s':>13}{'with start-up':>14}{'sim s/CPU s':>12}"
          f"{'CPU %':>6}")
    for label, r in s["scenes"].items():
        print(f"{label:<15}{r['scene']:<30}{r['time_step_s'] * 1e6:7.0f}{r['simulated_s']:7.1f}"
              f"{r['startup_s']:8.2f}{r['us_per_step']:9.1f}{r['cost_vs_still']:8.2f}"
              f"{r['sim_s_per_wall_s']:13.2f}{r['sim_s_per_wall_s_with_startup']:14.2f}"
              f"{r['sim_s_per_cpu_s']:12.2f}{r['cpu_pct']:6.0f}")
    print("   CPU %: the loop's CPU / wall time; below ~100 it shared its core with other work")


def print_after(a):
    print(f"\n3. After the motion: drum column, {a['motion_end_s']:.1f} s of weak shaking "
          f"(peaks {a['peak_acc_m_s2'][0]:g}/{a['peak_acc_m_s2'][1]:g}/{a['peak_acc_m_s2'][2]:g}"
          f" m/s^2 E/N/U), default early stop (t_max {a['t_max_s']:.1f} s)")
    print(f"   motion end {a['motion_end_s']:.2f} s, simulated {a['simulated_s']:.2f} s "
          f"(stopped early: {a['stopped_early']}): {a['after_motion_s']:.2f} s after the motion "
          f"= {a['after_motion_pct']:.1f} % of the run; wall {a['wall_s']:.1f} s; "
          f"toppled {a['toppled']}, max tilt {a['max_tilt_deg']:.2f} deg; "
          f"a campaign would {'run' if a['campaign_would_run_yade'] else 'skip'} YADE")
    print(f"   energy above rest {a['energy_at_motion_end_J']:.1f} J at the motion end, "
          f"{a['energy_at_end_J']:.1f} J at the end; fastest body in the last second "
          f"{a['max_speed_last_s_m_s'] * 1e3:.0f} mm/s (rest: < 5 mm/s for 0.5 s)")


def print_peer(p):
    print(f"\n4. Peer: the twin model in MuJoCo {p['mujoco_version']} (bench/mujoco_twin.py, "
          f"time step 0.5 ms), one-sine pulse 1 s toward N30E, 8 s record, both engines with "
          f"their early stop; simulated s per wall s of the simulation loop")
    print(f"{'pulse':>9}{'YADE s/s':>10}{'MuJoCo s/s':>12}{'YADE/MuJoCo':>13}   "
          f"{'column':<12}{'YADE az':>9}{'MuJoCo az':>11}{'YADE hit s':>12}{'MuJoCo hit s':>14}")
    for q in p["pulses"]:
        for k, c in enumerate(q["columns"]):
            head = (f"{q['amplitude_m_s2']:g} m/s^2".rjust(9) +
                    f"{q['yade']['sim_s_per_wall_s']:10.2f}{q['mujoco']['sim_s_per_wall_s']:12.2f}"
                    f"{q['speed_ratio_yade_to_mujoco']:13.3f}") if k == 0 else " " * 44
            print(f"{head}   {c['column']:<12}{fmt(c['yade_azimuth_deg']):>9}"
                  f"{fmt(c['mujoco_azimuth_deg']):>11}{fmt(c['yade_impact_s'], '.2f'):>12}"
                  f"{fmt(c['mujoco_impact_s'], '.2f'):>14}")
    for q in p["pulses"]:
        y, m = q["yade"], q["mujoco"]
        print(f"   {q['amplitude_m_s2']:g} m/s^2: YADE simulated {y['simulated_s']:.2f} s, run "
              f"{y['wall_s']:.1f} s wall ({y['sim_s_per_wall_s_with_startup']:.2f} s/s with "
              f"start-up), {y['sim_s_per_cpu_s']:.2f} s/CPU s (CPU {y['cpu_pct']:.0f} %); MuJoCo "
              f"{m['sim_s']:.2f} s in {m['wall_s'] + m['setup_s']:.2f} s wall, "
              f"{m['sim_s_per_cpu_s']:.2f} s/CPU s (CPU {m['cpu_pct']:.0f} %); "
              f"CPU-time ratio YADE/MuJoCo {q['cpu_speed_ratio_yade_to_mujoco']:.3f}")
    print("   note: the drum column at 5 m/s^2 is a marginal case in MuJoCo (it was found with "
          "the drums 8.9 deg off the pulse axis with 4-point face contacts); the "
          f"{STRONG_AMPLITUDE:g} m/s^2 pulse is the case both engines should agree on")


def print_convergence(rows):
    print("\n5. Convergence: one-sine pulse 5 m/s^2 toward N30E "
          "(results/bench/convergence.png)")
    print(f"{'parameter':<12}{'value':>7}{'column':>12}{'toppled':>9}{'azimuth':>9}"
          f"{'impact s':>10}{'wall s':>8}")
    for r in rows:
        print(f"{r['parameter']:<12}{r['value']:>7}{r['column']:>12}{str(r['toppled']):>9}"
              f"{fmt(r['downfall_azimuth_deg']):>9}{fmt(r['impact_time_s'], '.2f'):>10}"
              f"{r['wall_s']:8.1f}")


def print_parallel(p):
    print(f"\n6. Parallel runs: {p['runs']} twin-model pulse runs of {p['t_max_s']:g} s "
          f"(start-up included; load average before {p['load_average_before']:.2f})")
    for jobs in (1, 2):
        r = p[f"jobs_{jobs}"]
        line = (f"   {jobs} Dask worker(s): {r['wall_s']:.1f} s wall, "
                f"{r['runs_per_minute']:.1f} runs/min")
        threads = p.get(f"threads_jobs_{jobs}")
        if threads:
            line += f"; threads: {threads['runs_per_minute']:.1f} runs/min"
        reused = p.get(f"threads_reused_jobs_{jobs}")
        if reused:
            line += (f"; threads reusing one YADE process each (campaigns): "
                     f"{reused['runs_per_minute']:.1f} runs/min "
                     f"(x{reused['runs_per_minute'] / threads['runs_per_minute']:.2f})")
        print(line)
    print(f"   scaling 2 vs 1 (Dask): {p['scaling_2_vs_1']:.2f} (2.00 = perfect on 2 free cores)")
    for key, label in (("cluster_startup_s", "cluster start-up s"),
                       ("cluster_close_s", "cluster close s"),
                       ("task_overhead_ms", "overhead per task ms")):
        if key in p:
            print(f"   {label}: {p[key]:.2f}")


def print_quiet(q):
    def outcome(cols):
        return ", ".join(f"{c} {az:.0f}" if top else f"{c} stood"
                         for c, (top, az) in cols.items())
    print("\n7. Quiet motion: the twin model under real records, the motion's quiet parts "
          "skipped (default) and simulated, side by side")
    print(f"   {'record':<14}{'skip: window s':>18}{'sim s':>7}{'wall s':>8}   "
          f"{'full: sim s':>11}{'wall s':>8}   outcomes skip | full")
    for r in q["records"]:
        s, f = r["skip"], r["simulate"]
        print(f"   {r['record']:<14}{s['window_s'][0]:8.1f}-{s['window_s'][1]:<8.1f}"
              f"{s['simulated_s']:7.1f}{s['wall_s']:8.1f}   {f['simulated_s']:11.1f}"
              f"{f['wall_s']:8.1f}   {outcome(s['columns'])} | {outcome(f['columns'])}")
    print(f"   simulated s full / skip: {q['simulated_ratio']:.2f}; YADE wall s full / skip: "
          f"{q['wall_ratio']:.2f}")


def print_two_x(t):
    print(f"\n8. What 2x per simulated second takes: the shaking twin scene of section 2 "
          f"({t['shaking_s']:g} s), side by side")
    print(f"   {'numerics':<22}{'dt us':>7}{'us/step':>9}{'sim s/wall s':>13}{'x default':>10}"
          f"{'CPU %':>7}")
    for label, r in t["scenes"].items():
        print(f"   {label:<22}{r['time_step_s'] * 1e6:7.0f}{r['us_per_step']:9.1f}"
              f"{r['sim_s_per_wall_s']:13.2f}{r['x_default']:10.2f}{r['cpu_pct']:7.0f}")
    print("   no friction switch: mu_s only, YADE's C++ engines alone (the most a C++ "
          "static/kinetic friction law could give)")
    print(f"   several twin members in one scene ({MEMBER_SPACING_M:g} m apart, one pedestal, "
          "one motion), side by side:")
    print(f"   {'members':>10}{'loop wall s':>13}{'wall s/member':>15}{'members/h':>11}"
          f"{'x one':>7}{'CPU %':>7}")
    for r in t["members_per_scene"]:
        print(f"   {r['members']:>10}{r['loop_wall_s']:13.2f}{r['wall_s_per_member']:15.2f}"
              f"{r['members_per_wall_hour']:11.0f}{r['x_one']:7.2f}{r['cpu_pct']:7.0f}")
    for a in t["accuracy"]:
        still_ok = a["still_rotation_deg"] < t["still_rotation_limit_deg"]
        housner = (f"refused ({a['housner_refused']})" if a["housner_refused"] else
                   f"impact times within {100 * a['max_rel_error_impact_times']:.2f} %, peaks "
                   f"within {100 * a['max_rel_error_peaks']:.2f} % (tolerance "
                   f"{100 * a['housner_tolerance']:g} %): "
                   f"{'passed' if a['housner_passed'] else 'FAILED'}")
        print(f"   dt factor {a['dt_factor']:g}: Housner free rocking (critical damping) {housner}"
              f"; {t['still_column']} on a still pedestal for {t['still_s']:g} s turns "
              f"{a['still_rotation_deg']:.4f} deg (test: < {t['still_rotation_limit_deg']:g}): "
              f"{'passed' if still_ok else 'FAILED'}")


ROCK_SPECIMEN = "records/shake_table/sp1.json"
ROCK_PULSES = "pga_g=0.05:1.5:30;pgv_pga_s=0.1:0.7:3"    # 90 cells, PGA 0.05 g apart
ROCK_MEMBERS, ROCK_HEADINGS = 8, 4                      # 32 runs per cell in the full grid


def rock_fragility_adaptive(work, jobs=2):
    """The adaptive pulse-grid surface of SP1 beside the full grid of the same cells,
    members and headings, each campaign in a fresh directory (nothing shared)."""
    result = {"specimen": ROCK_SPECIMEN, "pulses": ROCK_PULSES, "members": ROCK_MEMBERS,
              "headings": ROCK_HEADINGS, "jobs": jobs, "load_average_1min": os.getloadavg()[0]}
    summaries = {}
    for mode in ("full", "adaptive"):
        out = work / f"rock_fragility_{mode}"
        command = [sys.executable, "-m", "pipeline", "campaign", "fragility",
                   "--column-file", str(PROJECT / ROCK_SPECIMEN), "--pulses", ROCK_PULSES,
                   "--members", str(ROCK_MEMBERS), "--headings", str(ROCK_HEADINGS),
                   "--jobs", str(jobs), "--out", str(out)]
        started = time.perf_counter()
        subprocess.run(command + (["--adaptive"] if mode == "adaptive" else []), cwd=PROJECT,
                       check=True, capture_output=True, text=True)
        wall = time.perf_counter() - started
        summaries[mode] = read_fragility_file(out)
        grid = summaries[mode].pulse_grid
        runs_per_cell = [c.n for c in grid.models["block2d"].cells]
        result[mode] = {"runs": grid.runs_finished, "full_grid_runs": grid.full_grid_runs,
                        "yade_wall_s": grid.yade_wall_s_total, "campaign_wall_s": wall,
                        "cells_by_runs": {str(n): runs_per_cell.count(n)
                                          for n in sorted(set(runs_per_cell))}}
    result["runs_ratio"] = result["full"]["runs"] / max(result["adaptive"]["runs"], 1)
    result["yade_wall_ratio"] = (result["full"]["yade_wall_s"]
                                 / max(result["adaptive"]["yade_wall_s"], 1e-9))
    result["campaign_wall_ratio"] = (result["full"]["campaign_wall_s"]
                                     / max(result["adaptive"]["campaign_wall_s"], 1e-9))
    result["contour_0_5"] = contour_difference(summaries["full"], summaries["adaptive"])
    return result


def print_rock_fragility(r):
    print(f"\n11. Adaptive pulse grid against the full grid: {r['specimen']}, {r['pulses']}, "
          f"{r['members']} members x {r['headings']} headings, --jobs {r['jobs']} (load "
          f"average {r['load_average_1min']:.1f} at the start: wall times grow with it)")
    print(f"   {'sampling':<10}{'runs':>6}{'YADE wall s':>13}{'campaign wall s':>17}")
    for mode in ("full", "adaptive"):
        m = r[mode]
        print(f"   {mode:<10}{m['runs']:6d}{m['yade_wall_s']:13.1f}{m['campaign_wall_s']:17.1f}")
    print(f"   full / adaptive: {r['runs_ratio']:.2f}x runs, {r['yade_wall_ratio']:.2f}x YADE "
          f"wall time, {r['campaign_wall_ratio']:.2f}x campaign wall time")
    print("   adaptive cells by their runs: " + ", ".join(
        f"{count} with {n}" for n, count in r["adaptive"]["cells_by_runs"].items()))
    c = r["contour_0_5"]
    print(f"   P = 0.5 contour (PGA g) {'PGV/PGA s':>10}{'full':>7}{'adaptive':>10}"
          f"{'diff':>7}   full grid's Monte Carlo band")
    for row in c["rows"]:
        band = " - ".join(fmt(v, ".2f") for v in row["reference_band_g"])
        print(f"   {'':<23}{row['pgv_pga_s']:10.2f}{fmt(row['pga_g_reference'], '.2f'):>7}"
              f"{fmt(row['pga_g_other'], '.2f'):>10}{fmt(row['diff_g'], '+.2f'):>7}   {band}")
    print(f"   largest difference {fmt(c['max_abs_diff_g'], '.2f')} g; "
          f"{'every' if c['within_band'] else 'NOT every'} adaptive crossing inside the full "
          "grid's band")


# ---------------------------------------------------------------- 12. run wing against a revision
RUN_WING_REFERENCE = "e505b77"   # the code before the fragility wing was typed (fragility file,
                                 # one interpolation, one friction rule, RunParams passed whole)
RUN_WING_RECORDS = ("GM20", "RC-CCC")   # a near-field pulse record and a long far record
RUN_WING_REPEATS = 3


def run_wing(work, reference=RUN_WING_REFERENCE, records=RUN_WING_RECORDS,
             repeats=RUN_WING_REPEATS):
    """The ``run`` command (record processing, scene, YADE, summary) of this checkout and of
    the git revision ``reference`` side by side: each record's twin-model run once untimed
    per tree (caches), then ``repeats`` times, the two trees alternating so that a change
    in the machine's load meets both.  Per tree and record: median command wall s, median
    YADE wall s (summary.json), outcomes; ``ratio`` = this checkout / reference."""
    tree = work / f"reference_{reference}"
    tree.mkdir()
    archive = subprocess.run(["git", "-C", str(PROJECT), "archive", reference],
                             capture_output=True)
    if archive.returncode:
        return {"reference": reference, "skipped": archive.stderr.decode().strip()[:200]}
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive.stdout, check=True)
    trees = {"this": PROJECT, "reference": tree}

    def one(name, record, out):
        started = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pipeline", "run", "--record", record,
                        "--out", str(out)], cwd=trees[name], check=True, capture_output=True,
                       env={**os.environ, "PYTHONPATH": str(trees[name])})
        wall = time.perf_counter() - started
        summary = json.loads((out / "summary.json").read_text())
        return wall, summary

    rows = []
    for record in records:
        row = {"record": record}
        for name in trees:
            one(name, record, work / f"run_wing_{name}_{record}_warm")
        samples = {name: [] for name in trees}
        for k in range(repeats):
            for name in (trees if k % 2 == 0 else reversed(list(trees))):
                samples[name].append(one(name, record, work / f"run_wing_{name}_{record}_{k}"))
        for name, runs in samples.items():
            summary = runs[-1][1]
            row[name] = {"command_wall_s": float(np.median([w for w, _ in runs])),
                         "yade_wall_s": float(np.median([s["wall_s"] for _, s in runs])),
                         "simulated_s": summary["simulated_s"],
                         "columns": {c["column"]: (c["toppled"], c["downfall_azimuth_deg"])
                                     for c in summary["columns"]}}
        row["command_ratio"] = row["this"]["command_wall_s"] / row["reference"]["command_wall_s"]
        row["yade_ratio"] = row["this"]["yade_wall_s"] / row["reference"]["yade_wall_s"]
        rows.append(row)
    return {"reference": reference, "repeats": repeats, "records": rows,
            "load_average_1min": os.getloadavg()[0]}


def print_run_wing(r):
    if "skipped" in r:
        print(f"\n12. Run wing against {r['reference']}: skipped ({r['skipped']})")
        return
    print(f"\n12. The run command against revision {r['reference']}, twin model, median of "
          f"{r['repeats']} alternating runs (load average {r['load_average_1min']:.1f} at the end)")
    print(f"   {'record':<10}{'tree':<11}{'command s':>10}{'YADE s':>9}{'simulated s':>13}"
          "   outcomes (toppled, azimuth deg)")
    for row in r["records"]:
        for name in ("this", "reference"):
            m = row[name]
            outcomes = "; ".join(f"{c} {t} {fmt(a)}" for c, (t, a) in m["columns"].items())
            print(f"   {row['record']:<10}{name:<11}{m['command_wall_s']:10.2f}"
                  f"{m['yade_wall_s']:9.2f}{m['simulated_s']:13.2f}   {outcomes}")
        print(f"   {'':<10}this / reference: command {row['command_ratio']:.3f}x, "
              f"YADE {row['yade_ratio']:.3f}x")


def only_section(out, key, measure, show):
    """Run one section (``measure(work)``), print it and add it under ``key`` to the
    bench.json in ``out``; exit status 0."""
    path = out / "bench.json"
    result = json.loads(path.read_text()) if path.is_file() else {}
    with tempfile.TemporaryDirectory(prefix="bench_yade_") as tmp:
        result[key] = measure(Path(tmp))
    show(result[key])
    write_json(path, result)
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="short runs, no convergence table (development)")
    parser.add_argument("--duration", type=float, default=None,
                        help="simulated s of shaking for the timing table and the still/shaking "
                        "scenes (default 20, quick 3)")
    parser.add_argument("--skip-peer", action="store_true", help="no MuJoCo comparison")
    parser.add_argument("--skip-convergence", action="store_true")
    parser.add_argument("--out", type=Path, default=RESULTS_DIR / "bench")
    parser.add_argument("--only-rock-fragility", action="store_true",
                        help="run only section 11 (adaptive against full pulse grid) and add "
                        "it to the bench.json in --out")
    parser.add_argument("--only-colonnade", action="store_true",
                        help="run only section 13 (a colonnade beside its columns apart) and "
                        "add it to the bench.json in --out")
    parser.add_argument("--only-run-wing", action="store_true",
                        help="run only section 12 (the run command against revision "
                        f"{RUN_WING_REFERENCE}) and add it to the bench.json in --out")
    parser.add_argument("--only-hazard", action="store_true",
                        help="run only section 14 (constrain at a study's size, a rate "
                        "density per branch) and add it to the bench.json in --out")
    args = parser.parse_args(argv)
    # SIGTERM as an exit, so that the temporary work directory is removed
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    colonnade_s = args.duration or (1.0 if args.quick else 5.0)

    def colonnade(work):
        return colonnade_cost(work, shaking_motion(colonnade_s), colonnade_s)
    if args.only_hazard:
        return only_section(args.out, "hazard", hazard_cost, print_hazard_cost)
    if args.only_colonnade:
        return only_section(args.out, "colonnade", colonnade, print_colonnade_cost)
    if args.only_run_wing:
        return only_section(args.out, "run_wing", run_wing, print_run_wing)
    if args.only_rock_fragility:
        return only_section(args.out, "rock_fragility_adaptive", rock_fragility_adaptive,
                            print_rock_fragility)
    shaking_s = args.duration or (3.0 if args.quick else 20.0)
    started = time.perf_counter()
    result = {"quick": args.quick}
    with tempfile.TemporaryDirectory(prefix="bench_yade_") as tmp:
        work = Path(tmp)
        result["engine_timing"] = engine_timing(work, shaking_s)
        print_timing(result["engine_timing"])
        result["speed"] = speed(work, shaking_s)
        print_speed(result["speed"])
        result["after_motion"] = after_motion(work, 5.0 if args.quick else 20.0)
        print_after(result["after_motion"])
        if args.skip_peer:
            result["peer"] = None
        else:
            try:
                import mujoco  # noqa: F401
            except ImportError:
                result["peer"] = None
                print("\n4. Peer skipped: MuJoCo is not installed "
                      "(.venv/bin/python -m pip install mujoco)")
            else:
                amplitudes = [PULSE["amplitude"]] + ([] if args.quick else [STRONG_AMPLITUDE])
                result["peer"] = peer(work, result["speed"]["startup_s"], amplitudes)
                print_peer(result["peer"])
        if not (args.quick or args.skip_convergence):
            result["convergence"] = convergence(work)
            print_convergence(result["convergence"])
            plot_convergence(result["convergence"], args.out / "convergence.png")
        result["parallel"] = parallel(work, 4, 1.0 if args.quick else 3.0)
        print_parallel(result["parallel"])
        result["quiet_motion"] = quiet_motion(work, QUIET_RECORDS[:1] if args.quick
                                              else QUIET_RECORDS)
        print_quiet(result["quiet_motion"])
        result["two_x"] = two_x(work, shaking_s)
        print_two_x(result["two_x"])
        result["time_step_limit"] = time_step_limit(work, 1.0 if args.quick else STABILITY_S)
        print_time_step_limit(result["time_step_limit"])
        result["ctrl_c"] = ctrl_c(work, 1 if args.quick else 3)
        print_ctrl_c(result["ctrl_c"])
        result["rock_fragility_adaptive"] = rock_fragility_adaptive(work)
        print_rock_fragility(result["rock_fragility_adaptive"])
        result["run_wing"] = run_wing(work, repeats=1 if args.quick else RUN_WING_REPEATS)
        print_run_wing(result["run_wing"])
        result["colonnade"] = colonnade(work)
        print_colonnade_cost(result["colonnade"])
        result["hazard"] = hazard_cost(work)
        print_hazard_cost(result["hazard"])
    result["bench_wall_s"] = time.perf_counter() - started
    write_json(args.out / "bench.json", result)
    print(f"\nbench: {result['bench_wall_s']:.0f} s wall; wrote {args.out / 'bench.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
