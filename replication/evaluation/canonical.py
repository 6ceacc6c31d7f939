"""An HNN on canonical (q, p) rolled out by its own Hamiltonian, for every system.

`canonical_rollout(time_derivative, s, q0, qdot0, t, dt, *, extra=None, momentum_kw=None) -> (q, p)`
  time_derivative(q, p, extra) -> (dH/dp, -dH/dq), each (B, dof) NumPy: the learned H's flow (a model
  adapter's `time_derivative`, `replication.evaluation.adapters`, or any callable of that form).
  s           the `systems.System` the model learned; it gives only the initial momentum,
              p0 = dL/dqdot(q0, qdot0) (`System.canonical_momentum`: exact for every Lagrangian, m gamma qdot
              for the relativistic particle, M(q) qdot where the kinetic energy is quadratic).
  q0, qdot0   (B, dof) float64 initial states; t (T,) the output times (t[0] the start); dt the RK4 step bound.
  extra       (B, k) or None: the model's extra inputs (e.g. the relativistic field g), constant along a
              trajectory (they ride in the integrated state with rate 0).
  momentum_kw the system's per-sample parameters for p0 (each (B,)), e.g. {"g": g}; None for none.
  The suite's RK4 (`rollout.rollout`, float64 state, each output interval in equal steps of at most dt)
  integrates Hamilton's equations of the learned H, dq/dt = dH/dp, dp/dt = -dH/dq.
  Returns q, p, each (B, T, dof) float64; a trajectory whose state turns non-finite is NaN from then on. No
  velocity is computed here: the evaluations read the true one at each state (`state_velocity`), and the
  learned H's own, where wanted, is `velocity`.

`velocity(time_derivative, q, p, extra=None) -> qdot`: the learned dH/dp at states q, p (B, T, dof), extra
  (B, k) or None; NaN where the state is non-finite (the model is not called there).
`state_velocity(s, q, p, momentum_kw=None) -> qdot`: the true system's velocity at the canonical state (q, p)
  (..., dof): the qdot with dL/dqdot(q, qdot) = p, by Newton's method on the momentum map with the system's
  velocity Hessian from qdot = 0 (exact in one step where the kinetic energy is quadratic: M(q)^-1 p), each
  step halved until the speed stays below the system's `max_speed` (the relativistic particle); NaN where the
  state is non-finite or the iteration does not converge. momentum_kw: per-sample parameters, each aligned
  with q's leading axes ((B,) for q (B, T, dof)).
  Quantities of the true system at a predicted canonical state (its energy H_true(q, p), as the HNN paper
  measures it, and the velocity an error against the true trajectory reads) use this velocity; the learned
  dH/dp is the model's own and drives its rollout.
"""
from __future__ import annotations

import numpy as np

from lagbench.replication.evaluation.rollout import rollout


def canonical_rollout(time_derivative, s, q0, qdot0, t, dt, *, extra=None, momentum_kw=None):
    q0, qdot0 = np.asarray(q0, np.float64), np.asarray(qdot0, np.float64)
    d = q0.shape[1]
    p0 = s.canonical_momentum(q0, qdot0, backend="numpy", **(momentum_kw or {}))
    rest = np.zeros((len(q0), 0)) if extra is None else np.asarray(extra, np.float64).reshape(len(q0), -1)
    k = rest.shape[1]

    def field(z):   # z = (q, p, extra): (dH/dp, -dH/dq, 0)
        qdot, pdot = time_derivative(z[:, :d], z[:, d:2 * d], z[:, 2 * d:] if extra is not None else None)
        return np.concatenate([qdot, pdot, np.zeros((len(z), k))], 1)

    z = rollout(field, np.concatenate([q0, p0, rest], 1), t, dt)
    return z[..., :d], z[..., d:2 * d]


def velocity(time_derivative, q, p, extra=None):
    b, n, d = q.shape
    qf, pf = q.reshape(b * n, d), p.reshape(b * n, d)
    ef = None if extra is None else np.repeat(np.asarray(extra, np.float64).reshape(b, -1), n, axis=0)
    ok = np.all(np.isfinite(qf), 1) & np.all(np.isfinite(pf), 1)
    out = np.full((b * n, d), np.nan)
    if ok.any():
        out[ok] = time_derivative(qf[ok], pf[ok], None if ef is None else ef[ok])[0]
    return out.reshape(b, n, d)


def state_velocity(s, q, p, momentum_kw=None, iterations: int = 60, tol: float = 1e-13):
    q, p = np.asarray(q, np.float64), np.asarray(p, np.float64)
    shape, d = q.shape, q.shape[-1]
    qf, pf = q.reshape(-1, d), p.reshape(-1, d)
    kw = {k: np.broadcast_to(np.asarray(v, np.float64)[(...,) + (None,) * (q.ndim - 1 - np.ndim(v))],
                             shape[:-1]).reshape(-1) for k, v in (momentum_kw or {}).items()}
    ok = np.all(np.isfinite(qf), 1) & np.all(np.isfinite(pf), 1)
    out = np.full(qf.shape, np.nan)
    if not ok.any():
        return out.reshape(shape)
    qo, po, kwo = qf[ok], pf[ok], {k: v[ok] for k, v in kw.items()}
    cap = s.definition.max_speed
    v = np.zeros_like(qo)
    done = np.zeros(len(qo), bool)
    for _ in range(iterations):
        r = s.canonical_momentum(qo, v, backend="numpy", **kwo) - po
        done = np.all(np.abs(r) <= tol * (1.0 + np.abs(po)), 1)
        if done.all():
            break
        step = np.linalg.solve(s.velocity_hessian(qo, v, backend="numpy", **kwo), r[..., None])[..., 0]
        new = v - step
        while cap is not None and (far := np.linalg.norm(new, axis=1) >= cap).any():   # stay inside |qdot| < c
            new[far] = v[far] - 0.5 * (v[far] - new[far])
        v = np.where(done[:, None], v, new)
    out[ok] = np.where(done[:, None], v, np.nan)
    return out.reshape(shape)
