"""Speed and convergence benchmark of the YADE scene (``make bench``).

Prints and writes results/bench/bench.json and results/bench/convergence.png:
- simulated seconds per wall second of the twin model (7 drums + monolith)
  driven by a record, with and without YADE's start-up;
- cost per step of a still scene, the inertial drive (gravity table, default)
  and the per-step kinematic drive (pedestal velocity from Python);
- convergence of the outcome (toppled, downfall azimuth) in the time step
  factor and in the number of rim contact points for a strong directed pulse.
"""
import argparse
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from pipeline import RESULTS_DIR, outcome, scenario
from pipeline.files import save_figure, write_json


def pulse_motion(azimuth_deg=30.0, amplitude=5.0, period=1.0, duration=8.0, dt=0.005):
    """One-sine acceleration pulse (m/s^2) along an azimuth, integrated exactly."""
    t = np.arange(0.0, duration, dt)
    w = 2 * math.pi / period
    on = t < period
    acc = np.where(on, amplitude * np.sin(w * t), 0.0)
    vel = np.where(on, amplitude / w * (1 - np.cos(w * t)), 0.0)
    disp = np.where(on, amplitude / w * (t - np.sin(w * t) / w), amplitude / w * period)
    u = np.array([math.sin(math.radians(azimuth_deg)), math.cos(math.radians(azimuth_deg)), 0.0])
    return {"dt": dt, "acc": acc[:, None] * u, "vel": vel[:, None] * u, "disp": disp[:, None] * u}


def shaking_motion(duration=20.0, dt=0.005, seed=1):
    """Band-limited random 3-component shaking (~0.3 g horizontal), for timing only."""
    from scipy.signal import butter, sosfiltfilt
    rng = np.random.default_rng(seed)
    sos = butter(4, [0.5, 8.0], btype="band", fs=1 / dt, output="sos")
    acc = sosfiltfilt(sos, rng.standard_normal((int(duration / dt), 3)), axis=0)
    acc *= np.array([3.0, 3.0, 1.5]) / np.abs(acc).max(axis=0)
    disp = np.cumsum(np.cumsum(acc, axis=0) * dt, axis=0) * dt
    return {"dt": dt, "acc": acc, "disp": disp}


def timed_run(workdir, columns, motion, t_max, **options):
    params = scenario.scene_params(columns=columns, t_max=t_max, rest_duration_s=1e9, **options)
    scenario.write_scenario(workdir, params, motion)
    traj = scenario.run_yade(workdir)
    return traj, traj["wall_s"], len(traj["t"])


def speed(workdir, duration):
    twin = scenario.column_specs("both")
    motion = shaking_motion(duration)
    _, startup, _ = timed_run(workdir / "startup", twin, motion, t_max=1e-3)
    rows = {}
    for label, motion_used, options in [("still", None, {}),
                                        ("inertial drive", motion, {"drive": "inertial"}),
                                        ("kinematic drive (per-step Python)", motion,
                                         {"drive": "kinematic"})]:
        traj, wall, _ = timed_run(workdir / label.split()[0], twin, motion_used, duration, **options)
        steps = traj["t"][-1] / traj["dt"]
        rows[label] = {"wall_s": wall, "simulated_s": float(traj["t"][-1]),
                       "us_per_step": 1e6 * (wall - startup) / steps,
                       "sim_s_per_wall_s": float(traj["t"][-1]) / (wall - startup),
                       "sim_s_per_wall_s_with_startup": float(traj["t"][-1]) / wall}
    still = rows["still"]["us_per_step"]
    for row in rows.values():
        row["cost_vs_still"] = row["us_per_step"] / still
    return {"startup_s": startup, "time_step_s": traj["dt"], "scenes": rows}


def convergence(workdir):
    """Outcome of a strong pulse at azimuth 30 deg against time step and rim points."""
    motion = pulse_motion()
    twin = scenario.column_specs("both")
    cases = [("dt_factor", f) for f in (0.075, 0.15, 0.3)] + [("rim_points", n) for n in (8, 16, 32)]
    rows = []
    for key, value in cases:
        traj, wall, _ = timed_run(workdir / f"{key}_{value}", twin, motion, 8.0, **{key: value})
        for col in outcome.column_outcomes(traj):
            rows.append({"parameter": key, "value": value, "column": col["column"],
                         "toppled": col["toppled"], "downfall_azimuth_deg": col["downfall_azimuth_deg"],
                         "impact_time_s": col["impact_time_s"], "wall_s": wall})
    return rows


def plot_convergence(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, key in zip(axes, ("dt_factor", "rim_points")):
        for column, marker in (("drums", "o"), ("monolithic", "s")):
            sel = [r for r in rows if r["parameter"] == key and r["column"] == column]
            ax.plot([r["value"] for r in sel],
                    [np.nan if r["downfall_azimuth_deg"] is None else r["downfall_azimuth_deg"]
                     for r in sel], marker=marker, label=column)
        ax.set_xscale("log")
        ax.set_xlabel({"dt_factor": "time step factor f (dt = f sqrt(m/kn))",
                       "rim_points": "contact spheres per rim"}[key])
        ax.set_ylabel("downfall azimuth (deg)")
        ax.set_ylim(0, 360)
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("Outcome convergence: one-sine pulse 5 m/s^2, 1 s, toward N30E")
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=20.0, help="simulated s per timing run")
    parser.add_argument("--skip-convergence", action="store_true")
    parser.add_argument("--out", type=Path, default=RESULTS_DIR / "bench")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        result = {"speed": speed(work, args.duration)}
        print(f"YADE start-up {result['speed']['startup_s']:.2f} s, "
              f"time step {result['speed']['time_step_s'] * 1e6:.0f} us (twin model, 7 drums)")
        print(f"{'scene':<36}{'us/step':>9}{'x still':>9}{'sim s/wall s':>14}{'incl. start-up':>16}")
        for label, row in result["speed"]["scenes"].items():
            print(f"{label:<36}{row['us_per_step']:9.1f}{row['cost_vs_still']:9.2f}"
                  f"{row['sim_s_per_wall_s']:14.2f}{row['sim_s_per_wall_s_with_startup']:16.2f}")
        if not args.skip_convergence:
            rows = convergence(work)
            result["convergence"] = rows
            print(f"\n{'parameter':<12}{'value':>7}{'column':>12}{'toppled':>9}{'azimuth':>9}"
                  f"{'impact s':>10}")
            for r in rows:
                az = "-" if r["downfall_azimuth_deg"] is None else f"{r['downfall_azimuth_deg']:.1f}"
                ti = "-" if r["impact_time_s"] is None else f"{r['impact_time_s']:.2f}"
                print(f"{r['parameter']:<12}{r['value']:>7}{r['column']:>12}{str(r['toppled']):>9}"
                      f"{az:>9}{ti:>10}")
            plot_convergence(rows, args.out / "convergence.png")
    write_json(args.out / "bench.json", result)
    print(f"\nwrote {args.out / 'bench.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
