"""Single-sample model calls compiled ahead of time: one call = one XLA dispatch (for online control).

    f = compile_single(model, method="inverse_dynamics", dtype=None, batch=None, freeze=False)
    tau = f(q, qdot, qddot)          # each (dof,) (or (batch, dof)); returns a jax.Array, e.g. (dof,)

The model's public methods are `eqx.filter_jit`-wrapped: every call flattens the equinox Module (its
parameter dict) and looks up the compiled program in a cache, which at one sample costs several times
the computation. `compile_single` instead lowers and compiles `jax.jit(pure)(leaves, *inputs)` once for
fixed input shapes (`jax.jit(...).lower(...).compile()`), where `pure` rebuilds the model from the list
of parameter arrays and calls `method`; the returned `CompiledMethod` holds the leaves and forwards each
call straight to the compiled executable. The numbers are those of `getattr(model, method)(*inputs)`.

Arguments:
  method: any array-in, array-out model method (e.g. "inverse_dynamics" (q, qdot, qddot) -> tau,
      "acceleration" (q, qdot[, tau]) -> qddot, "mass_matrix" (q,) -> (dof, dof)).
  dtype: the dtype of inputs and computation (default the model's spec.dtype); parameters are cast.
  batch: None for single samples of shape (dof,), or an int for (batch, dof) inputs.
  n_inputs: how many (.., width) inputs the method takes (default: its required positional arguments).
  width: the trailing size of each input (default spec.dof).
  freeze: compile the parameters in as constants (XLA may fold and pre-layout them; faster per call,
      but a parameter update needs a new `compile_single`).
  compiler_options: passed to `Lowered.compile` (XLA debug options, e.g. {"xla_cpu_multi_thread_eigen": False}).
Inputs must already have the compiled shape and dtype (NumPy or JAX arrays); anything else raises.

Latency note (CPU): by default JAX executes CPU programs on a worker thread (async dispatch), which
costs a thread hand-off per call (on two busy shared cores, about half the single-sample time). For a
control loop call `use_sync_dispatch()` (= `jax.config.update("jax_cpu_enable_async_dispatch", False)`)
before the first JAX array is created: the CPU client reads the flag once, when it starts.
`async_dispatch()` reports the setting in force.
"""
from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from lagbench.models.checks import n_required_inputs

__all__ = ["CompiledMethod", "async_dispatch", "compile_single", "use_sync_dispatch"]


class CompiledMethod:
    """A model method compiled for fixed input shapes; `f(*inputs)` runs it (one XLA dispatch)."""

    def __init__(self, compiled, leaves, frozen, method, in_shape, dtype):
        self.compiled, self.method, self.in_shape, self.dtype = compiled, method, in_shape, dtype
        self.leaves, self.frozen = leaves, frozen

    def __call__(self, *inputs):
        if self.frozen:
            return self.compiled(*inputs)
        return self.compiled(self.leaves, *inputs)

    def cost_analysis(self):
        """XLA's cost analysis of the compiled program (flops, bytes accessed), or None."""
        cost = self.compiled.cost_analysis()
        return cost[0] if isinstance(cost, list | tuple) and cost else cost


def compile_single(model, method: str = "inverse_dynamics", dtype=None, batch: int | None = None,
                   n_inputs: int | None = None, width: int | None = None, freeze: bool = False,
                   compiler_options: dict | None = None) -> CompiledMethod:
    """Compile `getattr(model, method)` ahead of time for inputs of shape (width,) or (batch, width)."""
    spec = model.spec
    dtype = jnp.dtype(dtype or spec.dtype)
    if dtype.name != spec.dtype:
        spec = dataclasses.replace(spec, dtype=dtype.name)
    if not callable(getattr(model, method, None)):
        raise ValueError(f"{spec.kind} model has no method {method!r}")
    keys = sorted(model.params)
    leaves = [jnp.asarray(model.params[k], dtype) for k in keys]
    cls = type(model)
    n = n_required_inputs(getattr(cls, method)) if n_inputs is None else int(n_inputs)
    shape = (spec.dof if width is None else width,)
    shape = shape if batch is None else (int(batch), *shape)
    example = [jax.ShapeDtypeStruct(shape, dtype) for _ in range(n)]

    def pure(ps, *xs):
        return getattr(cls(dict(zip(keys, ps, strict=True)), spec), method)(*xs)

    if freeze:
        lowered = jax.jit(lambda *xs: pure(leaves, *xs)).lower(*example)
    else:
        lowered = jax.jit(pure).lower(leaves, *example)
    return CompiledMethod(lowered.compile(compiler_options), leaves, freeze, method, shape, dtype)


def async_dispatch() -> bool:
    """Whether JAX's CPU client runs programs on a worker thread (the `jax_cpu_enable_async_dispatch` flag)."""
    return bool(jax.config.read("jax_cpu_enable_async_dispatch"))


def _backend_started() -> bool:
    try:
        from jax._src import xla_bridge
        return bool(xla_bridge.backends_are_initialized())
    except (ImportError, AttributeError):  # private API moved: assume started (the caller then refuses)
        return True


def use_sync_dispatch() -> bool:
    """Run CPU programs inline in the calling thread; True if that is now in force. Only possible before
    JAX's backend starts (the first array or compile): afterwards it changes nothing and returns False
    unless sync dispatch was already on."""
    if not async_dispatch():
        return True
    if _backend_started():
        return False
    jax.config.update("jax_cpu_enable_async_dispatch", False)
    return True
