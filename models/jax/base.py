"""The JAX model base: an equinox Module holding exactly the parameter dict and the static spec.
Public model methods are wrapped in eqx.filter_jit (compiled once per spec and input shape; they
inline under an outer jit or grad).

`Model(params, spec)`: params is {key: jax.Array} in the `models.params` layout, spec a ModelSpec.
Input checks raise ValueError (shape) / TypeError (dtype) naming what was expected and what came.
"""
from __future__ import annotations

import equinox as eqx

from lagbench.models.checks import check_input, check_state
from lagbench.models.spec import ModelSpec


class Model(eqx.Module):
    params: dict
    spec: ModelSpec = eqx.field(static=True)

    def _check(self, name: str, x, width: int | None, like=None):
        """x must be (..., width) (any width if None), of spec.dtype, and shaped like `like`."""
        check_input(self.spec, name, x, width, like)

    def _check_state(self, q, qdot, extra=None, width=None):
        check_state(self.spec, q, qdot, extra, width)

    def _parts(self, extra):
        return [] if extra is None or not self.spec.extra_inputs else [extra]
