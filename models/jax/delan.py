"""Deep Lagrangian Network (JAX): L = 1/2 qdot^T M(q) qdot - V(q), M = Lc Lc^T + eps I.

A shared trunk h = MLP(f(q)) (every layer activated; f the q part, `models.jax.mlp.q_features`: q, or
cos and sin of the periodic coordinates) feeds three linear heads: "delan_lower" (the strictly lower entries
of Lc, np.tril_indices order), "delan_diag" (diag(Lc) = softplus(raw + delan_diag_offset) > 0) and
"delan_potential" (V). M is symmetric positive definite by construction (eps >= 0, diag > 0).
Derivatives from ONE forward-mode pass along the d unit tangents of q (dh/dq_k propagated forward, as
the DeLaN paper does; `models.torch.delan` mirrors it line for line; activation slopes by an elementwise jvp):
  dLc_k = dLc/dq_k, Ldot = sum_k qdot_k dLc_k, u = Lc^T qdot, w_k = dLc_k^T qdot,
  Mdot qdot = Ldot u + Lc (Ldot^T qdot),  1/2 d(qdot^T M qdot)/dq_k = w_k . u,
  c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq,  g = dV/dq.
Shapes: q, qdot, qddot, tau (..., dof); M (..., dof, dof); V, L (...,).
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp

from lagbench.models.jax.base import Model
from lagbench.models.jax.mlp import (
    ACT,
    act_and_slope,
    input_scale,
    linear,
    mlp,
    mlp_input,
    q_features,
    q_features_jvp,
)
from lagbench.models.params import n_layers, tril_selection


def _mv(m, v):
    return (m @ v[..., None])[..., 0]


def _lower(vec, d):
    """[diag, strictly lower] (..., d(d+1)/2) -> Lc (..., d, d)."""
    return (vec @ jnp.asarray(tril_selection(d), dtype=vec.dtype).T).reshape(*vec.shape[:-1], d, d)


class DeLaN(Model):
    def _heads(self, q):
        """(Lc (..., d, d), V (...,)) from the trunk on q."""
        spec, d = self.spec, self.spec.dof
        h = mlp(self.params, mlp_input(spec, [q_features(spec, q)]), spec, final_linear=False)
        diag = ACT["softplus"](linear(self.params, "delan_diag", h) + spec.own.diag_offset)
        parts = [diag, linear(self.params, "delan_lower", h)] if d > 1 else [diag]
        return _lower(jnp.concatenate(parts, axis=-1), d), linear(self.params, "delan_potential", h)[..., 0]

    def _mass_of(self, lc):
        return lc @ jnp.swapaxes(lc, -1, -2) + self.spec.own.eps * jnp.eye(self.spec.dof, dtype=lc.dtype)

    def _heads_tangents(self, q):
        """(Lc (..., d, d), dLc (..., d_k, d, d) = dLc/dq_k, V (...,), dV/dq (..., d)): the trunk with
        its d forward tangents (x = scale * f(q), so dx/dq_k = scale_k e_k, wrapping has slope 1; with periodic
        coordinates row k is scale * (df/dq_k), -sin q_k and cos q_k in the slots of k's pair: per sample)."""
        spec, d, p = self.spec, self.spec.dof, self.params
        x = mlp_input(spec, [q_features(spec, q)])
        scale = input_scale(spec, spec.q_width(), q.dtype)
        if spec.periodic:
            eye = jnp.broadcast_to(jnp.eye(d, dtype=q.dtype), (*q.shape[:-1], d, d))
            dh = q_features_jvp(spec, q[..., None, :], eye) * scale
        else:
            dh = jnp.broadcast_to(jnp.diag(scale), (*q.shape[:-1], d, d))
        h = x
        for i in range(n_layers(spec)):
            h, s1 = act_and_slope(spec.activation, linear(p, f"mlp.{i}", h))
            dh = s1[..., None, :] * (dh @ p[f"mlp.{i}.weight"].T)
        diag, s1 = act_and_slope("softplus", linear(p, "delan_diag", h) + spec.own.diag_offset)
        ddiag = s1[..., None, :] * (dh @ p["delan_diag.weight"].T)
        if d > 1:
            vec = jnp.concatenate([diag, linear(p, "delan_lower", h)], axis=-1)
            dvec = jnp.concatenate([ddiag, dh @ p["delan_lower.weight"].T], axis=-1)
        else:
            vec, dvec = diag, ddiag
        v = linear(p, "delan_potential", h)[..., 0]
        return _lower(vec, d), _lower(dvec, d), v, (dh @ p["delan_potential.weight"].T)[..., 0]

    def _dynamics(self, q, qdot):
        """(M, c, g) at (q, qdot), one trunk pass."""
        lc, dlc, _, g = self._heads_tangents(q)
        u = _mv(jnp.swapaxes(lc, -1, -2), qdot)                    # Lc^T qdot
        w = jnp.einsum("...kij,...i->...kj", dlc, qdot)            # w_k = dLc_k^T qdot
        l_dot = jnp.einsum("...k,...kij->...ij", qdot, dlc)        # Ldot
        m_dot_qdot = _mv(l_dot, u) + _mv(lc, jnp.einsum("...k,...kj->...j", qdot, w))
        return self._mass_of(lc), m_dot_qdot - _mv(w, u), g

    @eqx.filter_jit
    def mass_matrix(self, q):
        """M(q) (..., dof, dof), symmetric positive definite."""
        self._check("q", q, self.spec.dof)
        return self._mass_of(self._heads(q)[0])

    @eqx.filter_jit
    def potential(self, q):
        """V(q) (...,)."""
        self._check("q", q, self.spec.dof)
        return self._heads(q)[1]

    @eqx.filter_jit
    def gravity(self, q):
        """g = dV/dq (..., dof)."""
        self._check("q", q, self.spec.dof)
        return self._heads_tangents(q)[3]

    @eqx.filter_jit
    def coriolis(self, q, qdot):
        """c = Mdot qdot - 1/2 d(qdot^T M qdot)/dq (..., dof)."""
        self._check_state(q, qdot)
        return self._dynamics(q, qdot)[1]

    @eqx.filter_jit
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
        return jax.nn.softplus(self.params["dissipation.raw"]) * qdot

    @eqx.filter_jit
    def acceleration(self, q, qdot, extra=None):
        """Forward model qddot = M^-1 (tau - c - g) (..., dof), tau = extra (zero if None)."""
        self._check_state(q, qdot)
        tau = jnp.zeros_like(q) if extra is None else extra
        self._check("tau (extra)", tau, self.spec.dof, like=q)
        m, c, g = self._dynamics(q, qdot)
        return jnp.linalg.solve(m, (tau - c - g - self._friction(qdot))[..., None])[..., 0]

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration (..., dof), 0): M is positive definite, no fallback."""
        return self.acceleration(q, qdot, extra), jnp.zeros((), dtype=jnp.int64)

    @eqx.filter_jit
    def lagrangian(self, q, qdot, extra=None):
        """L = 1/2 qdot^T M qdot - V (...,)."""
        self._check_state(q, qdot)
        lc, v = self._heads(q)
        return 0.5 * jnp.sum(qdot * _mv(self._mass_of(lc), qdot), axis=-1) - v
