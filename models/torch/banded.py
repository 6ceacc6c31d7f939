"""Solve a cyclic-banded system in O(n) (PyTorch): bordered block-tridiagonal elimination.

Mirrors `models.jax.banded` (see its docstring).
solve_cyclic_banded(band (B, n, 2w+1), rhs (B, n), layout) -> x (B, n).
"""
from __future__ import annotations

import torch

from lagbench.models.graph import band_columns


def _gather(band, triple):
    rows, cols, mask = triple
    return torch.where(torch.as_tensor(mask, device=band.device),
                       band[:, torch.as_tensor(rows, device=band.device), torch.as_tensor(cols, device=band.device)], 0.0)


def _solve_or_nan(a, b):
    """torch.linalg.solve without raising: a singular block gives NaN (as JAX does), left to the
    caller's counted fallback."""
    x, info = torch.linalg.solve_ex(a, b)
    return torch.where((info != 0)[..., None, None], torch.full_like(x, float("nan")), x)


def _shift(a, step):
    """Blocks moved one place along axis 1, zero-filled: step +1 gives a[j-1] at j, -1 gives a[j+1]."""
    zero = torch.zeros_like(a[:, :1])
    return torch.cat([zero, a[:, :-1]], 1) if step > 0 else torch.cat([a[:, 1:], zero], 1)


def block_tridiagonal_solve(diag, lower, upper, rhs):
    """diag, lower, upper (B, m, w, w) (lower[:, 0] = upper[:, -1] = 0), rhs (B, m, w, k) -> (B, m, w, k).

    Block cyclic reduction: each level solves all odd-numbered blocks at once for
    x_o = f_o - a_o x_(o-1) - b_o x_(o+1) ([a, b, f] = D_o^-1 [L_o, U_o, r_o]), substitutes them into the
    even-numbered rows (a block-tridiagonal system of half the size, solved recursively) and recovers
    the odd blocks from the even ones: log2(m) levels of batched operations instead of m sequential
    block steps (eager PyTorch pays a fixed cost per operation; the sweep made the banded LGN's cost
    grow like n^1.33, measured). Same arithmetic class as block Thomas: LU with pivoting inside each
    block, none across blocks; a singular pivot block gives NaN for the caller's fallback."""
    bsz, m, w = diag.shape[0], diag.shape[1], diag.shape[-1]
    if m == 1:
        return _solve_or_nan(diag[:, 0], rhs[:, 0])[:, None]
    if m % 2:                                    # append a decoupled identity block (x = 0 there)
        eye = torch.eye(w, dtype=diag.dtype, device=diag.device).expand(bsz, 1, w, w)
        zero_w, zero_k = torch.zeros_like(diag[:, :1]), torch.zeros_like(rhs[:, :1])
        return block_tridiagonal_solve(torch.cat([diag, eye], 1), torch.cat([lower, zero_w], 1),
                                       torch.cat([upper, zero_w], 1), torch.cat([rhs, zero_k], 1))[:, :m]
    sol = _solve_or_nan(diag[:, 1::2], torch.cat([lower[:, 1::2], upper[:, 1::2], rhs[:, 1::2]], -1))
    a, b, f = sol[..., :w], sol[..., w:2 * w], sol[..., 2 * w:]
    lo_e, up_e = lower[:, 0::2], upper[:, 0::2]  # even block e = 2j couples to odd j - 1 and odd j
    x_even = block_tridiagonal_solve(diag[:, 0::2] - up_e @ a - lo_e @ _shift(b, 1), -lo_e @ _shift(a, 1),
                                     -up_e @ b, rhs[:, 0::2] - up_e @ f - lo_e @ _shift(f, 1))
    x_odd = f - a @ x_even - b @ _shift(x_even, -1)
    return torch.stack([x_even, x_odd], 2).reshape(rhs.shape)


class _ImplicitSolve(torch.autograd.Function):
    """Implicit gradient of the solve (see models.jax.banded.solve_cyclic_banded). Forward and backward
    are plain batched torch ops, so torch.func.vmap (stacked members) maps them as they are."""
    generate_vmap_rule = True

    @staticmethod
    def forward(band, rhs, layout):
        return _solve(band, rhs, layout)

    @staticmethod
    def setup_context(ctx, inputs, output):
        band, _, layout = inputs
        ctx.save_for_backward(band, output)
        ctx.layout = layout

    @staticmethod
    def backward(ctx, xbar):
        band, x = ctx.saved_tensors
        lam = _solve(band, xbar, ctx.layout)
        cols = torch.as_tensor(band_columns(x.shape[-1], band.shape[-1]), device=x.device)
        return -lam[:, :, None] * x[:, cols], lam, None


def solve_cyclic_banded(band, rhs, layout):
    """x (B, n) with H x = rhs for a symmetric H given by its cyclic band (B, n, 2w+1); differentiated
    implicitly (mirrors models.jax.banded.solve_cyclic_banded)."""
    return _ImplicitSolve.apply(band, rhs, layout)


def _solve(band, rhs, layout):
    m, w, nb = layout["m"], layout["w"], layout["nb"]
    bsz, ni = rhs.shape[0], layout["m"] * layout["w"]
    col_border = _gather(band, layout["col_border"])
    stacked = torch.cat([rhs[:, :ni, None], col_border], dim=-1).reshape(bsz, m, w, 1 + nb)
    blocks = [_gather(band, layout[k]) for k in ("diag", "lower", "upper")]
    z_all = block_tridiagonal_solve(*blocks, stacked).reshape(bsz, ni, 1 + nb)
    z, x_border = z_all[..., 0], z_all[..., 1:]
    row_border = _gather(band, layout["row_border"])
    schur = _gather(band, layout["border"]) - row_border @ x_border
    y = _solve_or_nan(schur, (rhs[:, ni:] - (row_border @ z[..., None])[..., 0])[..., None])[..., 0]
    return torch.cat([z - (x_border @ y[..., None])[..., 0], y], dim=-1)
