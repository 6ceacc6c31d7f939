"""Single-sample model calls compiled ahead of time (PyTorch): one call = one compiled C++ function.

    f = compile_single(model, method="inverse_dynamics", batch=None, n_inputs=None, width=None)
    tau = f(q, qdot, qddot)          # torch tensors, each (dof,) (or (batch, dof)) -> a tensor, e.g. (dof,)

The PyTorch mirror of `models.jax.compiled.compile_single(..., freeze=True)`. Eager PyTorch pays a fixed
dispatch cost for every ATen operator (4-10 us here); DeLaN's inverse dynamics on one sample is ~115
operators, so eager stops near 1e3 calls per second whatever the arithmetic. `compile_single` exports
the method for fixed input shapes (`torch.export.export`, the parameters captured as constants: a
parameter update needs a new `compile_single`) and compiles the graph with AOTInductor
(`torch._inductor.aoti_compile_and_package`) into one shared library of fused C++ kernels, loaded back
with `aoti_load_package`. The numbers are those of `getattr(model, method)(*inputs)` up to float
rounding (fused kernels reassociate sums).

Costs and requirements: compiling takes 15-40 s and needs a C++ compiler (gcc; what inductor uses on
CPU). The compiled kernels use OpenMP: for a one-core control loop set OMP_NUM_THREADS=1 before the
process starts (measured: DeLaN 3 x 128 one-sample inverse dynamics 12.3k calls/s with it, 6.5k without,
eager 1.0-1.3k). Inputs must already have the compiled shape and dtype (torch tensors); anything else
raises a ValueError naming the input.
"""
from __future__ import annotations

import os
import tempfile
import warnings

import torch
from torch.utils._pytree import tree_flatten, tree_unflatten

from models.checks import n_required_inputs

__all__ = ["CompiledMethod", "compile_single"]


class _Method(torch.nn.Module):
    def __init__(self, model, method):
        super().__init__()
        self.model, self.method = model, method

    def forward(self, *xs):
        return getattr(self.model, self.method)(*xs)


class CompiledMethod:
    """A model method compiled for fixed input shapes; `f(*inputs)` runs it (one call into the library).

    The call goes straight to the package's loader (`runner.loader.run(list)`) and rebuilds the output
    with its tree spec: the package's own `__call__` flattens and checks the inputs as a pytree first,
    which costs more than DeLaN's whole one-sample computation (measured 9.5k calls/s through it, 20k
    direct)."""

    def __init__(self, runner, method, in_shape, dtype, n_inputs, out_spec):
        self.runner, self.method, self.in_shape, self.dtype, self.n_inputs = runner, method, in_shape, dtype, n_inputs
        self._run, self._out_spec = runner.loader.run, out_spec
        self._single = out_spec.is_leaf()

    def __call__(self, *inputs):
        if len(inputs) != self.n_inputs:
            raise ValueError(f"{self.method} was compiled for {self.n_inputs} inputs, got {len(inputs)}")
        xs = []
        for i, x in enumerate(inputs):
            if not isinstance(x, torch.Tensor) or x.shape != self.in_shape or x.dtype != self.dtype:
                got = (f"{tuple(x.shape)} {x.dtype}" if isinstance(x, torch.Tensor) else type(x).__name__)
                raise ValueError(f"{self.method} input {i}: compiled for a {self.in_shape} {self.dtype} tensor, "
                                 f"got {got}")
            xs.append(x if x.is_contiguous() else x.contiguous())  # the kernels index memory densely
        out = self._run(xs)
        return out[0] if self._single else tree_unflatten(out, self._out_spec)


def compile_single(model, method: str = "inverse_dynamics", batch: int | None = None,
                   n_inputs: int | None = None, width: int | None = None) -> CompiledMethod:
    """Compile `getattr(model, method)` ahead of time for inputs of shape (width,) or (batch, width)."""
    spec = model.spec
    if not callable(getattr(model, method, None)):
        raise ValueError(f"{spec.kind} model has no method {method!r}")
    n = n_required_inputs(getattr(type(model), method)) if n_inputs is None else int(n_inputs)
    shape = (spec.dof if width is None else width,)
    shape = shape if batch is None else (int(batch), *shape)
    dtype = getattr(torch, spec.dtype)
    example = tuple(torch.zeros(shape, dtype=dtype) for _ in range(n))
    with tempfile.TemporaryDirectory(prefix="lagbench_aoti_") as tmp, torch.no_grad(), warnings.catch_warnings():
        # torch's own deprecation notices from inside export (nothing a caller can act on)
        warnings.simplefilter("ignore", FutureWarning)
        program = torch.export.export(_Method(model, method).eval(), example)
        path = torch._inductor.aoti_compile_and_package(program, package_path=os.path.join(tmp, f"{method}.pt2"))
        runner = torch._inductor.aoti_load_package(path)
        out_spec = tree_flatten(getattr(model, method)(*example))[1]
    return CompiledMethod(runner, method, shape, dtype, n, out_spec)
