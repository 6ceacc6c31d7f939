"""Ground-truth trajectories: diffrax in float64 on the generated JAX equations of motion.

``integrate(system, q0, qdot0, t, *, rtol=1e-12, atol=1e-12, solver="dopri8", tau=None,
max_steps=2**20, return_steps=False, **param_overrides) -> (q, qdot) [+ steps]``

- ``q0``, ``qdot0``: (B, dof) or (dof,); ``t``: 1D strictly increasing grid of T times
  (the first is the initial time);
- returns float64 NumPy arrays (B, T, dof) (or (T, dof) for 1D inputs), states saved at ``t``;
- ``solver``: one of ``SOLVERS`` ("tsit5", "dopri5", "dopri8" explicit; "kvaerno5" implicit, L-stable,
  for dissipative stiff systems; ``systems.stiffness.pick_solver`` chooses), adaptive step with a PID
  controller at (rtol, atol) that also steps onto every time in ``t`` (saved states are step
  values, not dense-output interpolants); each trajectory gets its own step sizes (vmap over B);
- ``tau``: constant generalised forces (dof,) or (B, dof), or a JAX-traceable ``tau(t) -> (dof,)``;
- ``param_overrides``: scalars or per-trajectory arrays (B,).

Compiled solvers are cached in memory per (system, solver, tolerances, max_steps, tau kind).
Raises RuntimeError when the solver fails (e.g. max_steps reached).
"""

from __future__ import annotations

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from lagbench.systems import backends  # noqa: F401  (x64)
from lagbench.systems.system import System

SOLVERS = {"tsit5": diffrax.Tsit5, "dopri5": diffrax.Dopri5, "dopri8": diffrax.Dopri8,
           "kvaerno5": diffrax.Kvaerno5}
_COMPILED: dict = {}


def _solver_fn(system: System, solver: str, rtol: float, atol: float, max_steps: int, tau_fn):
    key = (system.definition.fingerprint(), solver, rtol, atol, max_steps, tau_fn)
    if key in _COMPILED:
        return _COMPILED[key]
    dof = system.dof

    def field(t, y, args):
        params, tau = args
        force = tau_fn(t) if tau_fn is not None else tau
        acc = system.acceleration(y[:dof], y[dof:], backend="jax", tau=force, **params)
        return jnp.concatenate([y[dof:], acc])

    def solve_one(y0, ts, params, tau):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(field),
            SOLVERS[solver](),
            t0=ts[0],
            t1=ts[-1],
            dt0=None,
            y0=y0,
            args=(params, tau),
            saveat=diffrax.SaveAt(ts=ts),
            stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol, step_ts=ts),
            max_steps=max_steps,
        )
        return sol.ys, sol.stats["num_steps"]

    fn = jax.jit(jax.vmap(solve_one, in_axes=(0, None, 0, 0)))
    _COMPILED[key] = fn
    return fn


def integrate(system: System, q0, qdot0, t, *, rtol: float = 1e-12, atol: float = 1e-12,
              solver: str = "dopri8", tau=None, max_steps: int = 2**20, return_steps: bool = False,
              **param_overrides):
    """Integrate ``system`` from (q0, qdot0) and return (q, qdot) at the times ``t``
    (and the accepted steps per trajectory, (B,) or an int for 1D input, if ``return_steps``)."""
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver {solver!r}; valid: {', '.join(SOLVERS)}")
    q0, qdot0 = np.asarray(q0, dtype=np.float64), np.asarray(qdot0, dtype=np.float64)
    single = q0.ndim == 1
    q0, qdot0 = np.atleast_2d(q0), np.atleast_2d(qdot0)
    dof = system.dof
    if q0.ndim != 2 or q0.shape[-1] != dof or qdot0.shape != q0.shape:
        raise ValueError(f"q0 and qdot0 must both have shape (B, {dof}) or ({dof},); got {q0.shape}, {qdot0.shape}")
    ts = np.asarray(t, dtype=np.float64)
    if ts.ndim != 1 or ts.size < 1 or np.any(np.diff(ts) <= 0):
        raise ValueError("t must be a 1D strictly increasing grid with at least one time")
    b = q0.shape[0]
    values = {**system.params, **param_overrides}
    unknown = set(values) - set(system.params)
    if unknown:
        raise ValueError(f"{system.name!r} has no parameters {sorted(unknown)}; valid: {sorted(system.params)}")
    system._check_speed(qdot0, "integrate")
    params = {}
    for k, v in values.items():
        arr = np.broadcast_to(np.asarray(v, dtype=np.float64), (b,))
        params[k] = jnp.asarray(arr)
    tau_fn = tau if callable(tau) else None
    tau_arr = np.zeros((b, dof)) if tau is None or tau_fn is not None else np.asarray(tau, dtype=np.float64)
    tau_arr = np.broadcast_to(tau_arr, (b, dof))
    if ts.size == 1:
        ys, steps = np.concatenate([q0, qdot0], axis=-1)[:, None, :], np.zeros(b, dtype=np.int64)
    else:
        fn = _solver_fn(system, solver, float(rtol), float(atol), int(max_steps), tau_fn)
        y0 = jnp.asarray(np.concatenate([q0, qdot0], axis=-1))
        try:
            ys, steps = fn(y0, jnp.asarray(ts), params, jnp.asarray(tau_arr))
            ys, steps = np.asarray(ys), np.asarray(steps)
        except Exception as err:  # diffrax reports step-limit and NaN failures as runtime errors
            raise RuntimeError(f"integration of {system.name!r} failed: {err}") from err
    q, qdot = ys[..., :dof], ys[..., dof:]
    out = (q[0], qdot[0]) if single else (q, qdot)
    if return_steps:
        return (*out, int(steps[0]) if single else steps)
    return out
