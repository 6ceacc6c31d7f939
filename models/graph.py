"""Graph structure of the Lagrangian graph network, in NumPy (shared by both frameworks).

A periodic 1D chain of n nodes; node i's neighbourhood is i-r .. i+r (mod n), given as an index
array so that other graphs can follow. The velocity Hessian of L = sum_i density(neighbourhood i)
couples nodes at cyclic distance <= 2r: it is cyclic-banded with half-bandwidth w = 2r, stored as
band[..., i, k] = H[i, (i + k - w) mod n], k = 0 .. 2w (needs n >= 2w + 1).

`band_coloring(n, r)`: colours such that nodes of one colour are >= 2w+1 apart (cyclically), so one
forward-mode tangent per colour gives all band entries: n // (2w+1) full blocks of 2w+1 colours, the
remaining n mod (2w+1) nodes each a colour of their own (at most 4w+1 = 8r+1 colours, for any n).

`cyclic_band_layout(n, r)`: index arrays that gather the band into the bordered block-tridiagonal
form solved in O(n): m = n // w - 1 interior blocks of size w (nodes 0 .. m*w-1) and one border
block of the remaining nb = n - m*w nodes (w <= nb < 2w). Each entry is (rows, cols) node indices;
`band_gather(rows, cols, n, w)` turns them into (band row, band column, mask) arrays.
`identity_band(n, r)`: the band of the identity (the fallback's safe system); `band_sum(r)`: where a node's
(2r+1)^2 velocity-Hessian terms land in the band (the hand-differentiated LGNs of both frameworks).
"""
from __future__ import annotations

import numpy as np


def periodic_neighbours(n: int, r: int) -> np.ndarray:
    """(n, 2r+1) int: node indices i-r .. i+r (mod n) of each node i."""
    return (np.arange(n)[:, None] + np.arange(-r, r + 1)[None, :]) % n


def banded_supported(n: int, r: int) -> bool:
    """True if the banded path applies (n >= 2w + 1 with w = 2r); smaller grids use the dense one."""
    return n >= 4 * r + 1


def band_coloring(n: int, r: int) -> tuple:
    """(colour (n,) int, n_colours); nodes sharing a colour are >= 4r+1 apart cyclically."""
    k = 4 * r + 1
    full = (n // k) * k
    colour = np.concatenate([np.arange(full) % k, k + np.arange(n - full)])
    return colour.astype(np.int64), int(colour.max()) + 1


def band_from_colours(n: int, r: int) -> tuple:
    """(colour index (n, 4r+1), row index (n, 4r+1)): band[i, k] = Hv[colour[(i+k-2r) % n], i]."""
    w = 2 * r
    colour, _ = band_coloring(n, r)
    rows = np.repeat(np.arange(n)[:, None], 2 * w + 1, axis=1)
    cols = (rows + np.arange(-w, w + 1)[None, :]) % n
    return colour[cols], rows


def band_gather(rows: np.ndarray, cols: np.ndarray, n: int, w: int) -> tuple:
    """For dense indices H[rows, cols]: (rows, band column clipped, mask of in-band entries)."""
    k = (cols - rows + w) % n
    mask = k <= 2 * w
    return rows, np.where(mask, k, 0), mask


def cyclic_band_layout(n: int, r: int) -> dict:
    """Gather indices for the bordered block-tridiagonal solve of a cyclic-banded (n, n) matrix.

    Returns {"m", "w", "nb", and for each of "diag" (m, w, w), "lower" (m, w, w) (block b, b-1; zero
    for b = 0), "upper" (m, w, w) (block b, b+1; zero for b = m-1), "col_border" (m*w, nb),
    "row_border" (nb, m*w), "border" (nb, nb): a (rows, band_cols, mask) triple}.
    """
    w = 2 * r
    m = n // w - 1
    nb = n - m * w
    a = np.arange(w)
    blk = np.arange(m)[:, None, None] * w
    out = {"m": m, "w": w, "nb": nb}
    rows = blk + a[None, :, None] + 0 * a[None, None, :]
    out["diag"] = band_gather(rows, blk + a[None, None, :] + 0 * rows, n, w)
    lo = band_gather(rows, (blk - w + a[None, None, :]) % n + 0 * rows, n, w)
    out["lower"] = (lo[0], lo[1], lo[2] & (np.arange(m) > 0)[:, None, None])
    up = band_gather(rows, (blk + w + a[None, None, :]) % n + 0 * rows, n, w)
    out["upper"] = (up[0], up[1], up[2] & (np.arange(m) < m - 1)[:, None, None])
    interior, border = np.arange(m * w), m * w + np.arange(nb)
    out["col_border"] = band_gather(interior[:, None] + 0 * border[None, :], border[None, :] + 0 * interior[:, None], n, w)
    out["row_border"] = band_gather(border[:, None] + 0 * interior[None, :], interior[None, :] + 0 * border[:, None], n, w)
    out["border"] = band_gather(border[:, None] + 0 * border[None, :], border[None, :] + 0 * border[:, None], n, w)
    return out


def band_columns(n: int, width: int) -> np.ndarray:
    """(n, 2w+1) column index of each band entry: band[:, i, k] = H[i, cols[i, k]]."""
    w = (width - 1) // 2
    return (np.arange(n)[:, None] + np.arange(width)[None, :] - w) % n


def identity_band(n: int, r: int) -> np.ndarray:
    """(n, 4r+1) band of the n x n identity."""
    return np.eye(1, 4 * r + 1, 2 * r)[0][None, :].repeat(n, 0)


def band_sum(r: int) -> np.ndarray:
    """(k*k, 4r+1) 0/1: node term (a, b) (velocity slots of neighbours i+a-r, i+b-r) -> band column 2r+b-a."""
    k = 2 * r + 1
    a, b = np.divmod(np.arange(k * k), k)
    return np.eye(4 * r + 1)[2 * r + b - a]
