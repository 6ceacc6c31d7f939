"""The stiff-solver study: which ground-truth solver stays accurate on the stiff spring chain, at what cost.

``stiff_study(system="stiff_chain", n_ics=4, t_end=10.0, cases=QUICK, verlet_dt=VERLET_DT) -> DataFrame`` with one
row per (solver, rtol): solver, rtol, dt (fixed-step rows), wall_s (after compilation), n_steps (mean
accepted steps per trajectory), state_err (max |z(T) - z_ref(T)| over trajectories, z = (q, qdot)),
energy_err (max over trajectories and time of |E(t) - E(0)| / |E(0)|), and the solver `pick_solver`
chooses (column `picked`). The reference is dopri8 at rtol = atol = 1e-13. Besides the diffrax solvers
(`systems.trajectories.SOLVERS`) it times a fixed-step Stoermer-Verlet (symplectic; valid here because
the chain's mass matrix is constant) in NumPy. ``write_study(folder, system)`` (`lagbench stiff`) runs it and
writes FOLDER/solvers.csv and FOLDER/choice.json.
"""
from __future__ import annotations

import time

import numpy as np
import pandas as pd

from lagbench import systems
from lagbench.systems.stiffness import pick_solver
from lagbench.systems.trajectories import integrate

QUICK = [("tsit5", 1e-6), ("tsit5", 1e-10), ("dopri5", 1e-6), ("dopri5", 1e-10), ("dopri8", 1e-6),
         ("dopri8", 1e-8), ("dopri8", 1e-10), ("kvaerno5", 1e-6), ("kvaerno5", 1e-8), ("kvaerno5", 1e-10)]
VERLET_DT = (1e-3, 1e-4)


def _verlet(s, q0, v0, t, dt):
    """Fixed-step velocity Verlet (kick-drift-kick) on q'' = a(q); states saved on the grid ``t``."""
    q, v = q0.copy(), v0.copy()
    out_q, out_v = [q.copy()], [v.copy()]
    n = 0
    for j in range(1, t.size):
        k = max(1, int(np.ceil((t[j] - t[j - 1]) / dt - 1e-9)))
        h = (t[j] - t[j - 1]) / k
        a = s.acceleration(q, v)
        for _ in range(k):
            v = v + 0.5 * h * a
            q = q + h * v
            a = s.acceleration(q, v)
            v = v + 0.5 * h * a
        n += k
        out_q.append(q.copy())
        out_v.append(v.copy())
    return np.stack(out_q, 1), np.stack(out_v, 1), n


def _row(s, name, rtol, dt, wall, steps, q, qd, ref):
    z, zr = np.concatenate([q[:, -1], qd[:, -1]], -1), np.concatenate([ref[0][:, -1], ref[1][:, -1]], -1)
    e = s.energy(q, qd)
    drift = np.abs(e - e[:, :1]) / np.abs(e[:, :1])
    return {"solver": name, "rtol": rtol, "dt": dt, "wall_s": wall, "n_steps": float(np.mean(steps)),
            "state_err": float(np.max(np.abs(z - zr))), "energy_err": float(np.max(drift))}


def stiff_study(system: str = "stiff_chain", n_ics: int = 4, t_end: float = 10.0,
                cases=QUICK, verlet_dt=VERLET_DT) -> pd.DataFrame:
    s = systems.get(system)
    st = s.sample_states(n_ics, 0)
    q0, v0 = st["q"], st["qdot"]
    t = np.linspace(0.0, t_end, 101)
    ref = integrate(s, q0, v0, t, solver="dopri8", rtol=1e-13, atol=1e-13)
    choice = pick_solver(s, q0, v0, t_end)
    rows = []
    for name, rtol in cases:
        integrate(s, q0, v0, t * 1e-6, solver=name, rtol=rtol, atol=rtol)   # compile (same shapes, few steps)
        t0 = time.perf_counter()
        q, qd, steps = integrate(s, q0, v0, t, solver=name, rtol=rtol, atol=rtol, return_steps=True)
        rows.append(_row(s, name, rtol, np.nan, time.perf_counter() - t0, steps, q, qd, ref))
    for dt in verlet_dt:
        t0 = time.perf_counter()
        q, qd, n = _verlet(s, q0, v0, t, dt)
        rows.append(_row(s, "verlet", np.nan, dt, time.perf_counter() - t0, n, q, qd, ref))
    df = pd.DataFrame(rows)
    df["picked"] = (df["solver"] == choice.solver) & np.isclose(df["rtol"], choice.rtol, rtol=1e-9, atol=0.0)
    df.attrs.update(stiffness_ratio=choice.stiffness_ratio, reason=choice.reason)
    return df


def write_study(folder, system: str = "stiff_chain") -> pd.DataFrame:
    from lagbench.files.results import write_csv, write_json

    df = stiff_study(system=system)
    write_csv(folder / "solvers.csv", df)
    write_json(folder / "choice.json", {"system": system, **{k: (float(v) if isinstance(v, float) else v)
                                                           for k, v in df.attrs.items()}})
    return df
