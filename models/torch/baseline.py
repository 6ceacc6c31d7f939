"""The feed-forward baseline (torch): qddot = MLP([f(q), qdot, extra]) (the LNN paper's baseline), or any
direct map such as the DeLaN comparison's inverse model tau = MLP([f(q), qdot, qddot = extra]); f is the q part
(`models.torch.mlp.q_features`: q, wrapped with angle_wrap, cos and sin of the periodic coordinates).

q, qdot (..., dof), extra (..., extra_inputs) or None -> (..., n_out), n_out = dof by default.
"""
from __future__ import annotations

import torch

from lagbench.models.torch.base import Model
from lagbench.models.torch.mlp import mlp, mlp_input, q_features


class Baseline(Model):
    @classmethod
    def stacks(cls, spec) -> bool:
        return True

    @classmethod
    def compiles(cls, spec) -> bool:
        """No: a plain MLP's step is its matrix products, which compiling leaves as they are. The quick double
        pendulum's baselines (three captures each) trained in 126 s (a cold cache), 95 s and 89 s compiled,
        against 107, 93 and 105 s eager."""
        return False

    def acceleration(self, q, qdot, extra=None):
        """MLP output (..., n_out)."""
        self._check_state(q, qdot, extra)
        x = mlp_input(self.spec, [q_features(self.spec, q), qdot, *self._parts(extra)])
        return mlp(self.params, x, self.spec)

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration (..., n_out), 0): no fallback exists."""
        return self.acceleration(q, qdot, extra), torch.zeros((), dtype=torch.int64, device=q.device)
