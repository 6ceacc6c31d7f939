"""How large batches are cut into cache-sized row blocks (shared by both frameworks; NumPy only).

`block_size(rows_per_sample) = max(8, BLOCK_ROWS // rows_per_sample)`
  rows_per_sample: the rows each sample adds to the widest intermediate (the LNN carries d + 1 tangent
  rows per sample through every layer). BLOCK_ROWS = 1024 keeps a (rows, 600) float32 activation at
  ~2.5 MB, inside this machine's 32 MB L3 with the layer's other operands.
`block_plan(n, rows_per_sample) -> (n_blocks, block) | None`
  n samples as n_blocks equal blocks of `block` samples (the last padded with fewer than n_blocks
  samples); None where the batch is at most two blocks and runs as one call (training batches never block).
`rows_per_sample(spec) -> int | None`
  what a model blocks with: the LNN (both formulations) and the LGN's dense and paper paths carry
  dof + 1 tangent rows per sample; None for the models computed in one call (HNN, DeLaN, baseline, the
  banded LGN, whose band needs at most 8r + 2 tangents).
Users: `models.jax.blocking` (lax.map over the blocks inside the model, CPU only) and its mirror
`models.torch.blocking` (a compiled library called once per block, `models.torch.compiled.BlockedMethod`;
eager PyTorch gained nothing reliable).
"""
from __future__ import annotations

from lagbench.models.graph import banded_supported

BLOCK_ROWS = 1024


def block_size(rows_per_sample: int) -> int:
    return max(8, BLOCK_ROWS // max(1, rows_per_sample))


def block_plan(n: int, rows_per_sample: int) -> tuple[int, int] | None:
    target = block_size(rows_per_sample)
    if n <= 2 * target:
        return None
    n_blocks = -(-n // target)
    return n_blocks, -(-n // n_blocks)  # equal blocks: at most n_blocks - 1 padded samples


def rows_per_sample(spec) -> int | None:
    if spec.kind == "lnn":
        return spec.dof + 1
    if spec.kind != "lgn":
        return None
    banded = spec.own.formulation in ("banded", "fast") and banded_supported(spec.dof, spec.own.radius)
    return None if banded else spec.dof + 1
