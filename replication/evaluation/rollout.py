"""The suite's one fixed-step RK4 integrator, batched over trajectories, in any dtype.

Learned models of both frameworks are rolled out by this one integrator (float64 state, the model
evaluated in its own dtype through a NumPy callable), so that a JAX and a PyTorch model are judged
by the same numerics; `rollout_native` runs the same steps inside the model's framework, for long rollouts; the precision evaluation runs the exact equations of motion through it in float32
(`replication.evaluation.precision`), and the speed study's jitted RK4 is `rk4_scan` (JAX). Ground truth
uses diffrax at tight tolerances (`systems.trajectories`).

`rk4_step(f, z, h) -> z'`: one classical step; plain arithmetic, so NumPy (any dtype) and JAX arrays alike.
`rollout(f, z0, t_eval, dt, *, dtype=float64, step="split") -> z`: z0 (B, k) first-order state,
f(z) -> dz/dt (B, k); returns z (B, T, k) float64 at the times `t_eval` (t_eval[0] is the start), the
state and the step held in `dtype` in between. step "split": each interval of t_eval in ceil(interval / dt)
equal steps; step "dt": in max(1, round(interval / dt)) steps of exactly dt (a grid that is a multiple of
dt). A trajectory whose state turns non-finite is frozen at NaN from then on (reported as diverged, never
silently).
`rk4_scan(f, y0, h, n_steps) -> y`: n_steps steps of size h under `jax.lax.scan` (traceable; JAX imported
only when called).
"""
from __future__ import annotations

import numpy as np

STEPS = ("split", "dt")


def _guarded(f):
    """Rows whose state is non-finite are not passed to the model (a framework may raise on them);
    their derivative is NaN, so the trajectory is marked diverged."""
    def g(z):
        bad = ~np.all(np.isfinite(z), axis=1)
        if not bad.any():
            return f(z)
        out = np.full_like(z, np.nan)
        if (~bad).any():
            out[~bad] = f(z[~bad])
        return out
    return g


def rk4_step(f, z, h):
    """One classical RK4 step of dz/dt = f(z) (z and h in one dtype keep the step in it)."""
    k1 = f(z)
    k2 = f(z + 0.5 * h * k1)
    k3 = f(z + 0.5 * h * k2)
    k4 = f(z + h * k3)
    return z + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)


def steps(interval, dt, step, dtype):
    """(number of steps, step size in `dtype`) covering one interval of the output grid."""
    if step == "dt":
        return max(1, int(round(interval / dt))), np.asarray(dt, dtype)
    n = max(1, int(np.ceil(interval / dt - 1e-9)))
    return n, np.asarray(interval / n, dtype)


def rollout(f, z0, t_eval, dt, *, dtype=np.float64, step: str = "split"):
    if step not in STEPS:
        raise ValueError(f"unknown step rule {step!r}; valid: {', '.join(STEPS)}")
    f, dtype = _guarded(f), np.dtype(dtype)
    z = np.array(z0, dtype=dtype)
    t_eval = np.asarray(t_eval, dtype=np.float64)
    out = np.full((z.shape[0], t_eval.size, z.shape[1]), np.nan)
    out[:, 0] = z
    alive = np.ones(z.shape[0], bool)
    for j in range(1, t_eval.size):
        n, h = steps(t_eval[j] - t_eval[j - 1], dt, step, dtype)
        for _ in range(n):
            with np.errstate(all="ignore"):
                z = rk4_step(f, z, h)
            bad = ~np.all(np.isfinite(z), axis=1)
            if bad.any():
                alive &= ~bad
                z[bad] = 0.0  # keep the batch finite; these trajectories are reported as diverged
        out[alive, j] = z[alive]
        out[~alive, j] = np.nan
    return out


def rk4_scan(f, y0, h, n_steps: int):
    """y(t0 + n_steps * h) from y0 by `rk4_step` in a `jax.lax.scan` (jit- and vmap-able)."""
    import jax

    def body(y, _):
        return rk4_step(f, y, h), None
    return jax.lax.scan(body, y0, None, length=n_steps)[0]


def lagrangian_field(accel, dof):
    """dz/dt for z = (q, qdot) given accel(q, qdot) -> qddot."""
    def f(z):
        q, qdot = z[:, :dof], z[:, dof:]
        return np.concatenate([qdot, accel(q, qdot)], axis=1)
    return f


def hamiltonian_field(time_derivative, dof):
    """dz/dt for z = (x, y) given time_derivative(x, y) -> (xdot, ydot)."""
    def f(z):
        xdot, ydot = time_derivative(z[:, :dof], z[:, dof:])
        return np.concatenate([xdot, ydot], axis=1)
    return f
