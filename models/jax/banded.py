"""Solve a cyclic-banded system in O(n) (JAX): bordered block-tridiagonal elimination.

solve_cyclic_banded(band, rhs, layout): band (B, n, 2w+1) with band[b, i, k] = H[i, (i+k-w) mod n],
rhs (B, n) -> x (B, n) with H x = rhs; layout = `models.graph.cyclic_band_layout(n, r)`.
Interior nodes 0 .. m*w-1 form a block-tridiagonal matrix A (blocks w x w), eliminated by block
Thomas (dense LU with partial pivoting inside each block, none across blocks) with the border columns
as extra right-hand sides; the border (nb nodes) is then solved from its Schur complement. Cost
O(n w^2 nb). Non-finite results (a singular pivot block) are left to the caller's fallback.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
from jax import lax

from models.graph import band_columns


def _gather(band, triple):
    rows, cols, mask = triple
    return jnp.where(jnp.asarray(mask), band[:, rows, cols], 0.0)


def block_tridiagonal_solve(diag, lower, upper, rhs):
    """diag, lower, upper (B, m, w, w) (lower[:, 0] = upper[:, -1] = 0), rhs (B, m, w, k) -> (B, m, w, k)."""
    w = diag.shape[-1]
    xs = tuple(jnp.moveaxis(a, 1, 0) for a in (diag, lower, upper, rhs))

    def forward(carry, blk):
        c_prev, f_prev = carry
        d, lo, up, r = blk
        sol = jnp.linalg.solve(d - lo @ c_prev, jnp.concatenate([up, r - lo @ f_prev], axis=-1))
        return (sol[..., :w], sol[..., w:]), (sol[..., :w], sol[..., w:])

    init = (jnp.zeros_like(xs[0][0]), jnp.zeros_like(xs[3][0]))
    _, (c, f) = lax.scan(forward, init, xs)

    def backward(x_next, blk):
        c_b, f_b = blk
        x = f_b - c_b @ x_next
        return x, x

    _, x = lax.scan(backward, jnp.zeros_like(f[0]), (c, f), reverse=True)
    return jnp.moveaxis(x, 0, 1)


def solve_cyclic_banded(band, rhs, layout):
    """x (B, n) with H x = rhs for a symmetric H given by its cyclic band (B, n, 2w+1).

    Differentiated implicitly, not through the elimination (whose unpivoted block steps amplify
    rounding in the backward pass: float32 gradients were off by more than 100 %, measured): with
    lam = H^-1 xbar (H symmetric), rhs_bar = lam and band_bar[b, i, k] = -lam[b, i] x[b, cols[i, k]]."""
    cols = band_columns(rhs.shape[-1], band.shape[-1])

    @jax.custom_vjp
    def solve(band, rhs):
        return _solve(band, rhs, layout)

    def fwd(band, rhs):
        x = _solve(band, rhs, layout)
        return x, (band, x)

    def bwd(res, xbar):
        band, x = res
        lam = _solve(band, xbar, layout)
        return -lam[:, :, None] * x[:, cols], lam

    solve.defvjp(fwd, bwd)
    return solve(band, rhs)


def _solve(band, rhs, layout):
    m, w, nb = layout["m"], layout["w"], layout["nb"]
    bsz, ni = rhs.shape[0], layout["m"] * layout["w"]
    col_border = _gather(band, layout["col_border"])
    stacked = jnp.concatenate([rhs[:, :ni, None], col_border], axis=-1).reshape(bsz, m, w, 1 + nb)
    blocks = [_gather(band, layout[k]) for k in ("diag", "lower", "upper")]
    z_all = block_tridiagonal_solve(*blocks, stacked).reshape(bsz, ni, 1 + nb)
    z, x_border = z_all[..., 0], z_all[..., 1:]
    row_border = _gather(band, layout["row_border"])
    schur = _gather(band, layout["border"]) - row_border @ x_border
    y = jnp.linalg.solve(schur, (rhs[:, ni:] - (row_border @ z[..., None])[..., 0])[..., None])[..., 0]
    return jnp.concatenate([z - (x_border @ y[..., None])[..., 0], y], axis=-1)
