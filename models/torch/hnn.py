"""The Hamiltonian neural network (torch): H = MLP([x, y, extra]); (xdot, ydot) = (dH/dy, -dH/dx).

x, y (..., dof) are canonical (q, p), or deliberately non-canonical (q, qdot) to replicate the failure;
extra (..., extra_inputs) or None is fed to the MLP but not differentiated. x enters as the q part
(`models.torch.mlp.q_features`: wrapped with angle_wrap, cos and sin of the periodic coordinates).
The gradient is the MLP's hand-written reverse pass (`models.torch.mlp_derivatives`), not torch.func:
same values, plain differentiable ops (training backpropagates through it), and it goes through
torch.export (`models.torch.compiled`), which torch.func.grad does not.
"""
from __future__ import annotations

import torch

from lagbench.models.lorentz import lorentz_slopes, velocity_parts
from lagbench.models.torch.base import Model
from lagbench.models.torch.mlp import mlp, mlp_input, q_features, q_features_vjp
from lagbench.models.torch.mlp_derivatives import input_grad_and_tangent_hessian


class HNN(Model):
    def _hamiltonian(self, x, y, extra=None):
        z = mlp_input(self.spec, [q_features(self.spec, x), *velocity_parts(self.spec, y), *self._parts(extra)])
        return mlp(self.params, z, self.spec)[..., 0]

    def hamiltonian(self, x, y, extra=None):
        """H (...,)."""
        self._check_state(x, y, extra)
        return self._hamiltonian(x, y, extra)

    def time_derivative(self, x, y, extra=None):
        """(xdot, ydot) = (dH/dy, -dH/dx), each (..., dof)."""
        self._check_state(x, y, extra)
        spec, d, nq = self.spec, x.shape[-1], self.spec.q_width()
        z = mlp_input(spec, [q_features(spec, x), *velocity_parts(spec, y), *self._parts(extra)])
        g, _ = input_grad_and_tangent_hessian(self.params, z.reshape(-1, z.shape[-1]), None, spec)
        if spec.input_scale is not None:
            g = g * torch.tensor(spec.input_scale, dtype=g.dtype, device=g.device)
        g = g.reshape(*z.shape[:-1], z.shape[-1])
        dh_dx = q_features_vjp(spec, x, g[..., :nq])   # (dq_features/dx)^T: wrapping has slope 1
        dh_dy = g[..., nq:nq + d]
        if spec.lorentz_factor:   # y also enters as gamma(y), slot nq + d + k
            dh_dy = dh_dy + g[..., nq + d:nq + 2 * d] * lorentz_slopes(y)[0]
        if spec.dissipation:   # Rayleigh D = 1/2 sum b xdot^2: the momentum loses b * dH/dy
            return dh_dy, -dh_dx - torch.nn.functional.softplus(self.params["dissipation.raw"]) * dh_dy
        return dh_dy, -dh_dx
