"""The PyTorch model base: an nn.Module whose parameters are exactly the parameter dict.

`Model(spec, params)`: params {key: array} in the `models.params` layout; each key "a.b.c" becomes the
nn.Parameter "c" of nested submodule "a.b", so `dict(model.named_parameters())` has the same keys.
`model.params` is that dict (what the pure functions take). Input checks: `models.checks` (shared with the JAX base).
Stacked members (`members=K`, built by `models.torch.build.build_stacked`): every parameter has a leading
axis of K models and every input a leading K, (K, ..., width); the kinds whose maths is written for that
say so in `stacks(spec)` (the members then train without torch.func.vmap, `replication.training.train_torch`).
"""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from lagbench.models.checks import check_input, check_state
from lagbench.models.spec import ModelSpec


class Model(nn.Module):
    def __init__(self, spec: ModelSpec, params: dict, members: int | None = None):
        super().__init__()
        self.spec, self.members = spec, members
        for key, value in params.items():
            *path, leaf = key.split(".")
            mod = self
            for name in path:
                if name not in mod._modules:
                    mod.add_module(name, nn.Module())
                mod = mod._modules[name]
            data = torch.tensor(np.asarray(value, dtype=spec.dtype))
            mod.register_parameter(leaf, nn.Parameter(data))

    @classmethod
    def stacks(cls, spec: ModelSpec) -> bool:
        """Whether this kind's maths takes stacked members (a leading K on parameters and inputs) for spec."""
        return False

    @classmethod
    def compiles(cls, spec: ModelSpec) -> bool:
        """Whether a training loss of this kind is run under torch.compile (`replication.training.compile_torch`):
        its maths is plain tensor ops with no torch.func transform, as for the kinds that stack, and compiling
        it pays."""
        return cls.stacks(spec)

    def _rows(self, x, width: int | None = None):
        """x (..., width) as the flat batch the maths runs on: (B, width), or (K, B, width) for stacked
        members; None stays None."""
        if x is None:
            return None
        width = x.shape[-1] if width is None else width
        return x.reshape(-1, width) if self.members is None else x.reshape(self.members, -1, width)

    @property
    def params(self) -> dict:
        return dict(self.named_parameters())

    def _check(self, name: str, x, width: int | None, like=None):
        """x must be (..., width) (any width if None), of spec.dtype, and shaped like `like`."""
        check_input(self.spec, name, x, width, like)

    def _check_state(self, q, qdot, extra=None, width=None):
        check_state(self.spec, q, qdot, extra, width)

    def _parts(self, extra):
        return [] if extra is None or not self.spec.extra_inputs else [extra]
