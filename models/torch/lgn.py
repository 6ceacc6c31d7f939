"""Lagrangian graph network on a periodic 1D grid (PyTorch, torch.func): L = sum_i density(q_nb(i), qdot_nb(i)).

q, qdot (..., n) with any n at call time (a model trained at n = 10 runs at n = 100). The density MLP
sees [q_{i-r..i+r}, qdot_{i-r..i+r}] (2(2r+1) inputs) gathered by `models.graph.periodic_neighbours`.
Accelerations by spec.formulation:
  "dense":  full n x n Hessian (forward-over-reverse) + solve with the counted pinv fallback (`lnn`).
  "paper":  the original code's full Hessian, full mixed Jacobian and pinv (`lnn`, "paper").
  "banded" (alias "fast"): the velocity Hessian is cyclic-banded (half-bandwidth 2r); its band comes from
            one reverse pass pushed forward along <= 8r+1 coloured tangents plus the one mixed-term
            tangent (`models.graph.band_coloring`), and the system is solved in O(n) by
            `models.torch.banded`. Samples whose solve is not finite take pinv of the dense Hessian and are
            counted. Grids with n < 4r + 1 use the dense path.
"""
from __future__ import annotations

import numpy as np
import torch
from torch.func import grad, jvp, vmap

from models.graph import (
    band_coloring,
    band_from_colours,
    banded_supported,
    cyclic_band_layout,
    periodic_neighbours,
)
from models.torch.banded import solve_cyclic_banded
from models.torch.base import Model
from models.torch.lnn import euler_lagrange_info, fast_terms, pinv_solve
from models.torch.mlp import mlp, mlp_input, wrap_angles


def banded_terms(L_fn, q, qdot, r):
    """On flat (B, n): (band (B, n, 4r+1), rhs = dL/dq - J qdot (B, n)) by coloured forward-over-reverse."""
    n = q.shape[-1]
    colour, n_col = band_coloring(n, r)
    grads = grad(lambda a, b: torch.sum(L_fn(a, b)), argnums=(0, 1))
    onehot = torch.as_tensor(colour[None, :] == np.arange(n_col)[:, None], dtype=q.dtype)
    t_q = torch.cat([torch.zeros((n_col, *q.shape), dtype=q.dtype), qdot[None]])
    t_qdot = torch.cat([onehot[:, None, :].expand(n_col, *q.shape), torch.zeros_like(qdot)[None]])
    (g_q, _), (_, dg_qdot) = vmap(lambda a, b: jvp(grads, (q, qdot), (a, b)))(t_q, t_qdot)
    col, row = band_from_colours(n, r)
    return torch.movedim(dg_qdot[:n_col], 0, 1)[:, torch.as_tensor(col), torch.as_tensor(row)], g_q[0] - dg_qdot[n_col]


def _identity_band(n, r):
    return np.eye(1, 4 * r + 1, 2 * r)[0][None, :].repeat(n, 0)


def banded_euler_lagrange_info(L_fn, q, qdot, r):
    """(qddot (..., n), n_fallback) by the banded path; see the module doc."""
    n, batch = q.shape[-1], q.shape[:-1]
    qf, qdf = q.reshape(-1, n), qdot.reshape(-1, n)
    band, rhs = banded_terms(L_fn, qf, qdf, r)
    layout = cyclic_band_layout(n, r)
    x = solve_cyclic_banded(band, rhs, layout)
    bad = ~torch.all(torch.isfinite(x.detach()), dim=-1)

    if bool(torch.any(bad)):
        safe = torch.where(bad[:, None, None], torch.as_tensor(_identity_band(n, r), dtype=band.dtype), band)
        x_safe = solve_cyclic_banded(safe, rhs, layout)
        x = torch.where(bad[:, None], pinv_solve(*fast_terms(L_fn, qf, qdf)), x_safe)
    return x.reshape(*batch, n), torch.sum(bad)


class LGN(Model):
    def _lagrangian(self, q, qdot):
        nb = torch.as_tensor(periodic_neighbours(q.shape[-1], self.spec.lgn_radius))
        x = mlp_input(self.spec, [wrap_angles(self.spec, q)[..., nb], qdot[..., nb]])
        return torch.sum(mlp(self.params, x, self.spec)[..., 0], dim=-1)

    def lagrangian(self, q, qdot, extra=None):
        """L (...,) for q, qdot (..., n)."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        return self._lagrangian(q, qdot)

    def acceleration_info(self, q, qdot, extra=None):
        """(qddot (..., n), n_fallback) with spec.formulation."""
        self._check_state(q, qdot, extra, width=q.shape[-1])
        form, n, r = self.spec.formulation, q.shape[-1], self.spec.lgn_radius
        if form in ("banded", "fast") and banded_supported(n, r):
            return banded_euler_lagrange_info(self._lagrangian, q, qdot, r)
        return euler_lagrange_info(self._lagrangian, q, qdot, "paper" if form == "paper" else "fast")

    def acceleration(self, q, qdot, extra=None):
        """qddot (..., n)."""
        return self.acceleration_info(q, qdot, extra)[0]
