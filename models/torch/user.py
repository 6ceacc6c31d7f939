"""A user's PyTorch module as a suite model (`models.user`): its parameters are the suite's parameter dict
(`models.torch.base.Model`), and q-double-dot is the user's forward(q, qdot) run on them with
torch.func.functional_call (or, for a module that declares `returns = "lagrangian"`, the suite's
Euler-Lagrange step of the scalar it returns; `returns = "hamiltonian"`, Hamilton's equations), so training, checkpoints, members (torch.func.vmap) and
evaluation treat it like any other kind."""
from __future__ import annotations

import torch
from torch.func import functional_call, grad

from lagbench.models import user
from lagbench.models.torch.base import Model
from lagbench.models.torch.lnn import euler_lagrange


class UserModel(Model):
    def __init__(self, spec, params, members=None):
        super().__init__(spec, params, members)
        object.__setattr__(self, "_net", user.make_module(spec))   # held apart: its parameters are self's

    def _forward(self, q, qdot):
        return user.forward(self.spec, self._net, functional_call, self._net, dict(self.named_parameters()), (q, qdot))

    def acceleration(self, q, qdot, extra=None):
        self._check_state(q, qdot, extra)
        if user.returns(self._net) == "lagrangian":   # L(q, qdot) (...,): the suite's Euler-Lagrange step
            return euler_lagrange(lambda a, b: user.scalar(self.spec, self._forward(a, b), a), q, qdot)
        out = self._forward(q, qdot)
        user.check_output(self.spec, out, q)
        return out

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration, 0): no fallback exists."""
        return self.acceleration(q, qdot, extra), torch.zeros((), dtype=torch.int64, device=q.device)

    def time_derivative(self, x, y, extra=None):
        """A Hamiltonian module's (xdot, ydot) = (dH/dy, -dH/dx), H = forward(x, y) (...,): Hamilton's equations."""
        self._check_state(x, y, extra)
        if user.returns(self._net) != "hamiltonian":
            raise ValueError(f"--add-model {self.spec.own.factory}: time_derivative is for a module that returns a "
                             f"Hamiltonian (returns = 'hamiltonian')")
        dh_dx, dh_dy = grad(lambda a, b: user.scalar(self.spec, self._forward(a, b), a).sum(), argnums=(0, 1))(x, y)
        return dh_dy, -dh_dx
