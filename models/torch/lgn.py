"""Lagrangian graph network on a periodic 1D grid (PyTorch): L = sum_i density(q_nb(i), qdot_nb(i)).

q, qdot (..., n) with any n at call time (a model trained at n = 10 runs at n = 100). The density MLP
sees [q_{i-r..i+r}, qdot_{i-r..i+r}] (2(2r+1) inputs): the neighbours `models.graph.periodic_neighbours`
names, taken by rolls.
Accelerations by spec.own.formulation:
  "dense":  full n x n Hessian (forward-over-reverse) + solve with the counted pinv fallback (`lnn`).
  "paper":  the original code's full Hessian, full mixed Jacobian and pinv (`lnn`, "paper").
  "banded" (alias "fast"): the velocity Hessian is cyclic-banded (half-bandwidth 2r), solved in O(n) by
            `models.torch.banded`. Samples whose solve is not finite take pinv of the same matrix made
            dense and are counted. Grids with n < 4r + 1 use the dense path.
            `banded_euler_lagrange_info(L_fn, q, qdot, r)` (as in the JAX mirror) solves the band of any
            L_fn, which `banded_terms(L_fn, ...)` gets by one reverse pass pushed forward along <= 8r+1
            coloured tangents plus the mixed-term tangent (`models.graph.band_coloring`). `LGN` itself
            differentiates its density MLP by hand at every node instead (`models.torch.mlp_derivatives`;
            k = 2r+1 velocity tangents and one mixed tangent per node, the node terms shifted into place):
            same values, plain torch ops, so the banded LGN goes through torch.export
            (`models.torch.compiled`), which torch.func does not. Exported, the fallback gathers the bad
            samples instead (chosen by `models.torch.export_paths.pick`).
"""
from __future__ import annotations

import numpy as np
import torch
from torch.func import grad, jvp, vmap

from lagbench.models.graph import (
    band_coloring,
    band_columns,
    band_from_colours,
    band_sum,
    banded_supported,
    cyclic_band_layout,
    identity_band,
)
from lagbench.models.torch.banded import solve_cyclic_banded
from lagbench.models.torch.base import Model
from lagbench.models.torch.export_paths import pick, vmapped
from lagbench.models.torch.lnn import euler_lagrange_info, pinv_solve
from lagbench.models.torch.mlp import input_scale, mlp, mlp_input, wrap_angles
from lagbench.models.torch.mlp_derivatives import input_grad_and_tangent_hessian


def banded_terms(L_fn, q, qdot, r):
    """On flat (B, n): (band (B, n, 4r+1), rhs = dL/dq - J qdot (B, n)) by coloured forward-over-reverse."""
    n = q.shape[-1]
    colour, n_col = band_coloring(n, r)
    grads = grad(lambda a, b: torch.sum(L_fn(a, b)), argnums=(0, 1))
    onehot = torch.as_tensor(colour[None, :] == np.arange(n_col)[:, None], dtype=q.dtype, device=q.device)
    t_q = torch.cat([torch.zeros((n_col, *q.shape), dtype=q.dtype, device=q.device), qdot[None]])
    t_qdot = torch.cat([onehot[:, None, :].expand(n_col, *q.shape), torch.zeros_like(qdot)[None]])
    (g_q, _), (_, dg_qdot) = vmap(lambda a, b: jvp(grads, (q, qdot), (a, b)))(t_q, t_qdot)
    col, row = band_from_colours(n, r)
    return torch.movedim(dg_qdot[:n_col], 0, 1)[:, torch.as_tensor(col, device=q.device),
                                                 torch.as_tensor(row, device=q.device)], g_q[0] - dg_qdot[n_col]


def dense_from_band(band):
    """The (B, n, n) matrix of a cyclic band (B, n, 2w+1) (n >= 2w+1: no two band entries share a place)."""
    bsz, n, width = band.shape
    cols = band_columns(n, width)
    flat = torch.as_tensor((np.arange(n)[:, None] * n + cols).reshape(-1), device=band.device)
    dense = torch.zeros((bsz, n * n), dtype=band.dtype, device=band.device)
    return dense.index_copy(1, flat, band.flatten(1)).unflatten(1, (n, n))


def _pinv_where_bad(band, rhs, x, bad, r, layout):
    """Eager: if any sample's banded solve is not finite, those take pinv of the dense matrix, solved
    again on an identity band first so that no NaN reaches the gradient. Vmapped: always, with no
    Python branch on data."""
    if not vmapped(band) and not bool(torch.any(bad)):
        return x
    eye = torch.as_tensor(identity_band(rhs.shape[-1], r), dtype=band.dtype, device=band.device)
    safe = torch.where(bad[:, None, None], eye, band)
    x_safe = solve_cyclic_banded(safe, rhs, layout)
    return torch.where(bad[:, None], pinv_solve(dense_from_band(band), rhs), x_safe)


def _pinv_gathered(band, rhs, x, bad, r, layout):
    """Exported (inference only): the bad samples are gathered and only they take pinv (a data-dependent
    count): an exported graph has no Python branch on data, and a torch.cond here fixed the batch size to
    >= 2 (torch 2.13)."""
    idx = torch.nonzero(bad).squeeze(1)
    return x.index_put((idx,), pinv_solve(dense_from_band(band[idx]), rhs[idx], by_svd=True))


def _banded_solve_info(band, rhs, r):
    """Flat band (B, n, 4r+1), rhs (B, n): (x (B, n), n_fallback); the bad samples take pinv of the
    dense matrix (counted), by `_pinv_where_bad` or, under torch.export, `_pinv_gathered`."""
    layout = cyclic_band_layout(rhs.shape[-1], r)
    x = solve_cyclic_banded(band, rhs, layout)
    bad = ~torch.all(torch.isfinite(x.detach()), dim=-1)
    x = pick(_pinv_where_bad, exporting=_pinv_gathered)(band, rhs, x, bad, r, layout)
    return x, torch.sum(bad)


def banded_euler_lagrange_info(L_fn, q, qdot, r):
    """(qddot (..., n), n_fallback) by the banded path for any L_fn (its band from `banded_terms`); see the
    module doc. `LGN` solves its own hand-differentiated band the same way."""
    n = q.shape[-1]
    x, n_bad = _banded_solve_info(*banded_terms(L_fn, q.reshape(-1, n), qdot.reshape(-1, n), r), r)
    return x.reshape(q.shape), n_bad


def _neighbours(x, r):
    """x (..., n) -> (..., n, 2r+1): x at nodes i-r .. i+r (mod n), as `periodic_neighbours` indexes them,
    by rolls (whose derivative is a roll: the scatter-add of an index gather's derivative fails inductor's
    CPU code generation, torch 2.13, when the dense path is traced and compiled)."""
    return torch.stack([torch.roll(x, r - a, dims=-1) for a in range(2 * r + 1)], dim=-1)


class LGN(Model):
    def _lagrangian(self, q, qdot):
        x = mlp_input(self.spec, [_neighbours(wrap_angles(self.spec, q), self.spec.own.radius),
                                  _neighbours(qdot, self.spec.own.radius)])
        return torch.sum(mlp(self.params, x, self.spec)[..., 0], dim=-1)

    def _banded_terms(self, q, qdot):
        """On flat (B, n): (band (B, n, 4r+1), rhs = dL/dq - J qdot (B, n)), as `banded_terms` gives them.
        Node i's density sees x_i = scale * [q_nb(i), qdot_nb(i)] (k = 2r+1 neighbours i+a-r); its MLP
        gradient g_i and its Gram G_i (tangents: s_qd[a] e_(k+a) for each a, and s_q * qdot_nb(i) in the
        q slots) give every term: node i adds G_i[a, b] to H[i+a-r, i+b-r] (band column 2r+b-a),
        G_i[a, k] to (J qdot)[i+a-r] and s_q[b] g_i[b] to dL/dq[i+b-r]. Rolling slot a's terms by a-r moves
        them all into place."""
        spec, (bsz, n), r = self.spec, q.shape, self.spec.own.radius
        k = 2 * r + 1
        qdot_nb = _neighbours(qdot, r)
        x = mlp_input(spec, [_neighbours(wrap_angles(spec, q), r), qdot_nb]).reshape(bsz * n, 2 * k)
        scale = input_scale(spec, 2 * k, x.dtype, x.device)
        s_q, s_qd = scale[:k], scale[k:]
        # built out of place: under torch.func.vmap (stacked members) qdot is batched, the zeros are not
        rows = torch.cat([torch.zeros((k, k), dtype=x.dtype, device=x.device), torch.diag(s_qd)], -1)
        mixed = torch.cat([qdot_nb.reshape(bsz * n, k) * s_q, torch.zeros((bsz * n, k), dtype=x.dtype, device=x.device)],
                          -1)
        tangents = torch.cat([rows.expand(bsz * n, k, 2 * k), mixed[:, None, :]], 1)
        g, gram = input_grad_and_tangent_hessian(self.params, x, tangents, spec, rows=k)
        g = torch.cat([(g[:, :k] * s_q).reshape(bsz, n, k, 1), gram.reshape(bsz, n, k, k + 1)], -1)
        moved = torch.stack([torch.roll(g[:, :, a], a - r, dims=1) for a in range(k)], 2)  # [j, a]: node j-a+r's slot a
        to_band = torch.as_tensor(band_sum(r), dtype=x.dtype, device=x.device)
        band = moved[..., 1:k + 1].reshape(bsz, n, k * k) @ to_band
        return band, moved[..., 0].sum(-1) - moved[..., k + 1].sum(-1)

    def lagrangian(self, q, qdot, extra=None):
        """L (...,) for q, qdot (..., n)."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        return self._lagrangian(q, qdot)

    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., n), n_fallback) with spec.own.formulation."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        form, n, r = self.spec.own.formulation, q.shape[-1], self.spec.own.radius
        if form in ("banded", "fast") and banded_supported(n, r):
            band, rhs = self._banded_terms(q.reshape(-1, n), qdot.reshape(-1, n))
            x, n_bad = _banded_solve_info(band, rhs, r)
            return x.reshape(q.shape), n_bad
        return euler_lagrange_info(self._lagrangian, q, qdot, "paper" if form == "paper" else "fast")

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., n)."""
        return self.acceleration_info(q, qdot, extra)[0]
