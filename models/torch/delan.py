"""Deep Lagrangian Network (PyTorch, torch.func): L = 1/2 qdot^T M(q) qdot - V(q), M = Lc Lc^T + eps I.

A shared trunk h = MLP(q) (every layer activated) feeds three linear heads: "delan_lower" (the strictly
lower entries of Lc, np.tril_indices order), "delan_diag" (diag(Lc) = softplus(raw + delan_diag_offset)
> 0) and "delan_potential" (V). M is symmetric positive definite by construction (eps >= 0, diag > 0).
Derivatives by autodiff (our choice, instead of the original's hand-propagated layer Jacobians):
  Mdot = jvp of q -> M(q) along qdot; d(qdot^T M qdot)/dq by one reverse pass; g = dV/dq by one reverse
  pass; c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq.
Shapes: q, qdot, qddot, tau (..., dof); M (..., dof, dof); V, L (...,).
"""
from __future__ import annotations

import torch
from torch.func import grad, jvp

from models.params import tril_selection
from models.torch.base import Model
from models.torch.mlp import ACT, linear, mlp, mlp_input, wrap_angles


def _mv(m, v):
    return (m @ v[..., None])[..., 0]


class DeLaN(Model):
    def _heads(self, q):
        """(Lc (..., d, d), V (...,)) from the trunk on q."""
        spec, d = self.spec, self.spec.dof
        h = mlp(self.params, mlp_input(spec, [wrap_angles(spec, q)]), spec, final_linear=False)
        diag = ACT["softplus"](linear(self.params, "delan_diag", h) + spec.delan_diag_offset)
        parts = [diag, linear(self.params, "delan_lower", h)] if d > 1 else [diag]
        vec = torch.cat(parts, dim=-1)
        lc = (vec @ torch.tensor(tril_selection(d), dtype=vec.dtype).T).reshape(*q.shape, d)
        return lc, linear(self.params, "delan_potential", h)[..., 0]

    def _mass(self, q):
        lc, _ = self._heads(q)
        eye = torch.eye(self.spec.dof, dtype=q.dtype)
        return lc @ lc.transpose(-1, -2) + self.spec.delan_eps * eye

    def _potential(self, q):
        return self._heads(q)[1]

    def mass_matrix(self, q):
        """M(q) (..., dof, dof), symmetric positive definite."""
        self._check("q", q, self.spec.dof)
        return self._mass(q)

    def potential(self, q):
        """V(q) (...,)."""
        self._check("q", q, self.spec.dof)
        return self._potential(q)

    def gravity(self, q):
        """g = dV/dq (..., dof)."""
        self._check("q", q, self.spec.dof)
        return grad(lambda a: torch.sum(self._potential(a)))(q)

    def coriolis(self, q, qdot):
        """c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq (..., dof)."""
        self._check_state(q, qdot)
        _, m_dot = jvp(self._mass, (q,), (qdot,))
        quad = grad(lambda a: torch.sum(qdot * _mv(self._mass(a), qdot)))(q)
        return _mv(m_dot, qdot) - 0.5 * quad

    def inverse_dynamics(self, q, qdot, qddot):
        """tau = M qddot + c + g (..., dof)."""
        self._check("qddot", qddot, self.spec.dof, like=q)
        return _mv(self.mass_matrix(q), qddot) + self.coriolis(q, qdot) + self.gravity(q)

    def acceleration(self, q, qdot, extra=None):
        """Forward model qddot = M^-1 (tau - c - g) (..., dof), tau = extra (zero if None)."""
        self._check_state(q, qdot)
        tau = torch.zeros_like(q) if extra is None else extra
        self._check("tau (extra)", tau, self.spec.dof, like=q)
        rhs = tau - self.coriolis(q, qdot) - self.gravity(q)
        return torch.linalg.solve(self._mass(q), rhs[..., None])[..., 0]

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration (..., dof), 0): M is positive definite, no fallback."""
        return self.acceleration(q, qdot, extra), torch.zeros((), dtype=torch.int64)

    def lagrangian(self, q, qdot, extra=None):
        """L = 1/2 qdot^T M qdot - V (...,)."""
        self._check_state(q, qdot)
        return 0.5 * torch.sum(qdot * _mv(self._mass(q), qdot), dim=-1) - self._potential(q)
