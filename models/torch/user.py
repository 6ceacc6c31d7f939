"""A user's PyTorch module as a suite model (`models.user`): its parameters are the suite's parameter dict
(`models.torch.base.Model`), and q-double-dot is the user's forward(q, qdot) run on them with
torch.func.functional_call, so training, checkpoints, members (torch.func.vmap) and evaluation treat it
like any other kind."""
from __future__ import annotations

import torch
from torch.func import functional_call

from models import user
from models.torch.base import Model


class UserModel(Model):
    def __init__(self, spec, params, members=None):
        super().__init__(spec, params, members)
        object.__setattr__(self, "_net", user.make_module(spec))   # held apart: its parameters are self's

    def acceleration(self, q, qdot, extra=None):
        self._check_state(q, qdot, extra)
        out = functional_call(self._net, dict(self.named_parameters()), (q, qdot))
        user.check_output(self.spec, out, q)
        return out

    def acceleration_info(self, q, qdot, extra=None):
        """(acceleration, 0): no fallback exists."""
        return self.acceleration(q, qdot, extra), torch.zeros((), dtype=torch.int64, device=q.device)
