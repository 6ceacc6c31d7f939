"""The JAX model base: an equinox Module holding exactly the parameter dict and the static spec.
Public model methods are wrapped in eqx.filter_jit (compiled once per spec and input shape; they
inline under an outer jit or grad).

`Model(params, spec)`: params is {key: jax.Array} in the `models.params` layout, spec a ModelSpec.
Input checks raise ValueError (shape) / TypeError (dtype) naming what was expected and what came.
"""
from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp

from models.spec import ModelSpec


class Model(eqx.Module):
    params: dict
    spec: ModelSpec = eqx.field(static=True)

    def _check(self, name: str, x, width: int | None, like=None):
        """x must be (..., width) (any width if None), of spec.dtype, and shaped like `like`."""
        if x is None:
            raise ValueError(f"{self.spec.kind}: {name} is required (shape (..., {width}))")
        if x.ndim < 1 or (width is not None and x.shape[-1] != width):
            raise ValueError(f"{self.spec.kind}: expected {name} of shape (..., {width}), got shape {tuple(x.shape)}")
        if like is not None and x.shape[:-1] != like.shape[:-1]:
            raise ValueError(f"{self.spec.kind}: {name} has batch shape {tuple(x.shape[:-1])}, "
                             f"expected {tuple(like.shape[:-1])} (as q)")
        if x.dtype != jnp.dtype(self.spec.dtype):
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
