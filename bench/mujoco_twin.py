"""The paper's twin column (7 drums + monolith) in MuJoCo, as a speed and outcome peer
of the YADE model for ``make bench``.

Units: metres, seconds, kilograms, m/s^2, degrees for azimuths.  Frame: the pedestal
frame (x East, y North, z Up, pedestal top face z = 0).  The pedestal stays still and
the ground acceleration enters as a time-varying gravity (-a_E, -a_N, -9.81 - a_U), as
in the project's inertial drive.  Outcome definitions follow pipeline/outcome.py: a
column has toppled when one of its bodies strikes the pedestal other than by its base
(any rim of a drum above the bottom one, the top rim of the bottom drum or monolith);
the downfall azimuth points from the column's initial axis to the mass-weighted mean of
the struck bodies' centres at their first strike, clockwise from North.

Run ``python bench/mujoco_twin.py`` for the one-sine pulse at N30E and a still-stack check.
Needs the PyPI package ``mujoco`` (>= 3).
"""
import math
import sys
import time

import numpy as np

G = 9.81                     # m/s^2
STRIKE_TOLERANCE_M = 0.02    # a rim this close to the pedestal top has struck it
REST_VELOCITY = 0.005        # m/s (angular speed x REST_LENGTH counts as a speed)
REST_LENGTH = 1.0            # m
REST_DURATION_S = 0.5
CHECK_INTERVAL_S = 0.01      # s: strike and rest checks, as the project's 100 Hz records

# Contact model (MuJoCo docs: "Solver parameters", "Contact parameters", "Preventing
# slip").  solref (timeconst s, dampratio): stiff, critically damped contacts the 0.5 ms
# step still resolves (the docs ask timeconst >= 2 x timestep); solimp (dmin, dmax,
# width m, midpoint, power): impedance 0.95 at touch, 0.99 from 1 mm of penetration.
# With these and multiccd (several points on flat drum faces) a still stack settles by
# ~0.03 mm; MuJoCo's default solref 0.02 s lets it creep ~4 mm in 5 s, and without
# multiccd ~3 mm.
# condim 4 adds torsional friction (TORSION_M, m: torque = TORSION_M x normal force):
# with condim 3 a drum pivoting on one rim point has no resistance to spinning about
# the contact normal and the rocking drums spin up and veer off the pulse axis.
SOLREF = (0.002, 1.0)
SOLIMP = (0.95, 0.99, 0.001, 0.5, 2)
CONDIM = 4
TORSION_M = 0.005


def one_sine_pulse(azimuth_deg=30.0, amplitude=5.0, period=1.0, duration=8.0, dt=0.005):
    """One-sine acceleration pulse a(t) = amplitude sin(2 pi t / period) for t < period,
    zero after, along a horizontal azimuth (deg clockwise from North).

    Returns (acc, dt): acc (n, 3) in m/s^2, columns East, North, Up; dt in s."""
    t = np.arange(0.0, duration, dt)
    a = np.where(t < period, amplitude * np.sin(2 * math.pi * t / period), 0.0)
    az = math.radians(azimuth_deg)
    return a[:, None] * np.array([math.sin(az), math.cos(az), 0.0]), dt


def twin_mjcf(timestep_s=5e-4, hd=6.0, height=3.5, n_drums=7, density=2960.0, mu=0.7,
              offset_m=1.5, multiccd=True, condim=CONDIM, solref=SOLREF, solimp=SOLIMP):
    """MJCF text of the twin model: drums at x = -offset_m, monolith at x = +offset_m,
    on a pedestal plane at z = 0.

    Collision bits (contype/conaffinity) let each column touch only itself and the
    pedestal: pedestal 1/0, drums 2/3 (drum-drum and drum-pedestal), monolith 0/1."""
    r = height / hd / 2
    hh = height / n_drums / 2
    sol = (f'friction="{mu} {TORSION_M} 0.0001" condim="{condim}" '
           f'solref="{solref[0]} {solref[1]}" solimp="{" ".join(map(str, solimp))}"')
    bodies = [f'<body name="drum{i}" pos="{-offset_m} 0 {(2 * i + 1) * hh}"><freejoint/>'
              f'<geom type="cylinder" size="{r} {hh}" density="{density}" contype="2" '
              f'conaffinity="3" {sol}/></body>' for i in range(n_drums)]
    bodies.append(f'<body name="monolith" pos="{offset_m} 0 {height / 2}"><freejoint/>'
                  f'<geom type="cylinder" size="{r} {height / 2}" density="{density}" '
                  f'contype="0" conaffinity="1" {sol}/></body>')
    body_lines = "\n    ".join(bodies)
    return f"""<mujoco model="twin column">
  <option timestep="{timestep_s}" gravity="0 0 {-G}" integrator="implicitfast" cone="elliptic">
    <flag multiccd="{'enable' if multiccd else 'disable'}"/>
  </option>
  <worldbody>
    <geom name="pedestal" type="plane" size="0 0 1" contype="1" conaffinity="0" {sol}/>
    {body_lines}
  </worldbody>
</mujoco>"""


def _rims(xpos, xmat, hh, r):
    """Lowest z (m) of the bottom and top rim circles of each body: (n, 2)."""
    u = xmat.reshape(-1, 3, 3)[:, :, 2]
    uz = np.clip(u[:, 2], -1.0, 1.0)
    spread = r * np.sqrt(1.0 - uz ** 2)
    return np.stack([xpos[:, 2] - hh * uz - spread, xpos[:, 2] + hh * uz - spread], axis=1), u


def run_twin(acc, dt, duration_s, timestep_s=5e-4, hd=6.0, height=3.5, n_drums=7,
             density=2960.0, mu=0.7, offset_m=1.5, **model_options):
    """Shake the twin model with ground acceleration ``acc`` ((n, 3) m/s^2, E/N/U, sampled
    every ``dt`` s, linearly interpolated, zero after the record) for up to ``duration_s``.

    Stops early once every standing body has rested (speed < 5 mm/s) for 0.5 s after the
    motion ends or after every column has fallen (bodies tilted > 60 deg may roll on).
    ``model_options`` go to twin_mjcf (multiccd, condim, solref, solimp).
    Gravity is set before each step from a table interpolated ahead of the loop;
    strikes and rest are checked every CHECK_INTERVAL_S.
    Returns sim_s, wall_s (stepping loop only), sim_s_per_wall_s, setup_s, timestep_s
    and per column: toppled, downfall_azimuth_deg, impact_time_s."""
    import mujoco
    t0 = time.perf_counter()
    model = mujoco.MjModel.from_xml_string(
        twin_mjcf(timestep_s, hd, height, n_drums, density, mu, offset_m, **model_options))
    data = mujoco.MjData(model)
    r = height / hd / 2
    hh = np.array([height / n_drums / 2] * n_drums + [height / 2])
    column = np.array([0] * n_drums + [1])                 # 0 drums, 1 monolith
    is_base = np.array([i == 0 for i in range(n_drums)] + [True])
    mass = model.body_mass[1:].copy()
    origin = np.array([[-offset_m, 0.0], [offset_m, 0.0]])
    # gravity per step, interpolated ahead of the loop (zero motion after the record)
    acc = np.asarray(acc, float)
    if acc.ndim != 2 or acc.shape[1] != 3 or not np.isfinite(acc).all():
        raise ValueError(f"acc must be a finite (n, 3) array, got shape {acc.shape}")
    n_steps = int(round(duration_s / timestep_s))
    t_steps = np.arange(n_steps) * timestep_s
    t_rec = np.arange(len(acc)) * dt
    gravity = np.stack([-np.interp(t_steps, t_rec, acc[:, k], right=0.0) for k in range(3)], 1)
    gravity[:, 2] -= G
    motion_end = len(acc) * dt
    check_every = max(1, int(round(CHECK_INTERVAL_S / timestep_s)))
    strike_time = np.full(len(mass), np.nan)
    strike_xy = np.zeros((len(mass), 2))
    rest_since = None
    setup_s = time.perf_counter() - t0

    opt_gravity, xpos, xmat = model.opt.gravity, data.xpos, data.xmat
    qvel = data.qvel.reshape(-1, 6)   # free joints: linear (world), angular (body frame)
    step = 0
    t1 = time.perf_counter()
    while step < n_steps:
        opt_gravity[:] = gravity[step]
        mujoco.mj_step(model, data)
        step += 1
        if step % check_every:
            continue
        low, u = _rims(xpos[1:], xmat[1:], hh, r)
        struck = np.where(is_base, low[:, 1], low.min(axis=1)) <= STRIKE_TOLERANCE_M
        new = struck & np.isnan(strike_time)
        if new.any():
            strike_time[new] = data.time
            strike_xy[new] = xpos[1:][new, :2] - origin[column[new]]
        lying = u[:, 2] < 0.5
        speed = np.maximum(np.linalg.norm(qvel[:, :3], axis=1),
                           np.linalg.norm(qvel[:, 3:], axis=1) * REST_LENGTH)
        fallen = [lying[column == c].any() for c in (0, 1)]
        if (speed[~lying] < REST_VELOCITY).all() and (data.time > motion_end or all(fallen)):
            rest_since = data.time if rest_since is None else rest_since
            if data.time - rest_since >= REST_DURATION_S:
                break
        else:
            rest_since = None
    wall_s = time.perf_counter() - t1

    columns = []
    for c, name in enumerate(("drums", "monolithic")):
        hit = (column == c) & ~np.isnan(strike_time)
        entry = {"column": name, "toppled": bool(hit.any()), "downfall_azimuth_deg": None,
                 "impact_time_s": None}
        if hit.any():
            centre = mass[hit] @ strike_xy[hit] / mass[hit].sum()
            entry["downfall_azimuth_deg"] = float(np.degrees(np.arctan2(*centre)) % 360.0)
            entry["impact_time_s"] = float(strike_time[hit].min())
        columns.append(entry)
    return {"sim_s": float(data.time), "wall_s": wall_s, "sim_s_per_wall_s": data.time / wall_s,
            "setup_s": setup_s, "timestep_s": timestep_s, "columns": columns}


def still_check(duration_s=5.0, timestep_s=5e-4, **model_options):
    """Zero ground motion for duration_s: largest body displacement (m) and tilt (deg)."""
    import mujoco
    model = mujoco.MjModel.from_xml_string(twin_mjcf(timestep_s, **model_options))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    start = data.xpos[1:].copy()
    mujoco.mj_step(model, data, nstep=int(round(duration_s / timestep_s)))
    move = float(np.linalg.norm(data.xpos[1:] - start, axis=1).max())
    uz = np.clip(data.xmat[1:, 8], -1.0, 1.0)
    return move, float(np.degrees(np.arccos(uz)).max())


def main():
    import mujoco
    print(f"MuJoCo {mujoco.__version__}")
    move, tilt = still_check()
    ok = move < 1e-3 and tilt < 0.05
    print(f"still stack, 5 s: max displacement {move * 1e3:.3f} mm, max tilt {tilt:.4f} deg "
          f"-> {'OK' if ok else 'FAILED'} (limits 1 mm, 0.05 deg)")
    acc, dt = one_sine_pulse(30.0, 5.0, 1.0, 8.0)
    res = run_twin(acc, dt, 8.0)
    print(f"one-sine pulse 5 m/s^2, 1 s, toward N30E; time step {res['timestep_s'] * 1e3:.1f} ms")
    print(f"{'column':<12}{'toppled':>9}{'azimuth':>9}{'off axis':>10}{'impact s':>10}")
    for c in res["columns"]:
        az, off, ti = "-", "-", "-"
        if c["toppled"]:
            az, ti = f"{c['downfall_azimuth_deg']:.1f}", f"{c['impact_time_s']:.2f}"
            # angle to the pulse axis, either sense (toward 30 or toward 210 deg)
            off = f"{abs((c['downfall_azimuth_deg'] - 30.0 + 90.0) % 180.0 - 90.0):.1f}"
        print(f"{c['column']:<12}{str(c['toppled']):>9}{az:>9}{off:>10}{ti:>10}")
    print(f"simulated {res['sim_s']:.2f} s in {res['wall_s']:.2f} s wall "
          f"({res['sim_s_per_wall_s']:.1f} sim s per wall s; setup {res['setup_s']:.3f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
