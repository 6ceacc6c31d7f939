"""Solve a cyclic-banded system in O(n) (PyTorch): bordered block-tridiagonal elimination.

Mirrors `models.jax.banded` (see its docstring); the block sweeps are Python loops instead of lax.scan.
solve_cyclic_banded(band (B, n, 2w+1), rhs (B, n), layout) -> x (B, n).
"""
from __future__ import annotations

import torch

from models.graph import band_columns


def _gather(band, triple):
    rows, cols, mask = triple
    return torch.where(torch.as_tensor(mask), band[:, torch.as_tensor(rows), torch.as_tensor(cols)], 0.0)


def _solve_or_nan(a, b):
    """torch.linalg.solve without raising: a singular block gives NaN (as JAX does), left to the
    caller's counted fallback."""
    x, info = torch.linalg.solve_ex(a, b)
    return torch.where((info != 0)[:, None, None], torch.full_like(x, float("nan")), x)


def block_tridiagonal_solve(diag, lower, upper, rhs):
    """diag, lower, upper (B, m, w, w) (lower[:, 0] = upper[:, -1] = 0), rhs (B, m, w, k) -> (B, m, w, k)."""
    w, m = diag.shape[-1], diag.shape[1]
    c_prev, f_prev, cs, fs = torch.zeros_like(diag[:, 0]), torch.zeros_like(rhs[:, 0]), [], []
    for b in range(m):
        d, lo, up, r = diag[:, b], lower[:, b], upper[:, b], rhs[:, b]
        sol = _solve_or_nan(d - lo @ c_prev, torch.cat([up, r - lo @ f_prev], dim=-1))
        c_prev, f_prev = sol[..., :w], sol[..., w:]
        cs.append(c_prev)
        fs.append(f_prev)
    x_next, xs = torch.zeros_like(fs[0]), [None] * m
    for b in reversed(range(m)):
        x_next = fs[b] - cs[b] @ x_next
        xs[b] = x_next
    return torch.stack(xs, dim=1)


class _ImplicitSolve(torch.autograd.Function):
    """Implicit gradient of the solve (see models.jax.banded.solve_cyclic_banded)."""

    @staticmethod
    def forward(ctx, band, rhs, layout):
        x = _solve(band, rhs, layout)
        ctx.save_for_backward(band, x)
        ctx.layout = layout
        return x

    @staticmethod
    def backward(ctx, xbar):
        band, x = ctx.saved_tensors
        lam = _solve(band, xbar, ctx.layout)
        cols = torch.as_tensor(band_columns(x.shape[-1], band.shape[-1]))
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
