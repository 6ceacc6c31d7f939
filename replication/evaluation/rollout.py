"""A framework-neutral fixed-step RK4 integrator for learned models, batched over trajectories.

Learned models of both frameworks are rolled out by this one integrator (float64 state, the model
evaluated in its own dtype through a NumPy callable), so that a JAX and a PyTorch model are judged
by the same numerics. Ground truth uses diffrax at tight tolerances (`systems.trajectories`).

`rollout(f, z0, t_eval, dt) -> (z, n_steps)`: z0 (B, k) first-order state, f(z) -> dz/dt (B, k);
returns z (B, T, k) at the times `t_eval` (t_eval[0] is the start). A trajectory whose state turns
non-finite is frozen at NaN from then on (reported as diverged, never silently).
"""
from __future__ import annotations

import numpy as np


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
    """One classical RK4 step of dz/dt = f(z): plain arithmetic, so NumPy (any dtype) and JAX arrays alike
    (the speed study's jitted RK4 scans this same step)."""
    k1 = f(z)
    k2 = f(z + 0.5 * h * k1)
    k3 = f(z + 0.5 * h * k2)
    k4 = f(z + h * k3)
    return z + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)


def rollout(f, z0, t_eval, dt):
    f = _guarded(f)
    z = np.array(z0, dtype=np.float64)
    t_eval = np.asarray(t_eval, dtype=np.float64)
    out = np.full((z.shape[0], t_eval.size, z.shape[1]), np.nan)
    out[:, 0] = z
    t, alive = t_eval[0], np.ones(z.shape[0], bool)
    for j in range(1, t_eval.size):
        n = max(1, int(np.ceil((t_eval[j] - t) / dt - 1e-9)))
        h = (t_eval[j] - t) / n
        for _ in range(n):
            with np.errstate(all="ignore"):
                z = rk4_step(f, z, h)
            bad = ~np.all(np.isfinite(z), axis=1)
            if bad.any():
                alive &= ~bad
                z[bad] = 0.0  # keep the batch finite; these trajectories are reported as diverged
        t = t_eval[j]
        out[alive, j] = z[alive]
        out[~alive, j] = np.nan
    return out


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
