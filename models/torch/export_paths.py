"""Which variant a PyTorch model runs inside a captured graph, decided here and nowhere else.

A model's maths (`models.torch.lnn`, `delan`, `lgn`) is written for eager PyTorch. Where a captured graph
cannot take that code as it is (a Python branch on data, a torch.func transform export cannot flatten, a
LAPACK call AOTInductor runs slowly), the model writes the graph-safe variant beside it and lets one
call here pick. The captures:
  traced:    make_fx is tracing: `models.torch.compiled.trace_flat` (the speed study's "traced" mode);
             `get_proxy_mode()` is set.
  exporting: torch.export: `models.torch.compiled.compile_batched` / `compile_single` (AOTInductor).
  vmapped:   the tensor is batched by torch.func.vmap (stacked members trained side by side).
  compiling: torch.compile (dynamo) is capturing a training loss (`replication.training.compile_torch`);
             not torch.export, which is `exporting`.

`pick(eager, traced=None, exporting=None, compiled=None)` -> the variant to call: `traced` while make_fx
  traces (if given), else `exporting` under torch.export (if given), else `compiled` under torch.compile
  (if given), else `eager`.
`replace_bad_rows(x (..., d), bad (...,), fix, hess, rhs) -> (..., d)`: x with the rows where bad is True
  replaced by those of fix(hess, rhs) (..., d), with no Python branch on data in a captured graph.
No JAX twin: a JAX model is always traced by jit, so it has one path, already graph-safe (`lax.cond`).
"""
from __future__ import annotations

import torch
from torch.fx.experimental.proxy_tensor import get_proxy_mode


def compiling() -> bool:
    """Whether torch.compile is capturing this call (not torch.export, which also counts as compiling)."""
    return torch.compiler.is_compiling() and not torch.compiler.is_exporting()


def tracing() -> bool:
    """Whether make_fx is tracing this call (`models.torch.compiled.trace_flat`); never under torch.compile,
    which cannot capture the proxy-mode lookup."""
    return not compiling() and get_proxy_mode() is not None


def exporting() -> bool:
    """Whether torch.export is capturing this call."""
    return torch.compiler.is_exporting()


def vmapped(x) -> bool:
    """Whether x is batched by torch.func.vmap (stacked members, `replication.training.train_torch`)."""
    return torch._C._functorch.is_batchedtensor(x)


def pick(eager, traced=None, exporting=None, compiled=None):
    """The variant to run now: traced while make_fx traces, exporting under torch.export, compiled under
    torch.compile (each only if given), else eager. All variants take the same arguments and give the same
    numbers."""
    if traced is not None and tracing():
        return traced
    if exporting is not None and torch.compiler.is_exporting():
        return exporting
    if compiled is not None and compiling():
        return compiled
    return eager


def replace_bad_rows(x, bad, fix, hess, rhs):
    """x (..., d) with the rows where bad (...,) is True taken from fix(hess, rhs) (..., d), computed:
      eager: only when some row is bad (a Python branch on data);
      traced with gradients, vmapped, or under torch.compile: always, on every row (no branch on data);
      traced without gradients, or exporting: inside a torch.cond on any(bad), so it runs only where a
        row is bad. Its operands are made contiguous: export of a make_fx graph whose cond takes a strided
        view (the dense LGN's Hessian) failed in placeholder naming (torch 2.13)."""
    traced = tracing()
    if (traced and torch.is_grad_enabled()) or compiling():
        return torch.where(bad[..., None], fix(hess, rhs), x)
    if traced or torch.compiler.is_exporting():
        operands = (hess.contiguous(), rhs.contiguous(), bad, x.contiguous())
        return torch.cond(torch.any(bad), lambda h, r, b, y: torch.where(b[..., None], fix(h, r), y),
                          lambda h, r, b, y: y.clone(), operands)
    if vmapped(hess) or bool(torch.any(bad)):
        return torch.where(bad[..., None], fix(hess, rhs), x)
    return x
