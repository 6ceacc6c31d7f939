"""Model calls compiled ahead of time (PyTorch): one call = one compiled C++ function.

    f = compile_single(model, method="inverse_dynamics", batch=None, n_inputs=None, width=None)
    tau = f(q, qdot, qddot)          # torch tensors, each (dof,) (or (batch, dof)) -> a tensor, e.g. (dof,)
    g = compile_batched(fn, n_inputs=2, width=2, dtype="float32")
    qddot = g(q, qdot)               # any batch: (B, width) each; fn(*inputs) a torch function or Module

The PyTorch mirror of `models.jax.compiled.compile_single(..., freeze=True)`. Eager PyTorch pays a fixed
dispatch cost for every ATen operator (4-10 us here); DeLaN's inverse dynamics on one sample is ~115
operators, so eager stops near 1e3 calls per second whatever the arithmetic. `compile_single` exports
the method for fixed input shapes (`torch.export.export`, the parameters captured as constants: a
parameter update needs a new `compile_single`) and compiles the graph with AOTInductor
(`torch._inductor.aoti_compile_and_package`) into one shared library of fused C++ kernels, loaded back
with `aoti_load_package`. The numbers are those of `getattr(model, method)(*inputs)` up to float
rounding (fused kernels reassociate sums).

Costs and requirements: compiling takes 15-40 s and needs a C++ compiler (gcc; what inductor uses on
CPU) and a private folder for the generated code (`models.torch.inductor_cache`). The compiled kernels use
OpenMP: for a one-core control loop set OMP_NUM_THREADS=1 before the process starts (measured: DeLaN
3 x 128 one-sample inverse dynamics 12.3k calls/s with it, 6.5k without, eager 1.0-1.3k). Inputs must
already have the compiled shape and dtype (torch tensors); anything else raises a ValueError naming the
input. `compile_batched` exports with a dynamic batch dimension (one library for every batch size; the
speed study's "aoti" mode); code that fixes the batch size while
tracing fails there with torch's constraint error, and `compile_batched(..., batch=B)` compiles it for
that one batch size instead. `compile_batched(..., rows_per_sample=k)` calls large batches in cache-sized
row blocks (`BlockedMethod`, the blocks of `models.row_blocks`), as the JAX models compute them; a
fixed-batch library is then compiled for the block size.
"""
from __future__ import annotations

import inspect
import os
import warnings

import torch
from torch.fx.experimental.proxy_tensor import make_fx
from torch.utils._pytree import tree_flatten, tree_unflatten

from lagbench.models.checks import n_required_inputs
from lagbench.models.row_blocks import block_plan
from lagbench.models.torch import inductor_cache
from lagbench.models.torch.blocking import in_row_blocks

__all__ = ["BlockedMethod", "CompiledMethod", "compile_batched", "compile_single"]

MAX_BATCH = 1 << 20  # the largest batch a dynamic-batch library accepts


def _checked(method, inputs, in_shape, dtype, n_inputs) -> list:
    """The inputs, contiguous (the kernels index memory densely), after checking their count, dtype and
    shape against in_shape (None first: any batch up to MAX_BATCH); a ValueError names the first misfit."""
    if len(inputs) != n_inputs:
        raise ValueError(f"{method} was compiled for {n_inputs} inputs, got {len(inputs)}")
    dynamic = bool(in_shape) and in_shape[0] is None
    xs = []
    for i, x in enumerate(inputs):
        fits = isinstance(x, torch.Tensor) and x.dtype == dtype and (
            x.dim() == len(in_shape) and 1 <= x.shape[0] <= MAX_BATCH and x.shape[1:] == in_shape[1:]
            if dynamic else x.shape == in_shape)
        if not fits:
            got = (f"{tuple(x.shape)} {x.dtype}" if isinstance(x, torch.Tensor) else type(x).__name__)
            want = "(batch, " + ", ".join(map(str, in_shape[1:])) + ")" if dynamic else in_shape
            raise ValueError(f"{method} input {i}: compiled for a {want} {dtype} tensor, got {got}")
        xs.append(x if x.is_contiguous() else x.contiguous())
    return xs


class CompiledMethod:
    """A function compiled for fixed input shapes (None in in_shape[0]: any batch size); `f(*inputs)` runs
    it (one call into the library).

    The call goes straight to the package's loader (`runner.loader.run(list)`) and rebuilds the output
    with its tree spec: the package's own `__call__` flattens and checks the inputs as a pytree first,
    which costs more than DeLaN's whole one-sample computation (measured 9.5k calls/s through it, 20k
    direct)."""

    def __init__(self, runner, method, in_shape, dtype, n_inputs, out_spec):
        self.runner, self.method, self.in_shape, self.dtype, self.n_inputs = runner, method, in_shape, dtype, n_inputs
        self._run, self._out_spec = runner.loader.run, out_spec
        self._single = out_spec.is_leaf()

    def __call__(self, *inputs):
        out = self._run(_checked(self.method, inputs, self.in_shape, self.dtype, self.n_inputs))
        return out[0] if self._single else tree_unflatten(out, self._out_spec)


class BlockedMethod:
    """A compiled function called once per row block (`models.torch.blocking.in_row_blocks`, the mirror of
    `models.jax.blocking`): the inputs are padded with copies of sample 0 to equal blocks, each block is
    one call into `inner` (compiled for that block size, or for any batch), and the outputs (tensors with
    the batch first) are joined and the padding sliced off. Batches of at most two blocks go to `inner`
    in one call."""

    def __init__(self, inner: CompiledMethod, rows_per_sample: int, batch: int | None = None):
        self.inner, self.rows_per_sample, self.batch = inner, int(rows_per_sample), batch
        self.method, self.dtype, self.n_inputs = inner.method, inner.dtype, inner.n_inputs
        self.in_shape = (batch, *inner.in_shape[1:])

    def __call__(self, *inputs):
        xs = _checked(self.method, inputs, self.in_shape, self.dtype, self.n_inputs)
        return in_row_blocks(self.inner, xs, self.rows_per_sample)


class _Fn(torch.nn.Module):
    """A function (a bound model method, a closure) as the module torch.export takes; the tensors it
    reaches are captured as constants."""

    def __init__(self, fn):
        super().__init__()
        self.fn = fn

    def forward(self, *xs):
        return self.fn(*xs)


# For compile_single: inductor's pass that writes matrix products with one row (static shapes, CPU) as
# fused elementwise code instead of a call into ATen's mm. A one-sample DeLaN makes ~20 such calls, each
# a few us of overhead (inverse dynamics 18k -> 25k calls/s, measured). Not for compile_batched: the pass
# fails on the data-dependent sizes of the banded LGN's export (torch 2.13).
_ONE_ROW_MM_AS_ELEMENTWISE = {"post_grad_fusion_options": {"decompose_mm_pass": {}}}

# For compile_batched(flatten=True) at batch > 1: inductor's freezing folds the captured weights into the
# graph (pre-transposed, pre-packed for oneDNN). Measured on the paper LNN 3 x 128, one thread, samples/s
# without -> with: float32 b256 36.8k -> 39.5k, b4096 30.0k -> 38.2k; float64 b256 14.9k -> 19.6k, b4096
# 10.7k -> 11.8k. At batch 1 it is slower (3.2k -> 1.3k) and is left off; on the dynamic-batch export
# (the fast LNN, b4096) it gave nothing (68k -> 64k).
_FREEZE_WEIGHTS = {"freezing": True}


def _package(module, example, dynamic_shapes=None, inductor_configs=None):
    """(AOTI runner, output tree spec) of module(*example), exported and compiled in a scratch folder inside
    inductor's private cache (`models.torch.inductor_cache`; InductorCacheError without one)."""
    with inductor_cache.scratch("lagbench_aoti_") as tmp, torch.no_grad(), warnings.catch_warnings():
        # torch's own deprecation notices from inside export (nothing a caller can act on)
        warnings.simplefilter("ignore", FutureWarning)
        program = torch.export.export(module.eval(), example, dynamic_shapes=dynamic_shapes)
        path = torch._inductor.aoti_compile_and_package(program, package_path=os.path.join(tmp, "fn.pt2"),
                                                        inductor_configs=inductor_configs)
        runner = torch._inductor.aoti_load_package(path)
        out_spec = tree_flatten(module(*example))[1]
    return runner, out_spec


def trace_flat(fn, example: tuple) -> torch.fx.GraphModule:
    """fn(*example) as a graph of plain ATen operators, traced by make_fx on the (real) example tensors:
    torch.func transforms (vmap, jacrev, hessian) come out flattened, which torch.export cannot do with
    them inside (torch 2.13). The graph is for the example's shapes; data-dependent branches must use
    torch.cond while tracing (the models choose their traced variants in `models.torch.export_paths`)."""
    # torch.cond runs its branches through dynamo, which makes a size dynamic once it has seen two values
    # of it (another batch size traced in this process); the graph's export then fails on the size it
    # passes to the cond (torch 2.13). Each trace is for one batch size: keep sizes static.
    with torch.no_grad(), torch._dynamo.config.patch(automatic_dynamic_shapes=False):
        return make_fx(lambda *xs: fn(*xs))(*example)  # make_fx would trace every parameter of fn's signature


def compile_batched(fn, n_inputs: int, width: int, dtype: str = "float32", batch: int | None = None,
                    name: str = "fn", flatten: bool = False,
                    rows_per_sample: int | None = None) -> CompiledMethod | BlockedMethod:
    """Compile fn(*inputs), each input (B, width), for every batch size B (batch=None) or for B = batch.
    flatten: trace fn with `trace_flat` first (for functions built on torch.func; needs a batch).
    rows_per_sample: call large batches in row blocks (`BlockedMethod`; fn must act on each sample
    independently and return tensors with the batch first); with a batch, the library is compiled for
    the block size only."""
    if n_inputs < 1 or width < 1:
        raise ValueError(f"compile_batched needs n_inputs >= 1 and width >= 1, got {n_inputs}, {width}")
    if flatten and batch is None:
        raise ValueError("compile_batched(flatten=True) traces for one batch size: give batch")
    if rows_per_sample is not None and torch.get_default_device().type == "cpu":  # no cache to fit on a GPU
        plan = None if batch is None else block_plan(int(batch), rows_per_sample)
        inner = compile_batched(fn, n_inputs, width, dtype, batch if plan is None else plan[1], name, flatten)
        return BlockedMethod(inner, rows_per_sample, batch)
    dt = getattr(torch, dtype)
    if flatten:
        fn = trace_flat(fn, tuple(torch.zeros(int(batch), width, dtype=dt) for _ in range(n_inputs)))
    module = fn if isinstance(fn, torch.nn.Module) else _Fn(fn)
    if batch is None:
        dim = torch.export.Dim("batch", min=1, max=MAX_BATCH)
        example = tuple(torch.zeros(8, width, dtype=dt) for _ in range(n_inputs))  # 0 and 1 would specialise
        dims = tuple({0: dim} for _ in range(n_inputs))
        varargs = any(p.kind is p.VAR_POSITIONAL for p in inspect.signature(module.forward).parameters.values())
        runner, out_spec = _package(module, example, (dims,) if varargs else dims)
        return CompiledMethod(runner, name, (None, width), dt, n_inputs, out_spec)
    example = tuple(torch.zeros(int(batch), width, dtype=dt) for _ in range(n_inputs))
    configs = _FREEZE_WEIGHTS if flatten and int(batch) > 1 else None
    runner, out_spec = _package(module, example, inductor_configs=configs)
    return CompiledMethod(runner, name, (int(batch), width), dt, n_inputs, out_spec)


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
    runner, out_spec = _package(_Fn(getattr(model, method)), example, inductor_configs=_ONE_ROW_MM_AS_ELEMENTWISE)
    return CompiledMethod(runner, method, shape, dtype, n, out_spec)
