"""Deep Lagrangian Network (PyTorch): L = 1/2 qdot^T M(q) qdot - V(q), M = Lc Lc^T + eps I.

A shared trunk h = MLP(f(q)) (every layer activated; f the q part, `models.torch.mlp.q_features`: q, or
cos and sin of the periodic coordinates) feeds three linear heads: "delan_lower" (the strictly lower entries
of Lc, np.tril_indices order), "delan_diag" (diag(Lc) = softplus(raw + delan_diag_offset) > 0) and
"delan_potential" (V). M is symmetric positive definite by construction (eps >= 0, diag > 0).
Derivatives in closed form from ONE forward pass carrying d tangents (dh/dq_k, k = 1..d, the layer
Jacobians propagated forward as the DeLaN paper does), no autograd graph of its own:
  dLc_k = dLc/dq_k, Ldot = sum_k qdot_k dLc_k, u = Lc^T qdot, w_k = dLc_k^T qdot,
  Mdot qdot = Ldot u + Lc (Ldot^T qdot),  1/2 d(qdot^T M qdot)/dq_k = w_k . u,
  c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq,  g = dV/dq.
Mirrored line for line by `models.jax.delan`, except that under torch.export the forward model solves
by `spd_solve_unrolled` (dof <= 8; same numbers, it compiles to fused kernels; chosen by
`models.torch.export_paths.pick`). Shapes: q, qdot, qddot, tau
(..., dof); M (..., dof, dof); V, L (...,).
"""
from __future__ import annotations

import torch
from torch.nn.functional import linear as _lin

from lagbench.models.params import n_layers, tril_selection
from lagbench.models.torch.base import Model
from lagbench.models.torch.export_paths import pick
from lagbench.models.torch.mlp import ACT, input_scale, linear, mlp, mlp_input, q_features, q_features_jvp
from lagbench.models.torch.mlp_derivatives import ACT_DERIVS


def _mv(m, v):
    return (m @ v[..., None])[..., 0]


def _vm(v, m):
    """v^T m over the second-to-last axis of m: v (..., i), m (..., i, j) -> (..., j)."""
    return (v[..., None, :] @ m)[..., 0, :]


def _linalg_solve(m, b):
    """m^-1 b for m (..., d, d), b (..., d) by torch.linalg.solve (eager)."""
    return torch.linalg.solve(m, b[..., None])[..., 0]


def spd_solve_unrolled(m, b):
    """m^-1 b for symmetric positive definite m (..., d, d), b (..., d), by a Cholesky factorisation and
    two substitutions written out over the d rows: elementwise ops on the batch only. Used under
    torch.export: AOTInductor fuses these into its kernels, while torch.linalg.solve there becomes a call
    through its slow proxy executor (DeLaN one-sample acceleration 9.9k calls/s with it, measured)."""
    d = m.shape[-1]
    lo = [[None] * d for _ in range(d)]
    for j in range(d):
        lo[j][j] = torch.sqrt(m[..., j, j] - sum(lo[j][k] ** 2 for k in range(j)))
        for i in range(j + 1, d):
            lo[i][j] = (m[..., i, j] - sum(lo[i][k] * lo[j][k] for k in range(j))) / lo[j][j]
    y = []
    for i in range(d):
        y.append((b[..., i] - sum(lo[i][k] * y[k] for k in range(i))) / lo[i][i])
    x = [None] * d
    for i in reversed(range(d)):
        x[i] = (y[i] - sum(lo[k][i] * x[k] for k in range(i + 1, d))) / lo[i][i]
    return torch.stack(x, dim=-1)


def _lower(vec, tril, d):
    """[diag, strictly lower] (..., d(d+1)/2) -> Lc (..., d, d); tril = S^T (`models.params.tril_selection`)."""
    return (vec @ tril).unflatten(-1, (d, d))


class DeLaN(Model):
    def __init__(self, spec, params):
        """Per-call constants are built once, as non-persistent buffers (a tensor built from NumPy costs
        more than the small products; buffers, unlike a module-level cache, are also what torch.export
        captures): "tril" the (d(d+1)/2, d*d) assembly matrix S^T, "eye" I_d, "scale" the input scale and,
        without periodic coordinates, "dx" = diag(scale), the tangents dx/dq_k (with them they vary per sample)."""
        super().__init__(spec, params)
        d, dtype = spec.dof, getattr(torch, spec.dtype)
        scale = input_scale(spec, spec.q_width(), dtype)
        self.register_buffer("tril", torch.tensor(tril_selection(d).T, dtype=dtype), persistent=False)
        self.register_buffer("eye", torch.eye(d, dtype=dtype), persistent=False)
        self.register_buffer("scale", scale, persistent=False)
        if not spec.periodic:
            self.register_buffer("dx", torch.diag(scale), persistent=False)

    def _heads(self, q):
        """(Lc (..., d, d), V (...,)) from the trunk on q (no derivatives)."""
        spec, d = self.spec, self.spec.dof
        h = mlp(self.params, mlp_input(spec, [q_features(spec, q)]), spec, final_linear=False)
        diag = ACT["softplus"](linear(self.params, "delan_diag", h) + spec.own.diag_offset)
        parts = [diag, linear(self.params, "delan_lower", h)] if d > 1 else [diag]
        return _lower(torch.cat(parts, dim=-1), self.tril, d), linear(self.params, "delan_potential", h)[..., 0]

    def _heads_tangents(self, q):
        """(Lc (..., d, d), dLc (..., d_k, d, d) = dLc/dq_k, V (...,), dV/dq (..., d)): the trunk with
        its d forward tangents (x = scale * f(q), so dx/dq_k = scale_k e_k, wrapping has slope 1; with periodic
        coordinates row k is scale * (df/dq_k), -sin q_k and cos q_k in the slots of k's pair: per sample)."""
        spec, d, p = self.spec, self.spec.dof, self.params
        x = mlp_input(spec, [q_features(spec, q)])
        if spec.periodic:
            dh = q_features_jvp(spec, q[..., None, :], self.eye.expand(*q.shape[:-1], d, d)) * self.scale
        else:
            dh = self.dx.expand(*q.shape[:-1], d, d)
        h = x
        derivs = ACT_DERIVS[spec.activation]
        for i in range(n_layers(spec)):
            a = linear(p, f"mlp.{i}", h)
            h, s1, _ = derivs(a)
            dh = s1[..., None, :] * _lin(dh, p[f"mlp.{i}.weight"])
        raw = linear(p, "delan_diag", h) + spec.own.diag_offset
        diag, s1, _ = ACT_DERIVS["softplus"](raw)
        ddiag = s1[..., None, :] * _lin(dh, p["delan_diag.weight"])
        if d > 1:
            vec = torch.cat([diag, linear(p, "delan_lower", h)], dim=-1)
            dvec = torch.cat([ddiag, _lin(dh, p["delan_lower.weight"])], dim=-1)
        else:
            vec, dvec = diag, ddiag
        v = linear(p, "delan_potential", h)[..., 0]
        return _lower(vec, self.tril, d), _lower(dvec, self.tril, d), v, _lin(dh, p["delan_potential.weight"])[..., 0]

    def _mass_of(self, lc):
        return lc @ lc.transpose(-1, -2) + self.spec.own.eps * self.eye

    def _dynamics(self, q, qdot):
        """(M, c, g) at (q, qdot), one trunk pass."""
        lc, dlc, _, g = self._heads_tangents(q)
        d = self.spec.dof
        u = _vm(qdot, lc)                                          # Lc^T qdot
        w = _vm(qdot[..., None, :], dlc)                           # w_k = dLc_k^T qdot (..., k, j)
        l_dot = _vm(qdot, dlc.flatten(-2)).unflatten(-1, (d, d))   # Ldot = sum_k qdot_k dLc_k
        m_dot_qdot = _mv(l_dot, u) + _mv(lc, _vm(qdot, w))
        return self._mass_of(lc), m_dot_qdot - _mv(w, u), g

    def mass_matrix(self, q):
        """M(q) (..., dof, dof), symmetric positive definite."""
        self._check("q", q, self.spec.dof)
        return self._mass_of(self._heads(q)[0])

    def potential(self, q):
        """V(q) (...,)."""
        self._check("q", q, self.spec.dof)
        return self._heads(q)[1]

    def gravity(self, q):
        """g = dV/dq (..., dof)."""
        self._check("q", q, self.spec.dof)
        return self._heads_tangents(q)[3]

    def coriolis(self, q, qdot):
        """c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq (..., dof)."""
        self._check_state(q, qdot)
        return self._dynamics(q, qdot)[1]

    def inverse_dynamics(self, q, qdot, qddot):
        """tau = M qddot + c + g (..., dof)."""
        self._check_state(q, qdot)
        self._check("qddot", qddot, self.spec.dof, like=q)
        m, c, g = self._dynamics(q, qdot)
        return _mv(m, qddot) + c + g + self._friction(qdot)

    def _friction(self, qdot):
        """The Rayleigh force's torque b * qdot (spec.dissipation), else 0."""
        if not self.spec.dissipation:
            return 0.0
        return torch.nn.functional.softplus(self.params["dissipation.raw"]) * qdot

    def acceleration(self, q, qdot, extra=None):
        """Forward model qddot = M^-1 (tau - c - g) (..., dof), tau = extra (zero if None)."""
        self._check_state(q, qdot)
        tau = torch.zeros_like(q) if extra is None else extra
        self._check("tau (extra)", tau, self.spec.dof, like=q)
        m, c, g = self._dynamics(q, qdot)
        solve = pick(_linalg_solve, exporting=spd_solve_unrolled if self.spec.dof <= 8 else None)
        return solve(m, tau - c - g - self._friction(qdot))

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration (..., dof), 0): M is positive definite, no fallback."""
        return self.acceleration(q, qdot, extra), torch.zeros((), dtype=torch.int64, device=q.device)

    def lagrangian(self, q, qdot, extra=None):
        """L = 1/2 qdot^T M qdot - V (...,)."""
        self._check_state(q, qdot)
        lc, v = self._heads(q)
        return 0.5 * torch.sum(qdot * _mv(self._mass_of(lc), qdot), dim=-1) - v
