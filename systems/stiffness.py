"""Stiffness from the linearisation, and the ground-truth solver chosen by a stated rule.

``linear_rates(system, q0, qdot0, **params) -> (B, 2 dof) complex``: eigenvalues of the Jacobian of the
first-order dynamics d(q, qdot)/dt = (qdot, qddot(q, qdot)) at each initial state (q0, qdot0 (B, dof)
or (dof,)).

``pick_solver(system, q0, qdot0, t_end, tol=1e-10, **params) -> SolverChoice``: the solver, tolerances,
stiffness ratio, expected explicit step count and the reason; ``choice.kwargs()`` goes straight into
``systems.trajectories.integrate``. The rule (measured on ``stiff_chain``: see replication/studies/stiff_solvers.py):

- stiffness ratio r = max |lambda| / min |lambda| over the non-zero eigenvalues (worst initial state);
  the decay rate of the fastest mode is -Re lambda; "dissipative" means the fast modes decay
  (-Re lambda >= DISSIPATIVE * |lambda| for an eigenvalue with |lambda| = max |lambda|).
- r >= STIFF and dissipative: "kvaerno5" (implicit, L-stable): the fast modes decay, so damping them
  costs no accuracy, and the step is no longer bounded by the fastest rate.
- otherwise (non-stiff, or oscillatory stiffness such as undamped springs): "dopri8" (explicit, 8th
  order). An L-stable implicit solver would damp a fast oscillation that physically persists (energy
  error), and an explicit solver must resolve it anyway; its step count grows like t_end * max |lambda|,
  which the choice reports (``expected_steps``) so a caller can see the cost before integrating.
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from lagbench.systems.system import System

STIFF = 100.0        # stiffness ratio above which a system counts as stiff
DISSIPATIVE = 0.1    # fast modes decay if -Re(lambda) >= DISSIPATIVE * |lambda|
STEPS_PER_PERIOD = 16.0  # dopri8 steps per period of the fastest mode at tol 1e-10 (measured on stiff_chain)


@dataclass(frozen=True)
class SolverChoice:
    solver: str
    rtol: float
    atol: float
    stiffness_ratio: float
    max_rate: float          # max |lambda|, 1/s
    min_rate: float          # min non-zero |lambda|, 1/s
    dissipative: bool
    expected_steps: float    # rough dopri8 step count: t_end * max |lambda| / 2 pi * STEPS_PER_PERIOD
    reason: str

    def kwargs(self) -> dict:
        return {"solver": self.solver, "rtol": self.rtol, "atol": self.atol}


def linear_rates(system: System, q0, qdot0, **params) -> np.ndarray:
    """Eigenvalues (B, 2 dof) (or (2 dof,) for 1D input) of the Jacobian of the first-order dynamics."""
    q0, qdot0 = np.asarray(q0, dtype=np.float64), np.asarray(qdot0, dtype=np.float64)
    single = q0.ndim == 1
    y0 = np.concatenate([np.atleast_2d(q0), np.atleast_2d(qdot0)], axis=-1)
    dof = system.dof
    if y0.shape[-1] != 2 * dof:
        raise ValueError(f"q0 and qdot0 must have shape (B, {dof}) or ({dof},); got {q0.shape}, {qdot0.shape}")
    system._check_speed(qdot0, "linear_rates")

    def field(y):
        acc = system.acceleration(y[:dof], y[dof:], backend="jax", **params)
        return jnp.concatenate([y[dof:], acc])

    jac = np.asarray(jax.vmap(jax.jacfwd(field))(jnp.asarray(y0)))
    if not np.all(np.isfinite(jac)):
        raise ValueError(f"{system.name!r}: the Jacobian of the dynamics is not finite at the initial state")
    eig = np.linalg.eigvals(jac)
    return eig[0] if single else eig


def pick_solver(system: System, q0, qdot0, t_end: float, tol: float = 1e-10, **params) -> SolverChoice:
    """Choose the ground-truth solver for integrating ``system`` from (q0, qdot0) to ``t_end``."""
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"t_end must be a positive finite time, got {t_end!r}")
    if not (np.isfinite(tol) and 0 < tol < 1):
        raise ValueError(f"tol must be in (0, 1), got {tol!r}")
    eig = np.atleast_2d(linear_rates(system, q0, qdot0, **params))
    mag = np.abs(eig)
    top = float(mag.max())
    nonzero = mag[mag > 1e-9 * max(top, 1e-300)]
    low = float(nonzero.min()) if nonzero.size else top
    ratio = top / low if low > 0 else 1.0
    fastest = eig[mag >= 0.5 * top] if top > 0 else eig.ravel()
    dissipative = bool(top > 0 and np.max(-fastest.real) >= DISSIPATIVE * top)
    steps = float(t_end) * top / (2 * np.pi) * STEPS_PER_PERIOD
    facts = f"stiffness ratio {ratio:.3g} (|lambda| from {low:.3g} to {top:.3g} 1/s)"
    if ratio >= STIFF and dissipative:
        solver = "kvaerno5"
        reason = (f"stiff and dissipative: {facts}, fastest modes decay; implicit L-stable kvaerno5 "
                  f"avoids ~{steps:.3g} explicit steps")
    elif ratio >= STIFF:
        solver = "dopri8"
        reason = (f"oscillatory stiffness: {facts}, fastest modes undamped; an L-stable implicit solver "
                  f"would damp them (energy error), so explicit dopri8 resolves them in ~{steps:.3g} steps")
    else:
        solver = "dopri8"
        reason = f"not stiff: {facts} < {STIFF:g}; explicit dopri8"
    return SolverChoice(solver, float(tol), float(tol), ratio, top, low, dissipative, steps, reason)
