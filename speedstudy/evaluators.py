"""q-double-dot evaluators: one callable per (model, framework, dtype), and the error against truth.

`make_evaluator(framework, model_or_system, kind, dtype) -> Evaluator`:
  `ev.prepare(q, qdot)` converts float64 NumPy (B, d) states to the framework's arrays (outside timing);
  `ev.run(args)` blocks until q-double-dot (B, d) is computed (what is timed);
  `ev.numpy(args)` returns it as float64 NumPy (for the error column).
Models: "lnn" / "lgn" / "delan" (tau = 0) / "baseline" use `.acceleration`; "hnn" is used on the
non-canonical (q, qdot) (its second output is q-double-dot); "truth" is the SymPy-generated system
(`System.acceleration` with backend numpy | jax | torch). A model is built by the suite's NumPy view
(`replication.evaluation.adapters.adapter`) and mapped to q-double-dot by its `qddot`; what is timed
and counted here is the speed study's own program of that call. JAX calls are `jax.jit` of the model passed as
an argument (the weights are inputs of the compiled program, not folded constants), lowered and
compiled ahead of time on the first call per shape (the same object serves `flops` and `ops`); PyTorch
runs eagerly under `torch.no_grad()` (torch.func inside still differentiates), or with mode="aoti"
through `lagbench.models.torch.compiled.compile_batched` (torch.export + AOTInductor: one library for every
batch size, compiled when the evaluator is made, 10-25 s, once per intra-op thread count the rows are
timed at: inductor fixes a kernel's thread count when it compiles, `per_thread_count`). Not every model
exports: what differentiates with torch.func (the paper-formulation LNN's hessian, the dense LGN's
forward-over-reverse) fails inside torch.export (torch 2.13), which raises. The fast LNN, the HNN, DeLaN
and the banded LGN differentiate their MLPs by hand and export. Those two go through mode="traced" (`TorchTracedEvaluator`): make_fx traces the call
into plain ATen operators first (`lagbench.models.torch.compiled.trace_flat`), which exports and compiles, one
library per batch size. `ev.mode`: "jit", "eager", "aoti", "traced", "numpy".
`ev.ops(args)`: kernels per call, for the ratio notes: JAX the compiled program's top-level kernels
(fusions, dots, custom calls, ... in the optimised HLO's entry computation), PyTorch the ATen operators
one call dispatches (counted with a TorchDispatchMode); None for NumPy.
`median_rel_error(pred, true)`: median over samples of |pred - true| / |true| (Euclidean norms).
"""
from __future__ import annotations

import re

import jax
import jax.numpy as jnp
import numpy as np
import torch

import lagbench.models.jax  # noqa: F401 - float64 enabled on import (the evaluators' arrays may be float64)
from lagbench.models.row_blocks import rows_per_sample
from lagbench.models.torch.compiled import compile_batched
from lagbench.replication.evaluation.adapters import adapter, qddot
from lagbench.speedstudy.device import sync, to_numpy
from lagbench.speedstudy.timing import torch_thread_choices, torch_threads


def median_rel_error(pred, true) -> float:
    num = np.linalg.norm(np.asarray(pred, np.float64) - true, axis=-1)
    den = np.maximum(np.linalg.norm(true, axis=-1), 1e-300)
    return float(np.median(num / den))


def _model(framework: str, spec, params):
    """The model object of the suite's NumPy view (`replication.evaluation.adapters.adapter`): the speed
    study times the very model the evaluation judges, built in one place."""
    return adapter(framework, spec, params).model


FLOPS_ROWS = 16  # at most 2 * the smallest block (`lagbench.models.jax.blocking.block_size` >= 8): one block

_NOT_KERNELS = {"parameter", "constant", "bitcast", "tuple", "get-tuple-element"}


def xla_kernels(compiled) -> int:
    """Instructions of the optimised entry computation that run code (not parameters, constants, views)."""
    text = compiled.as_text()
    entry = text[text.index("ENTRY"):] if "ENTRY" in text else text
    ops = re.findall(r"=\s*\S+\s+([a-z][\w-]*)\(", entry)
    return sum(op not in _NOT_KERNELS for op in ops)


def torch_ops(fn) -> int:
    """ATen operators dispatched by one fn() call."""
    from torch.utils._python_dispatch import TorchDispatchMode

    class Count(TorchDispatchMode):
        n = 0

        def __torch_dispatch__(self, func, types, args=(), kwargs=None):
            Count.n += 1
            return func(*args, **(kwargs or {}))
    with Count():
        fn()
    return Count.n


class JaxEvaluator:
    framework, mode = "jax", "jit"

    def __init__(self, model, kind, dtype):
        self.model, self.kind, self.dtype = model, kind, jnp.dtype(dtype)
        self._fn = jax.jit(lambda m, q, qd: qddot(m, kind, q, qd))
        self._compiled = {}

    def prepare(self, q, qdot):
        return jnp.asarray(q, self.dtype), jnp.asarray(qdot, self.dtype)

    def compiled(self, args):
        key = tuple(a.shape for a in args)
        if key not in self._compiled:
            self._compiled[key] = self._fn.lower(self.model, *args).compile()
        return self._compiled[key]

    def run(self, args):
        # the ahead-of-time compiled program for this shape (compiled on the first call per shape)
        return jax.block_until_ready(self.compiled(args)(self.model, *args))

    def numpy(self, args):
        return np.asarray(self.run(args), np.float64)

    def ops(self, args) -> int:
        return xla_kernels(self.compiled(args))

    def flops(self, args) -> float | None:
        """FLOPs of one call from XLA's compiled cost analysis (None if unavailable). The analysis
        counts a loop body once, and large batches run in row blocks (`lagbench.models.jax.blocking`), so the
        call is costed on its first FLOPS_ROWS samples (never blocked) and scaled to the batch."""
        n = args[0].shape[0]
        m = min(n, FLOPS_ROWS)
        cost = self.compiled(tuple(a[:m] for a in args)).cost_analysis()
        if isinstance(cost, list | tuple):
            cost = cost[0] if cost else None
        return float(cost["flops"]) * n / m if cost and "flops" in cost else None


class TruthJax(JaxEvaluator):
    def __init__(self, system, dtype):
        self.model, self.kind, self.dtype = None, "truth", jnp.dtype(dtype)
        self._fn = jax.jit(lambda _, q, qd: system.acceleration(q, qd, backend="jax"))
        self._compiled = {}


class TorchEvaluator:
    framework, mode = "torch", "eager"

    def __init__(self, model, kind, dtype):
        self.model, self.kind, self.dtype = model, kind, getattr(torch, dtype)

    def prepare(self, q, qdot):
        return torch.as_tensor(q, dtype=self.dtype), torch.as_tensor(qdot, dtype=self.dtype)

    def _call(self, args):
        with torch.no_grad():
            return qddot(self.model, self.kind, *args)

    def run(self, args):
        out = self._call(args)
        sync()  # on a GPU: wait for the queued kernels
        return out

    def numpy(self, args):
        return to_numpy(self._call(args)).astype(np.float64)

    def ops(self, args) -> int:
        return torch_ops(lambda: self._call(args))


class TruthTorch(TorchEvaluator):
    def __init__(self, system, dtype):
        self.system, self.kind, self.dtype = system, "truth", getattr(torch, dtype)

    def _call(self, args):
        with torch.no_grad():
            return self.system.acceleration(*args, backend="torch")


def per_thread_count(compile_fn, counts=None) -> dict:
    """{threads: compile_fn()} compiled at each intra-op thread count a row is timed at (default
    `inference.torch_thread_choices()`). Inductor writes the count in force at compile time into its
    OpenMP kernels: a library compiled at 1 thread stays serial when timed at 2 (DeLaN float64, batch 256,
    interleaved: 71k samples/s compiled at 1 thread, 79k at 2, whatever the thread count at run time)."""

    out = {}
    for n in counts or torch_thread_choices():
        with torch_threads(n):
            out[n] = compile_fn()
    return out


def for_threads(libraries: dict):
    """The library compiled for the current intra-op thread count (else the nearest count compiled)."""
    n = torch.get_num_threads()
    return libraries[n] if n in libraries else libraries[min(libraries, key=lambda k: abs(k - n))]


class TorchAotEvaluator(TorchEvaluator):
    """PyTorch through `compile_batched`: one library for every batch size, compiled when made, at each
    thread count the rows are timed at (`per_thread_count`). rows: large batches are called in row blocks
    where the JAX model computes them so (`lagbench.models.row_blocks.rows_per_sample`)."""
    mode = "aoti"

    def __init__(self, fn, width, dtype, kind, rows=None):
        self.kind, self.dtype = kind, getattr(torch, dtype)
        self._libs = per_thread_count(lambda: compile_batched(fn, 2, width, dtype, name=f"{kind} q''",
                                                              rows_per_sample=rows))

    def _call(self, args):
        return for_threads(self._libs)(*args)

    def ops(self, args):
        return None  # one call into the compiled library


class TorchTracedEvaluator(TorchEvaluator):
    """PyTorch through `compile_batched(..., flatten=True)`: the call traced by make_fx (its torch.func
    transforms flattened into ATen operators), exported and compiled with AOTInductor, one library per
    batch size, compiled in `prepare` (outside the timing; 20-30 s each) at each thread count the rows are
    timed at (`per_thread_count`; batch 1 at one thread only: one sample has no parallel work). rows: as
    `TorchAotEvaluator`; a blocked batch size is compiled for its block size."""
    mode = "traced"

    def __init__(self, fn, width, dtype, kind, rows=None):
        self.kind, self.dtype, self._fn, self._width = kind, getattr(torch, dtype), fn, width
        self._dtype_name, self._by_batch, self._rows = dtype, {}, rows

    def prepare(self, q, qdot):
        args = super().prepare(q, qdot)
        b = int(args[0].shape[0])
        if b not in self._by_batch:
            self._by_batch[b] = per_thread_count(
                lambda: compile_batched(self._fn, 2, self._width, self._dtype_name, batch=b,
                                        name=f"{self.kind} q'' batch {b}", flatten=True, rows_per_sample=self._rows),
                counts=(1,) if b == 1 else None)
        return args

    def _call(self, args):
        return for_threads(self._by_batch[int(args[0].shape[0])])(*args)

    def ops(self, args):
        return None  # one call into the compiled library


class TruthNumpy:
    framework, mode = "numpy", "numpy"

    def __init__(self, system, dtype):
        self.system, self.kind, self.dtype = system, "truth", np.dtype(dtype)

    def prepare(self, q, qdot):
        return np.asarray(q, self.dtype), np.asarray(qdot, self.dtype)

    def run(self, args):
        return self.system.acceleration(*args, backend="numpy")

    def numpy(self, args):
        return np.asarray(self.run(args), np.float64)

    def ops(self, args):
        return None


def make_evaluator(framework: str, spec=None, params=None, kind=None, dtype="float32", system=None,
                   mode: str | None = None):
    """An evaluator for a model (spec + NumPy params) or, with kind="truth", for `system`; mode "aoti"
    (PyTorch only) compiles it ahead of time for any batch, "traced" (PyTorch models only) traces and
    compiles it per batch size, otherwise each framework's default (jit, eager)."""
    if mode == "aoti":
        if framework != "torch":
            raise ValueError(f"mode 'aoti' is PyTorch's; got framework {framework!r}")
        if kind == "truth":
            return TorchAotEvaluator(lambda q, qd: system.acceleration(q, qd, backend="torch"), system.dof,
                                     dtype, "truth")
        model = _model("torch", spec, params)
        return TorchAotEvaluator(lambda q, qd: qddot(model, spec.kind, q, qd), spec.dof, spec.dtype, spec.kind,
                                 rows_per_sample(spec))
    if mode == "traced":
        if framework != "torch" or kind == "truth":
            raise ValueError(f"mode 'traced' is for PyTorch models; got framework {framework!r}, kind {kind!r}")
        model = _model("torch", spec, params)
        return TorchTracedEvaluator(lambda q, qd: qddot(model, spec.kind, q, qd), spec.dof, spec.dtype,
                                    spec.kind, rows_per_sample(spec))
    if mode not in (None, "jit", "eager", "numpy"):
        raise ValueError(f"unknown evaluator mode {mode!r}; valid: jit, eager, numpy, aoti, traced")
    if kind == "truth":
        return {"jax": TruthJax, "torch": TruthTorch, "numpy": TruthNumpy}[framework](system, dtype)
    if framework == "jax":
        return JaxEvaluator(_model("jax", spec, params), spec.kind, spec.dtype)
    if framework == "torch":
        return TorchEvaluator(_model("torch", spec, params), spec.kind, spec.dtype)
    raise ValueError(f"unknown framework {framework!r}; valid: jax, torch (numpy for truth only)")
