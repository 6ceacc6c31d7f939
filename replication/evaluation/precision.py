"""The precision evaluation: the energy-rollout evaluation plus the ground truth's own drift in the unit's dtype.

`eval_precision(ctx)` runs `eval_energy_rollout` (held-out L1, energy error of the learned model against
the float64 truth) and adds `truth_energy_drift_final` / `truth_energy_drift_max`: the exact equations of
motion rolled out from the same initial conditions with the state, the time step and every evaluation held
in the protocol's dtype (float32 or float64), |E(t) - E(0)| / energy_scale at the final time (and the max
over time), averaged over initial conditions. The integrator (`truth_integrator` in the evaluation config)
is "dopri5": adaptive Dormand-Prince 5(4) in diffrax at rtol = atol = `truth_tol` (the original code's
odeint, default 1e-10, unattainable in float32), capped at `truth_max_steps`; or "rk4": fixed-step RK4 at
the config's `dt` in NumPy (`replication.evaluation.rollout.rollout`, step "dt", the state, the step and
the equations of motion in the dtype; no compilation; the smoke profile; a run that diverges is NaN from then
on). `truth_energy_drift_f64ref` is the drift of the float64 ground truth used everywhere else
(systems.trajectories), for comparison.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from lagbench.replication.evaluation.routines import _truth, eval_energy_rollout, truth_key, truth_rk4


@lru_cache(maxsize=8)
def truth_drift_in_dtype(name, params, cfg_items, dtype: str):
    """(final, max) drift per initial condition, (B,) arrays, of the truth integrated in ``dtype``."""
    cfg = dict(cfg_items)
    s, t, q, qd, _, _ = _truth(name, params, cfg_items)
    y0 = np.concatenate([q[:, 0], qd[:, 0]], -1)
    if cfg.get("truth_integrator", "dopri5") == "rk4":
        ys = truth_rk4(name, params, cfg_items, dtype, step="dt")
    else:
        ys = _dopri5_in_dtype(s, y0, t, cfg, dtype)
    e = s.energy(ys[..., :s.dof], ys[..., s.dof:])
    d = np.abs(e - e[:, :1]) / cfg["energy_scale"]
    return d[:, -1], np.max(d, axis=1)


def _dopri5_in_dtype(s, y0, t, cfg, dtype):
    import diffrax
    import jax
    import jax.numpy as jnp

    dt_ = jnp.dtype(dtype)
    dof = s.dof
    tol = float(cfg.get("truth_tol", 1e-10))

    def field(tt, y, args):
        return jnp.concatenate([y[dof:], s.acceleration(y[:dof], y[dof:], backend="jax")]).astype(dt_)

    def solve(y0):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(field), diffrax.Dopri5(), t0=jnp.asarray(t[0], dt_), t1=jnp.asarray(t[-1], dt_),
            dt0=jnp.asarray(cfg["dt"], dt_), y0=y0, saveat=diffrax.SaveAt(ts=jnp.asarray(t, dt_)),
            stepsize_controller=diffrax.PIDController(rtol=tol, atol=tol, dtmin=None),
            max_steps=int(cfg.get("truth_max_steps", 200_000)), throw=False)
        return sol.ys

    return np.asarray(jax.jit(jax.vmap(solve))(jnp.asarray(y0, dt_)), dtype=np.float64)


def eval_precision(ctx):
    out = eval_energy_rollout(ctx)
    key = truth_key(ctx)
    final, mx = truth_drift_in_dtype(*key, ctx.protocol.dtype)
    ok = np.isfinite(final)
    out.metrics["truth_energy_drift_final"] = float(np.mean(final[ok])) if ok.any() else float("nan")
    out.metrics["truth_energy_drift_max"] = float(np.mean(mx[ok])) if ok.any() else float("nan")
    out.metrics["truth_energy_drift_worst"] = float(np.max(final[ok])) if ok.any() else float("nan")
    out.counters["truth_failed"] = int((~ok).sum())
    s, t, q, qd, _, _ = _truth(*key)
    e = s.energy(q, qd)
    out.metrics["truth_energy_drift_f64ref"] = float(np.mean(np.abs(e[:, -1] - e[:, 0]))) / ctx.cfg["energy_scale"]
    return out
