"""The PyTorch model base: an nn.Module whose parameters are exactly the parameter dict.

`Model(spec, params)`: params {key: array} in the `models.params` layout; each key "a.b.c" becomes the
nn.Parameter "c" of nested submodule "a.b", so `dict(model.named_parameters())` has the same keys.
`model.params` is that dict (what the pure functions take). Input checks mirror `models.jax.base`.
"""
from __future__ import annotations

import numpy as np
import torch
from torch import nn

from models.spec import ModelSpec

DTYPE = {"float32": torch.float32, "float64": torch.float64}


class Model(nn.Module):
    def __init__(self, spec: ModelSpec, params: dict):
        super().__init__()
        self.spec = spec
        for key, value in params.items():
            *path, leaf = key.split(".")
            mod = self
            for name in path:
                if name not in mod._modules:
                    mod.add_module(name, nn.Module())
                mod = mod._modules[name]
            data = torch.tensor(np.asarray(value, dtype=spec.dtype))
            mod.register_parameter(leaf, nn.Parameter(data))

    @property
    def params(self) -> dict:
        return dict(self.named_parameters())

    def _check(self, name: str, x, width: int | None, like=None):
        """x must be (..., width) (any width if None), of spec.dtype, and shaped like `like`."""
        if x is None:
            raise ValueError(f"{self.spec.kind}: {name} is required (shape (..., {width}))")
        if x.ndim < 1 or (width is not None and x.shape[-1] != width):
            raise ValueError(f"{self.spec.kind}: expected {name} of shape (..., {width}), got shape {tuple(x.shape)}")
        if like is not None and x.shape[:-1] != like.shape[:-1]:
            raise ValueError(f"{self.spec.kind}: {name} has batch shape {tuple(x.shape[:-1])}, "
                             f"expected {tuple(like.shape[:-1])} (as q)")
        if x.dtype != DTYPE[self.spec.dtype]:
            raise TypeError(f"{self.spec.kind}: {name} has dtype {x.dtype}, the model is {self.spec.dtype}")

    def _check_state(self, q, qdot, extra=None, width=None):
        width = self.spec.dof if width is None else width
        self._check("q", q, width)
        self._check("qdot", qdot, q.shape[-1], like=q)
        if qdot.shape != q.shape:
            raise ValueError(f"{self.spec.kind}: qdot shape {tuple(qdot.shape)} != q shape {tuple(q.shape)}")
        if self.spec.extra_inputs:
            self._check("extra", extra, self.spec.extra_inputs, like=q)
        elif extra is not None:
            raise ValueError(f"{self.spec.kind}: got extra inputs but spec.extra_inputs == 0")

    def _parts(self, extra):
        return [] if extra is None or not self.spec.extra_inputs else [extra]
