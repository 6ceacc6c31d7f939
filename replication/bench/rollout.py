"""Rollout study on the double pendulum ground truth: wall time against final-time state and energy error.

`rollout_rows(sizes) -> rows {system, solver, rtol, dt, kind, wall_s, state_err, energy_err, n_ics, t_end}`:
  kind "truth": diffrax Tsit5 / Dopri5 / Dopri8 (`sizes.rollout_solvers`; adaptive, PID, atol = rtol) at `sizes.rollout_rtols`
    (`systems.trajectories.integrate`), and a fixed-step classical RK4 (jax.lax.scan over the generated
    JAX accelerations; solver "rk4", rtol empty, `dt` the step) at `sizes.rollout_dts`;
  kind "chaos_floor": the reference re-run from initial states perturbed by 1e-12 (relative): the state
    error any integrator must reach before its own error is distinguishable from chaotic divergence.
Reference: Dopri8 at rtol = atol = 1e-13. `rollout_ics` initial states: angles U(-pi, pi), velocities
U(-1, 1), integrated for `rollout_t_end`. state_err: median over initial states of
|z(T) - z_ref(T)| / |z_ref(T)|, z = (q, qdot); energy_err: mean |E(T) - E(0)| / 29.4 (the double
pendulum claims' energy scale). wall_s: the fastest of two calls after one compiling call, all states
in one vmapped call.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

import systems
from replication.bench.timing import best_time
from systems.trajectories import integrate

REF_RTOL = 1e-13
ENERGY_SCALE = 29.4
CHAOS_EPS = 1e-12


def _ics(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (n, 2)), rng.uniform(-1.0, 1.0, (n, 2))


def _rk4(system, dt, n_steps):
    dof = system.dof

    def field(y):
        return jnp.concatenate([y[dof:], system.acceleration(y[:dof], y[dof:], backend="jax")])

    def one(y0):
        def body(y, _):
            k1 = field(y)
            k2 = field(y + 0.5 * dt * k1)
            k3 = field(y + 0.5 * dt * k2)
            k4 = field(y + dt * k3)
            return y + (dt / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4), None
        return jax.lax.scan(body, y0, None, length=n_steps)[0]
    return jax.jit(jax.vmap(one))


def _errors(system, zT, z_ref, e0):
    dof = system.dof
    state = np.linalg.norm(zT - z_ref, axis=-1) / np.linalg.norm(z_ref, axis=-1)
    e_T = system.energy(zT[:, :dof], zT[:, dof:], backend="numpy")
    return float(np.median(state)), float(np.mean(np.abs(e_T - e0)) / ENERGY_SCALE)


def rollout_rows(sizes, progress=None) -> list[dict]:
    s = systems.get("double_pendulum")
    q0, qd0 = _ics(sizes.rollout_ics)
    t = np.array([0.0, sizes.rollout_t_end])
    e0 = s.energy(q0, qd0, backend="numpy")

    def final(q, qd, solver, rtol):
        qs, qds = integrate(s, q, qd, t, rtol=rtol, atol=rtol, solver=solver)
        return np.concatenate([qs[:, -1], qds[:, -1]], -1)
    z_ref = final(q0, qd0, "dopri8", REF_RTOL)
    base = {"system": "double_pendulum", "n_ics": sizes.rollout_ics, "t_end": sizes.rollout_t_end}
    rows = []
    for solver in sizes.rollout_solvers:
        for rtol in sizes.rollout_rtols:
            zT = final(q0, qd0, solver, rtol)
            wall = best_time(lambda solver=solver, rtol=rtol: final(q0, qd0, solver, rtol), min_time=0.0)
            se, ee = _errors(s, zT, z_ref, e0)
            rows.append({**base, "solver": solver, "rtol": rtol, "dt": None, "kind": "truth", "wall_s": wall,
                         "state_err": se, "energy_err": ee})
            if progress:
                progress.update(1)
    y0 = jnp.asarray(np.concatenate([q0, qd0], -1))
    for dt in sizes.rollout_dts:
        n_steps = int(round(sizes.rollout_t_end / dt))
        f = _rk4(s, sizes.rollout_t_end / n_steps, n_steps)
        zT = np.asarray(f(y0))
        wall = best_time(lambda f=f: jax.block_until_ready(f(y0)), min_time=0.0)
        se, ee = _errors(s, zT, z_ref, e0)
        rows.append({**base, "solver": "rk4", "rtol": None, "dt": dt, "kind": "truth", "wall_s": wall,
                     "state_err": se, "energy_err": ee})
        if progress:
            progress.update(1)
    zp = final(q0 * (1 + CHAOS_EPS), qd0 * (1 + CHAOS_EPS), "dopri8", REF_RTOL)
    wall = best_time(lambda: final(q0, qd0, "dopri8", REF_RTOL), min_time=0.0)
    se, ee = _errors(s, zp, z_ref, e0)
    rows.append({**base, "solver": "dopri8", "rtol": REF_RTOL, "dt": None, "kind": "chaos_floor", "wall_s": wall,
                 "state_err": se, "energy_err": ee})
    if progress:
        progress.update(1)
    return rows


def n_rollout_cases(sizes) -> int:
    return len(sizes.rollout_solvers) * len(sizes.rollout_rtols) + len(sizes.rollout_dts) + 1
