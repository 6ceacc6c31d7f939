"""SymPy derivations from a ``Definition``: everything the Euler–Lagrange equations give.

With p = dL/dqdot, H = d2L/dqdot2 (velocity Hessian, dof x dof), A_ij = d2L/(dqdot_i dq_j),
generalised forces Q(q, qdot) and joint torques tau, the equations of motion are
``H qddot = dL/dq - A qdot + Q + tau``. ``Derivation`` computes (lazily, each once):

- ``hessian``, ``mixed``, ``rhs`` (b = dL/dq - A qdot + Q + tau), ``acceleration`` (closed form
  when H is diagonal or dof <= 2, otherwise ``None``: callers solve H qddot = b numerically);
- ``energy`` = qdot . p - L, ``momentum`` = p, ``momentum_rate`` = dp/dt = dL/dq + Q;
- ``structure``: quadratic_kinetic (L = qdot^T M(q) qdot / 2 - V(q) exactly), separable
  (L = f(qdot) + g(q)), plus the definition's declared local_coupling and actuated;
- for quadratic kinetic energy: ``gravity`` g(q) = dV/dq, ``coriolis`` c(q, qdot) with
  M qddot + c + g = tau + Q, and ``coriolis_matrix`` C (Christoffel form, C qdot = c);
- ``inverse_dynamics``: tau = H qddot + A qdot - dL/dq - Q.

Symbols for qddot and tau are ``qddot_syms`` and ``tau_syms``. All results are lists of
SymPy expressions (vectors) or SymPy matrices.
"""

from __future__ import annotations

import functools

import sympy as sp

from lagbench.systems.definition import Definition


class NotQuadraticError(ValueError):
    """Raised where a quantity needs L = qdot^T M(q) qdot / 2 - V(q) and the system is not of that form."""


def _split_sum(expr) -> list:
    """Terms of ``expr`` as a sum, distributing products over nested sums (c * (a + b) -> c a, c b)."""
    if expr.is_Add:
        return [t for a in expr.args for t in _split_sum(a)]
    if expr.is_Mul:
        for i, f in enumerate(expr.args):
            if f.is_Add:
                rest = sp.Mul(*expr.args[:i], *expr.args[i + 1 :])
                return [rest * t for t in _split_sum(f)]
    return [expr]


class Derivation:
    def __init__(self, definition: Definition):
        self.d = definition
        n = definition.dof
        self.qddot_syms = tuple(sp.Symbol(f"qddot_{i}", real=True) for i in range(n))
        self.tau_syms = tuple(sp.Symbol(f"tau_{i}", real=True) for i in range(n))

    # --- building blocks -------------------------------------------------------------
    @functools.cached_property
    def _terms_by_symbol(self) -> dict:
        """Top-level terms of L indexed by the symbols they contain: dL/dx only visits those
        (linear instead of quadratic cost for large, locally coupled systems such as the wave)."""
        index: dict = {}
        for term in _split_sum(self.d.lagrangian):
            for sym in term.free_symbols:
                index.setdefault(sym, []).append(term)
        return index

    def _dl(self, sym) -> sp.Expr:
        return sp.Add(*[sp.diff(t, sym) for t in self._terms_by_symbol.get(sym, ())])

    @functools.cached_property
    def momentum(self) -> list:
        return [self._dl(v) for v in self.d.qdot]

    @functools.cached_property
    def grad_q(self) -> list:
        return [self._dl(x) for x in self.d.q]

    @functools.cached_property
    def hessian(self) -> sp.Matrix:
        n = self.d.dof
        return sp.Matrix(n, n, lambda i, j: sp.diff(self.momentum[i], self.d.qdot[j]))

    @functools.cached_property
    def mixed(self) -> sp.Matrix:
        n = self.d.dof
        return sp.Matrix(n, n, lambda i, j: sp.diff(self.momentum[i], self.d.q[j]))

    @functools.cached_property
    def forces(self) -> list:
        return list(self.d.forces) if self.d.forces is not None else [sp.Integer(0)] * self.d.dof

    @functools.cached_property
    def rhs(self) -> list:
        a_qdot = self.mixed * sp.Matrix(self.d.qdot)
        return [
            self.grad_q[i] - a_qdot[i] + self.forces[i] + self.tau_syms[i] for i in range(self.d.dof)
        ]

    # --- equations of motion ---------------------------------------------------------
    @functools.cached_property
    def acceleration(self) -> list | None:
        """Closed-form qddot (diagonal H, or dof <= 2 via the adjugate); None for a numerical solve."""
        h, b = self.hessian, self.rhs
        if h.is_diagonal():
            return [b[i] / h[i, i] for i in range(self.d.dof)]
        if self.d.dof <= 2:
            det = h.det(method="berkowitz")
            sol = h.adjugate() * sp.Matrix(b)
            return [sol[i] / det for i in range(self.d.dof)]
        return None

    @functools.cached_property
    def momentum_rate(self) -> list:
        """dp/dt = dL/dq + Q (with tau = 0): the HNN target in canonical coordinates."""
        return [g + f for g, f in zip(self.grad_q, self.forces, strict=True)]

    @functools.cached_property
    def energy(self) -> sp.Expr:
        return sum(v * p for v, p in zip(self.d.qdot, self.momentum, strict=True)) - self.d.lagrangian

    @functools.cached_property
    def inverse_dynamics(self) -> list:
        hq = self.hessian * sp.Matrix(self.qddot_syms)
        aq = self.mixed * sp.Matrix(self.d.qdot)
        return [hq[i] + aq[i] - self.grad_q[i] - self.forces[i] for i in range(self.d.dof)]

    # --- structure -------------------------------------------------------------------
    @functools.cached_property
    def _at_rest(self) -> dict:
        return {v: 0 for v in self.d.qdot}

    @functools.cached_property
    def quadratic_kinetic(self) -> bool:
        h = self.hessian
        if any(e.has(*self.d.qdot) for e in h):
            return False
        v = sp.Matrix(self.d.qdot)
        rest = self.d.lagrangian.xreplace(self._at_rest)
        residual = self.d.lagrangian - rest - (v.T * h * v)[0, 0] / 2
        return sp.expand(residual) == 0

    @functools.cached_property
    def separable(self) -> bool:
        return all(sp.expand(e) == 0 for e in self.mixed)

    @functools.cached_property
    def structure(self) -> dict:
        return {
            "quadratic_kinetic": self.quadratic_kinetic,
            "separable": self.separable,
            "local_coupling": bool(self.d.local_coupling),
            "actuated": bool(self.d.actuated),
        }

    # --- rigid-body form (quadratic kinetic energy only) -----------------------------
    def _require_quadratic(self, what: str) -> None:
        if not self.quadratic_kinetic:
            raise NotQuadraticError(
                f"{what} of {self.d.name!r} is undefined: its Lagrangian is not of the form "
                "L = qdot^T M(q) qdot / 2 - V(q) (the kinetic term is not quadratic in qdot); "
                "use velocity_hessian(q, qdot) for d2L/dqdot2"
            )

    @functools.cached_property
    def mass_matrix(self) -> sp.Matrix:
        self._require_quadratic("the mass matrix")
        return self.hessian

    @functools.cached_property
    def gravity(self) -> list:
        self._require_quadratic("the gravity term")
        return [-e.xreplace(self._at_rest) for e in self.grad_q]

    @functools.cached_property
    def coriolis(self) -> list:
        self._require_quadratic("the Coriolis term")
        aq = self.mixed * sp.Matrix(self.d.qdot)
        return [aq[i] - self.grad_q[i] - self.gravity[i] for i in range(self.d.dof)]

    @functools.cached_property
    def coriolis_matrix(self) -> sp.Matrix:
        """C_ij = sum_k Gamma_ijk qdot_k, Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2."""
        m, q, v, n = self.mass_matrix, self.d.q, self.d.qdot, self.d.dof

        def entry(i, j):
            return sum(
                (sp.diff(m[i, j], q[k]) + sp.diff(m[i, k], q[j]) - sp.diff(m[j, k], q[i])) * v[k] / 2
                for k in range(n)
            )

        return sp.Matrix(n, n, entry)
