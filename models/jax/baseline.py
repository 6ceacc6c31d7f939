"""The feed-forward baseline (jax): qddot = MLP([f(q), qdot, extra]) (the LNN paper's baseline), or any
direct map such as the DeLaN comparison's inverse model tau = MLP([f(q), qdot, qddot = extra]); f is the q part
(`models.jax.mlp.q_features`: q, wrapped with angle_wrap, cos and sin of the periodic coordinates).

q, qdot (..., dof), extra (..., extra_inputs) or None -> (..., n_out), n_out = dof by default.
"""
from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp

from lagbench.models.jax.base import Model
from lagbench.models.jax.mlp import mlp, mlp_input, q_features


class Baseline(Model):
    @eqx.filter_jit
    def acceleration(self, q, qdot, extra=None):
        """MLP output (..., n_out)."""
        self._check_state(q, qdot, extra)
        x = mlp_input(self.spec, [q_features(self.spec, q), qdot, *self._parts(extra)])
        return mlp(self.params, x, self.spec)

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration (..., n_out), 0): no fallback exists."""
        return self.acceleration(q, qdot, extra), jnp.zeros((), dtype=jnp.int64)
