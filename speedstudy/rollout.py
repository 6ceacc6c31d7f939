"""Rollout study on the double pendulum: wall time against final-time state and energy error, for the
ground truth and for learned models.

`rollout_rows(sizes, progress, trained_from, notes) -> rows {system, solver, rtol, dt, kind, model, source,
wall_s, state_err, energy_err, n_ics, t_end}`:
  kind "truth": diffrax Tsit5 / Dopri5 / Dopri8 (`sizes.rollout_solvers`; adaptive, PID, atol = rtol,
    at most TRUTH_MAX_STEPS steps) at `sizes.rollout_rtols` (`field_solver` on the generated JAX accelerations,
    the same code as the learned rows; rtol is traced, so one compilation per solver), and a fixed-step classical RK4 (`replication.evaluation.rollout.rk4_scan`
    over the generated JAX accelerations; solver "rk4", rtol empty, `dt` the step) at `sizes.rollout_dts`;
  kind "chaos_floor": the reference re-run from initial states perturbed by 1e-12 (relative): the state
    error any integrator must reach before its own error is distinguishable from chaotic divergence.
Reference: Dopri8 at rtol = atol = 1e-13. `rollout_ics` initial states: angles U(-pi, pi), velocities
U(-1, 1), integrated for `rollout_t_end`. state_err: median over initial states of
|z(T) - z_ref(T)| / |z_ref(T)|, z = (q, qdot); energy_err: mean |E(T) - E(0)| / 29.4 (the double
pendulum claims' energy scale). wall_s: the fastest of up to three calls, all states in one vmapped call
(`timed_solve`: the compiling call is never timed; calls of 1 s or more are not repeated).
  kind "learned" / "learned_tiny": a learned double-pendulum model (LNN and baseline) as the vector field,
    same solvers and tolerances (`speedstudy.learned`); errors against the same true reference,
    so they hold the model's error plus the solver's. source says where the parameters came from.
"""
from __future__ import annotations

import time

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from lagbench import systems
from lagbench.replication.claims.double_pendulum import ENERGY_SCALE
from lagbench.replication.evaluation.rollout import rk4_scan
from lagbench.speedstudy.timing import best_time
from lagbench.systems.trajectories import SOLVERS, integrate

REF_RTOL = 1e-13
MAX_STEPS = 4096  # per adaptive solve of a learned model (a non-smooth learned field can need far more)
TRUTH_MAX_STEPS = 2**16
CHAOS_EPS = 1e-12


def _ics(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (n, 2)), rng.uniform(-1.0, 1.0, (n, 2))


def _rk4(system, dt, n_steps):
    dof = system.dof

    def field(y):
        return jnp.concatenate([y[dof:], system.acceleration(y[:dof], y[dof:], backend="jax")])

    return jax.jit(jax.vmap(lambda y0: rk4_scan(field, y0, dt, n_steps)))


def field_solver(accel, solver: str, max_steps: int = MAX_STEPS):
    """jit(vmap) of (y0 (B, 2d), t_end, rtol) -> (z(t_end) (B, 2d), ok (B,)): diffrax `solver` on the field
    (q, qdot) -> (qdot, accel(q, qdot)), PID controller at atol = rtol; rtol is an input (one compilation
    per solver and field); a failed solve (step limit, non-finite state) has ok False, never raises."""
    def field(t, y, args):
        d = y.shape[-1] // 2
        return jnp.concatenate([y[d:], accel(y[:d], y[d:])])

    def one(y0, t_end, rtol):
        sol = diffrax.diffeqsolve(diffrax.ODETerm(field), SOLVERS[solver](), t0=0.0, t1=t_end, dt0=None, y0=y0,
                                  stepsize_controller=diffrax.PIDController(rtol=rtol, atol=rtol),
                                  max_steps=max_steps, throw=False)
        return sol.ys[-1], sol.result == diffrax.RESULTS.successful
    return jax.jit(jax.vmap(one, in_axes=(0, None, None)))


def timed_solve(fn, y0, t_end: float, rtol: float, compiled: bool = False):
    """(z (B, 2d), ok (B,), wall_s). The call giving the values compiles unless `compiled` (fn was called
    before), and then is itself timed; more calls while they take under 1 s (the fastest counts)."""
    args = (y0, jnp.asarray(float(t_end)), jnp.asarray(float(rtol)))
    t0 = time.perf_counter()
    zT, ok = (np.asarray(a) for a in fn(*args))
    wall = time.perf_counter() - t0 if compiled else float("inf")
    if wall >= 1.0 and np.isfinite(wall):
        return zT, ok, wall
    wall = min(wall, best_time(lambda: jax.block_until_ready(fn(*args)), min_time=0.0, min_reps=1))
    if wall < 1.0:
        wall = min(wall, best_time(lambda: jax.block_until_ready(fn(*args)), min_time=0.0, min_reps=1))
    return zT, ok, wall


def _errors(system, zT, z_ref, e0):
    dof = system.dof
    state = np.linalg.norm(zT - z_ref, axis=-1) / np.linalg.norm(z_ref, axis=-1)
    e_T = system.energy(zT[:, :dof], zT[:, dof:], backend="numpy")
    return float(np.median(state)), float(np.mean(np.abs(e_T - e0)) / ENERGY_SCALE)


def rollout_rows(sizes, progress=None, trained_from=None, notes=None, learned_rows=None) -> list[dict]:
    """The study's rows; with `sizes.rollout_learned`, `learned_rows` (`learned.learned_rollout_rows`, passed
    in by the caller: learned.py builds on this module) adds the learned models' rows."""
    s = systems.get("double_pendulum")
    q0, qd0 = _ics(sizes.rollout_ics)
    t = np.array([0.0, sizes.rollout_t_end])
    e0 = s.energy(q0, qd0, backend="numpy")

    def final(q, qd, solver, rtol):
        qs, qds = integrate(s, q, qd, t, rtol=rtol, atol=rtol, solver=solver)
        return np.concatenate([qs[:, -1], qds[:, -1]], -1)
    z_ref = final(q0, qd0, "dopri8", REF_RTOL)
    base = {"system": "double_pendulum", "n_ics": sizes.rollout_ics, "t_end": sizes.rollout_t_end,
            "model": "truth", "source": "sympy"}
    rows = []
    y0 = jnp.asarray(np.concatenate([q0, qd0], -1))
    for solver in sizes.rollout_solvers:
        fn = field_solver(lambda q, qd: s.acceleration(q, qd, backend="jax"), solver, TRUTH_MAX_STEPS)
        for rtol in sizes.rollout_rtols:
            zT, ok, wall = timed_solve(fn, y0, sizes.rollout_t_end, rtol, compiled=rtol != sizes.rollout_rtols[0])
            se, ee = _errors(s, np.where(ok[:, None], zT, np.nan), z_ref, e0)
            if not ok.all() and notes is not None:
                notes.append(f"rollout truth {solver} rtol={rtol:g}: {int((~ok).sum())} solves failed")
            rows.append({**base, "solver": solver, "rtol": rtol, "dt": None, "kind": "truth", "wall_s": wall,
                         "state_err": se, "energy_err": ee})
            if progress:
                progress.update(1)
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
    if sizes.rollout_learned and learned_rows is not None:
        def errors(zT):
            return _errors(s, zT, z_ref, e0)
        rows += learned_rows(sizes, q0, qd0, errors, base, trained_from, notes, progress)
    return rows


def n_rollout_cases(sizes) -> int:
    n = len(sizes.rollout_solvers) * len(sizes.rollout_rtols) + len(sizes.rollout_dts) + 1
    return n + (2 * len(sizes.rollout_solvers) * len(sizes.rollout_rtols) if sizes.rollout_learned else 0)
