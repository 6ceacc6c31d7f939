"""Cache blocking for large batches (PyTorch): a per-sample-independent function run on row blocks in turn.

`in_row_blocks(fn, tensors, rows_per_sample) -> fn(*tensors)`
  tensors: (B, ...) tensors or None, fn acting on each sample independently; the result (a pytree of
  (B, ...) tensors) is the same as one call, computed by a Python loop over the equal blocks of
  `models.row_blocks.block_plan` (the last padded with copies of sample 0; the padding is sliced off).
  Batches up to two blocks run as one call, and so does every batch off the CPU (no cache to fit).
The mirror of `models.jax.blocking` (same plan, same samples per block; a loop instead of `lax.map`).
Where: around a compiled library (`models.torch.compiled.BlockedMethod`, one call per block); the eager
PyTorch models compute in one call (blocking them gained nothing reliable, `models.row_blocks`).
"""
from __future__ import annotations

import torch
from torch.utils._pytree import tree_flatten, tree_unflatten

from lagbench.models.row_blocks import block_plan, block_size  # noqa: F401 - block_size re-exported


def _pad(x, pad):
    return torch.cat([x, x[:1].expand(pad, *x.shape[1:])]) if pad else x


def in_row_blocks(fn, tensors, rows_per_sample: int):
    """fn(*tensors) computed block by block over the leading axis; see the module docstring."""
    n = tensors[0].shape[0]
    plan = block_plan(n, rows_per_sample)
    if plan is None or tensors[0].device.type != "cpu":
        return fn(*tensors)
    n_blocks, block = plan
    pad = n_blocks * block - n
    padded = [None if x is None else _pad(x, pad) for x in tensors]
    outs = [tree_flatten(fn(*(None if x is None else x[k * block:(k + 1) * block] for x in padded)))
            for k in range(n_blocks)]
    leaves = [torch.cat([o[0][j] for o in outs])[:n] for j in range(len(outs[0][0]))]
    return tree_unflatten(leaves, outs[0][1])
