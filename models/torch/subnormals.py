"""Subnormal floats in lagbench's PyTorch: flushed to zero, as XLA does on the CPU.

A float below the smallest normal number (1.2e-38 in float32, 2.2e-308 in float64) is subnormal; the CPU
computes with one through a slow path, many times the cost of a normal operation. A softplus LNN's second
derivatives underflow there as it trains (the pre-activations of its saturated units), so its step slows as
training goes on: a trained relativistic-particle LNN's loss and gradient take 7 x as long with subnormals kept
as flushed (`docs/decisions/subnormal_floats.md`). XLA on the CPU flushes them to zero (denormals-are-zero and
flush-to-zero), PyTorch keeps them unless told otherwise: `flush()` tells it, from the import of
`lagbench.models.torch` on, so the two frameworks compute alike and PyTorch's step keeps its pace. The values
flushed are below 1.2e-38: a gradient entry that small moves no float32 parameter.

The setting is the CPU's, per thread, and a thread takes it from the thread that starts it: threads that
PyTorch's intra-op pool started before `flush()` keep subnormals, so it runs before lagbench computes
anything with PyTorch (the package's import, a worker's start: `replication.run.environment.worker_start`).
Being the CPU's, it holds for NumPy in those threads too (float64's subnormals lie below 2.2e-308).

`mode() -> "flushed" | "kept"`: what this thread does, measured; units record it (`environment.hardware`).
"""
from __future__ import annotations

import torch

SMALLEST_NORMAL = float(torch.finfo(torch.float32).tiny)


def flush() -> None:
    """Flush subnormal results and inputs to zero in this thread and in every thread it starts from now on."""
    torch.set_flush_denormal(True)


def mode() -> str:
    """"flushed" where a subnormal float32 comes out as zero in this thread, else "kept"."""
    x = torch.tensor([SMALLEST_NORMAL], dtype=torch.float32) * 0.25
    return "flushed" if x.item() == 0.0 else "kept"
