"""The Hamiltonian neural network (jax): H = MLP([x, y, extra]); (xdot, ydot) = (dH/dy, -dH/dx).

x, y (..., dof) are canonical (q, p), or deliberately non-canonical (q, qdot) to replicate the failure;
extra (..., extra_inputs) or None is fed to the MLP but not differentiated. x enters as the q part
(`models.jax.mlp.q_features`: wrapped with angle_wrap, cos and sin of the periodic coordinates).
"""
from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp

from lagbench.models.jax.base import Model
from lagbench.models.jax.mlp import mlp, mlp_input, q_features
from lagbench.models.lorentz import velocity_parts


class HNN(Model):
    def _hamiltonian(self, x, y, extra=None):
        z = mlp_input(self.spec, [q_features(self.spec, x), *velocity_parts(self.spec, y), *self._parts(extra)])
        return mlp(self.params, z, self.spec)[..., 0]

    @eqx.filter_jit
    def hamiltonian(self, x, y, extra=None):
        """H (...,)."""
        self._check_state(x, y, extra)
        return self._hamiltonian(x, y, extra)

    @eqx.filter_jit
    def time_derivative(self, x, y, extra=None):
        """(xdot, ydot) = (dH/dy, -dH/dx), each (..., dof)."""
        self._check_state(x, y, extra)
        dh_dx, dh_dy = jax.grad(lambda a, b: jnp.sum(self._hamiltonian(a, b, extra)), argnums=(0, 1))(x, y)
        if self.spec.dissipation:   # Rayleigh D = 1/2 sum b xdot^2: the momentum loses b * dH/dy
            return dh_dy, -dh_dx - jax.nn.softplus(self.params["dissipation.raw"]) * dh_dy
        return dh_dy, -dh_dx
